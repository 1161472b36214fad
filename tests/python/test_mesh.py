"""cadmorph.read_mesh, write_mesh and Mesh: points and cells against meshio, round trips,
points as a view onto the library's memory."""
import gc

import meshio
import numpy as np
import pytest

import cadmorph

# meshio's names of the cadmorph types these fixtures hold
MESHIO_TYPES = {"tet4": "tetra", "hex8": "hexahedron", "wedge6": "wedge", "pyramid5": "pyramid",
                "tri3": "triangle", "quad4": "quad", "line2": "line", "point": "vertex",
                "tet10": "tetra10", "tri6": "triangle6"}
# cadmorph keeps VTK's node order for every type (mesh.h); meshio reorders wedges to its own
MESHIO_ORDER = {"wedge": [0, 2, 1, 3, 5, 4]}
FIXTURES = ["vtk/meshio_ascii.vtu", "vtk/meshio_binary.vtu", "vtk/meshio_ascii.vtk",
            "msh/box_hole_41.msh", "msh/box_hole_22b.msh"]


def by_type(blocks):
    """{type: all its cells stacked in file order}: the per-type content, whatever the
    blocks (meshio splits msh files by entity, cadmorph by runs of one type)."""
    out = {}
    for t, a in blocks:
        out.setdefault(t, []).append(np.asarray(a))
    return {t: np.concatenate(v) for t, v in out.items()}


@pytest.mark.parametrize("name", FIXTURES)
def test_read_matches_meshio(data, name):
    path = data / name
    mesh = cadmorph.read_mesh(path)
    ref = meshio.read(path)
    assert mesh.points.shape == ref.points.shape
    assert mesh.points.dtype == np.float64
    assert np.array_equal(mesh.points, ref.points)
    ours = by_type((MESHIO_TYPES[t], a) for t, a in mesh.cells)
    for t, order in MESHIO_ORDER.items():
        if t in ours:
            ours[t] = ours[t][:, order]
    theirs = by_type((b.type, b.data) for b in ref.cells)
    assert sorted(ours) == sorted(theirs)
    for t in ours:
        assert ours[t].dtype == np.int64
        assert np.array_equal(ours[t], theirs[t]), t
    assert mesh.n_nodes == len(ref.points)
    assert mesh.n_cells == sum(len(b.data) for b in ref.cells)


def test_fields(data):
    mesh = cadmorph.read_mesh(data / "vtk/meshio_ascii.vtu")
    ref = meshio.read(data / "vtk/meshio_ascii.vtu")
    assert np.array_equal(mesh.point_data["displacement"], ref.point_data["displacement"])
    sj = np.concatenate(ref.cell_data["scaled_jacobian"])
    assert np.array_equal(mesh.cell_data["scaled_jacobian"], sj)
    assert mesh.cell_types[:2] == ["hex8", "pyramid5"]


@pytest.mark.parametrize("ext", [".vtu", ".msh", ".vtk", ".mesh"])
def test_write_round_trip(data, work, ext):
    mesh = cadmorph.read_mesh(data / "msh/box_hole_41.msh")
    out = work / ("box" + ext)
    cadmorph.write_mesh(out, mesh)
    back = cadmorph.read_mesh(str(out))
    assert np.array_equal(back.points, mesh.points)
    assert [t for t, _ in back.cells] == [t for t, _ in mesh.cells]
    for (_, a), (_, b) in zip(back.cells, mesh.cells):
        assert np.array_equal(a, b)
    ref = meshio.read(out)  # and another reader agrees
    assert np.array_equal(ref.points, mesh.points)


def test_write_options(data, work):
    mesh = cadmorph.read_mesh(data / "msh/box_hole_41.msh")
    cadmorph.write_mesh(work / "a.msh", mesh, binary=True, msh_version=22)
    assert b"$MeshFormat\n2.2 1 8" in (work / "a.msh").read_bytes()
    with pytest.raises(ValueError, match="msh_version"):
        cadmorph.write_mesh(work / "b.msh", mesh, msh_version=3)


def test_points_is_a_view(data, work):
    mesh = cadmorph.read_mesh(data / "vtk/meshio_ascii.vtu")
    p = mesh.points
    assert p.flags.writeable and p.flags.c_contiguous
    assert np.shares_memory(p, mesh.points)  # two views, one memory
    assert p.base is not None and not p.flags.owndata
    p[0, 0] = 12.5
    assert mesh.points[0, 0] == 12.5
    cadmorph.write_mesh(work / "moved.vtu", mesh)
    assert cadmorph.read_mesh(work / "moved.vtu").points[0, 0] == 12.5
    assert meshio.read(work / "moved.vtu").points[0, 0] == 12.5


def test_views_keep_the_mesh(data):
    mesh = cadmorph.read_mesh(data / "msh/box_hole_41.msh")
    expect = mesh.points.copy()
    p, cells = mesh.points, mesh.cells
    mesh.close()
    with pytest.raises(ValueError, match="closed"):
        mesh.points
    del mesh
    gc.collect()
    for _ in range(3):  # allocations that would reuse freed memory
        cadmorph.read_mesh(data / "msh/box_hole_41.msh")
    assert np.array_equal(p, expect)
    assert cells[-1][1].max() < len(expect)


def test_connectivity_is_read_only(data):
    mesh = cadmorph.read_mesh(data / "vtk/meshio_ascii.vtu")
    _, tets = mesh.cells[3]
    with pytest.raises(ValueError):
        tets[0, 0] = 10**9  # an out-of-range node must not reach the library


def test_context_manager(data):
    with cadmorph.read_mesh(data / "vtk/meshio_ascii.vtu") as mesh:
        assert mesh.n_nodes == 14
    assert mesh.closed and "closed" in repr(mesh)


def test_polyhedra(data):
    mesh = cadmorph.read_mesh(data / "vtk/vtk_legacy_ascii.vtk")
    blocks = dict(mesh.cells)
    (stream,) = blocks["polyhedron"]  # one polyhedron: a copy of its face stream
    assert stream.dtype == np.int64 and stream.ndim == 1
    nf, at = stream[0], 1
    for _ in range(nf):  # nf faces, each its count and its nodes, and nothing after them
        at += 1 + stream[at]
    assert at == len(stream) and stream[1:].max() < mesh.n_nodes
    q = cadmorph.quality(mesh)
    assert np.isfinite(q.per_cell[mesh.cell_types.index("polyhedron")])


def test_set_points(data, work):
    mesh = cadmorph.read_mesh(data / "vtk/meshio_ascii.vtu")
    new = mesh.points * 2.0
    mesh.points = new.tolist()  # any array-like of reals, copied into the mesh
    assert np.array_equal(mesh.points, new)
    with pytest.raises(ValueError, match=r"\(14, 3\)"):
        mesh.points = np.zeros((13, 3))
    with pytest.raises(ValueError):
        mesh.points = np.zeros((14, 2))
    with pytest.raises(TypeError):
        mesh.points = np.array([["a", "b", "c"]] * 14)
    assert np.array_equal(mesh.points, new)  # the refused assignments changed nothing


def test_no_direct_construction():
    for args in ((), (None,), (0,), (cadmorph._ffi.NULL,)):
        with pytest.raises(TypeError, match="read_mesh"):
            cadmorph.Mesh(*args)


@pytest.mark.parametrize("threads, exc", [(-1, ValueError), (10**6, ValueError),
                                           ("2", TypeError), (True, TypeError)])
def test_threads_checked(data, threads, exc):
    with pytest.raises(exc, match="threads"):
        cadmorph.read_mesh(data / "vtk/meshio_ascii.vtu", threads=threads)


def test_mesh_formats_as_the_cli_names_them(cli):
    """mesh_formats() is the list every --help shows, with the solvers' formats in it."""
    import subprocess
    formats = cadmorph.mesh_formats()
    for ext in (".msh", ".vtu", ".cgns", ".su2", ".cas", ".inp", ".bdf", ".exo"):
        assert ext in formats
    assert formats.endswith("or an OpenFOAM case directory")
    helptext = subprocess.run([cli, "quality", "--help"], capture_output=True, text=True).stdout
    assert formats in " ".join(helptext.split())
