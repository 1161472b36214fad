"""The library's errors as exceptions: classes as the CLI's exit codes, the library's
message naming the file; bad arguments stopped before the library."""
import subprocess

import pytest

import cadmorph

EXIT_CLASS = {2: cadmorph.BadInputError, 4: cadmorph.ResourceError}


def test_missing_file(work):
    path = work / "no_such_mesh.vtu"
    with pytest.raises(cadmorph.BadInputError) as e:
        cadmorph.read_mesh(path)
    assert str(path) in str(e.value) and str(path) in e.value.message
    assert e.value.status == -3 and e.value.status_name
    assert isinstance(e.value, cadmorph.Error)


def hostile(data):
    return sorted((data / "vtk/bad").iterdir())


@pytest.mark.parametrize("i", range(22))
def test_hostile_files(cli, data, i):
    files = hostile(data)
    assert len(files) == 22, "tests/data/vtk/bad changed: update the range"
    path = files[i]
    r = subprocess.run([cli, "quality", str(path)], capture_output=True, text=True)
    with pytest.raises(cadmorph.Error) as e:
        cadmorph.read_mesh(path)
    assert type(e.value) is EXIT_CLASS[r.returncode]
    assert str(path) in str(e.value)
    assert r.stderr.strip() == "cadmorph quality: " + e.value.message


@pytest.mark.parametrize("bad", [None, 3, ["a.vtu"]])
def test_path_type(bad):
    with pytest.raises(TypeError):
        cadmorph.read_mesh(bad)


@pytest.mark.parametrize("bad", ["", "a\0b.vtu"])
def test_path_value(bad):
    with pytest.raises(ValueError):
        cadmorph.read_mesh(bad)


def test_write_needs_a_mesh(work):
    with pytest.raises(TypeError, match="cadmorph.Mesh"):
        cadmorph.write_mesh(work / "x.vtu", object())


def test_write_to_a_missing_directory(data, work):
    mesh = cadmorph.read_mesh(data / "vtk/meshio_ascii.vtu")
    target = work / "missing" / "x.vtu"
    with pytest.raises(cadmorph.BadInputError, match="missing"):
        cadmorph.write_mesh(target, mesh)
    assert not target.exists()


def test_error_classes():
    assert issubclass(cadmorph.MismatchError, cadmorph.BadInputError)
    for c in (cadmorph.BadInputError, cadmorph.RejectedError, cadmorph.ResourceError):
        assert issubclass(c, cadmorph.Error)


def test_docstrings():
    """Every public name, and every public method and property of its classes."""
    import inspect
    missing = []
    for name in cadmorph.__all__:
        obj = getattr(cadmorph, name)
        if name.startswith("__"):
            continue
        if not inspect.getdoc(obj):
            missing.append(name)
        if inspect.isclass(obj):
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and not inspect.getdoc(member):
                    missing.append(name + "." + attr)
    assert not missing, missing


def test_error_pickles(work):
    import pickle
    with pytest.raises(cadmorph.BadInputError) as e:
        cadmorph.read_mesh(work / "absent.msh")
    back = pickle.loads(pickle.dumps(e.value))
    assert type(back) is cadmorph.BadInputError
    assert (back.status, back.message, str(back)) == (e.value.status, e.value.message,
                                                       str(e.value))
