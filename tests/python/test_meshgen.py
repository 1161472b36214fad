"""cadmorph.mesh_step against `cadmorph mesh` on the bore (both meshers: the same nodes bit
for bit, the same counts and quality field), a model without a file for gmsh, errors."""
import subprocess

import numpy as np
import pytest

import cadmorph


def cli_mesh(cli, step, out, *args):
    r = subprocess.run([cli, "mesh", str(step), "-o", str(out), *args], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    return dict(kv.split("=") for kv in r.stdout.splitlines()[0].split())


@pytest.mark.parametrize("mesher", ["gmsh", "tetgen"])
def test_mesh_step_equals_cli(cli, data, work, mesher):
    step = data / "models/bore_0.step"
    out = work / "bore.vtu"
    line = cli_mesh(cli, step, out, "--size", "0.6", *(["--mesher", "tetgen"]
                                                       if mesher == "tetgen" else []))
    g = cadmorph.read_step(step)
    mesh = cadmorph.mesh_step(g, size=0.6, mesher=None if mesher == "gmsh" else mesher,
                              progress=False)
    ref = cadmorph.read_mesh(out)
    assert mesh.n_nodes == int(line["nodes"])
    types = mesh.cell_types
    assert types.count("tet4") == int(line["tets"])
    assert types.count("tri3") == int(line["boundary_triangles"])
    assert np.array_equal(mesh.points, ref.points)
    assert [(t, np.array_equal(a, b)) for (t, a), (_, b) in zip(mesh.cells, ref.cells)] == \
        [(t, True) for t, _ in ref.cells]
    assert np.array_equal(mesh.cell_data["scaled_jacobian"], ref.cell_data["scaled_jacobian"],
                          equal_nan=True)
    assert ("solid" in [name for _, _, name in mesh.groups]) and \
        len([1 for d, _, _ in mesh.groups if d == 2]) == g.n_faces


def test_mesh_step_model_without_file():
    # model() reads a temporary STEP file that is gone afterwards: gmsh gets a new one
    g = cadmorph.model("bore", 0.5)
    mesh = cadmorph.mesh_step(g, size=0.8, progress=False)
    q = cadmorph.quality(mesh)
    assert mesh.n_nodes > 50 and q.inverted == 0 and q.cells > 100


def test_mesh_step_errors(data):
    g = cadmorph.read_step(data / "models/bore_0.step")
    with pytest.raises(ValueError, match="TetGen's"):
        cadmorph.mesh_step(g, mesher="gmsh", quality=1.2)
    with pytest.raises(ValueError, match="mesher"):
        cadmorph.mesh_step(g, mesher="netgen")
    with pytest.raises(ValueError, match="size"):
        cadmorph.mesh_step(g, size=0)
    with pytest.raises(ValueError, match="min_dihedral"):
        cadmorph.mesh_step(g, min_dihedral=30)
    with pytest.raises(TypeError, match="Geometry"):
        cadmorph.mesh_step(str(data / "models/bore_0.step"))
    with pytest.raises(cadmorph.ResourceError, match="estimate|tets"):
        cadmorph.mesh_step(g, size=1e-3, progress=False)
    sheet = cadmorph.read_step(data / "models/sheet.step")
    with pytest.raises(cadmorph.BadInputError, match="no solid"):
        cadmorph.mesh_step(sheet, mesher="tetgen", progress=False)
    assert cadmorph.mesh_step.__doc__
