"""Mesh.from_arrays, from_meshio and to_meshio: round trips through meshio keep points
(exactly), cells, groups and fields; node order against files meshio reads itself; bad arrays
stopped with ValueError/TypeError before the library sees them."""
import numpy as np
import meshio
import pytest

import cadmorph

# files both read; meshio cannot read the polyhedra of tests/data/vtk/vtk_*.vtu with other
# cells, nor wedge15/pyramid13 (meshio 5.0 has no dimension for them)
MESHIO_FIXTURES = ["vtk/meshio_ascii.vtu", "vtk/meshio_binary.vtk", "msh/box_hole_41.msh",
                   "msh/box_hole_22b.msh", "vtk/gmsh_blocks.msh", "vtk/gmsh_blocks.mesh"]
# files cadmorph reads, through meshio's in-memory form and back
FIXTURES = MESHIO_FIXTURES + ["vtk/vtk_ascii.vtu", "msh/hybrid_o2_41.msh",
                              "quality/mixed.vtu", "vtk/meshio_42.vtk"]


def by_type(blocks):
    """{type: its cells stacked in file order} (meshio splits .msh blocks by entity)."""
    out = {}
    for t, a in blocks:
        if t.startswith("polyhedron") or t == "polygon":
            out.setdefault(t, []).extend(np.concatenate([np.ravel(f) for f in c]) if
                                         t.startswith("polyhedron") else c for c in a)
        else:
            out.setdefault(t, []).append(np.asarray(a))
    return {t: (np.concatenate(v) if not (t.startswith("polyhedron") or t == "polygon")
                else v) for t, v in out.items()}


def cells_equal(a, b):
    ta, tb = by_type(a), by_type(b)
    assert sorted(ta) == sorted(tb)
    for t in ta:
        if isinstance(ta[t], list):
            assert len(ta[t]) == len(tb[t]) and all(np.array_equal(x, y)
                                                    for x, y in zip(ta[t], tb[t])), t
        else:
            assert ta[t].dtype.kind == tb[t].dtype.kind == "i"
            assert np.array_equal(ta[t], tb[t]), t


def per_type_data(m, name):
    """meshio cell data of one name, concatenated per cell type (file order)."""
    out = {}
    for b, d in zip(m.cells, m.cell_data[name]):
        out.setdefault(b.type, []).append(np.asarray(d))
    return {t: np.concatenate(v) for t, v in out.items()}


def ids(name):
    return name.replace("/", "_")


@pytest.mark.parametrize("name", MESHIO_FIXTURES, ids=ids)
def test_meshio_round_trip(data, name):
    ref = meshio.read(data / name)
    mesh = cadmorph.Mesh.from_meshio(ref)
    back = mesh.to_meshio()
    assert back.points.dtype == np.float64
    assert np.array_equal(back.points, ref.points)  # bit for bit
    cells_equal([(b.type, b.data) for b in back.cells], [(b.type, b.data) for b in ref.cells])
    keys = set(ref.point_data) - {"gmsh:dim_tags"}  # meshio's bookkeeping, dropped
    assert set(back.point_data) == keys
    for k in keys:
        assert np.array_equal(back.point_data[k], ref.point_data[k])
    assert set(back.cell_data) == set(ref.cell_data)
    for k in ref.cell_data:
        ours, theirs = per_type_data(back, k), per_type_data(ref, k)
        assert sorted(ours) == sorted(theirs)
        for t in ours:
            assert np.array_equal(ours[t], theirs[t]), (k, t)
    assert {k: list(v) for k, v in back.field_data.items()} == \
        {k: list(v) for k, v in ref.field_data.items()}


@pytest.mark.parametrize("name", FIXTURES, ids=ids)
def test_file_round_trip(data, work, name):
    mesh = cadmorph.read_mesh(data / name)
    back = cadmorph.Mesh.from_meshio(mesh.to_meshio())
    assert np.array_equal(back.points, mesh.points)
    assert back.cell_types == mesh.cell_types
    for (ta, a), (tb, b) in zip(back.cells, mesh.cells):
        assert ta == tb
        if isinstance(a, list):
            assert all(np.array_equal(x, y) for x, y in zip(a, b)) and len(a) == len(b)
        else:
            assert np.array_equal(a, b)
    assert np.array_equal(back.physical, mesh.physical)
    assert np.array_equal(back.entity, mesh.entity)
    assert back.groups == mesh.groups
    for mine, theirs in ((back.point_data, mesh.point_data), (back.cell_data, mesh.cell_data)):
        assert list(mine) == list(theirs)
        for k in mine:
            assert np.array_equal(mine[k], theirs[k], equal_nan=True)
    # and the files cadmorph writes are the same bytes (gmsh 4's $Entities, which meshio
    # does not carry, leave .msh out)
    for ext in (".vtu", ".vtk"):
        cadmorph.write_mesh(work / ("a" + ext), mesh)
        cadmorph.write_mesh(work / ("b" + ext), back)
        assert (work / ("a" + ext)).read_bytes() == (work / ("b" + ext)).read_bytes()


def small_mesh():
    """Arrays of a hex, a wedge (meshio's order), a tet and boundary triangles, with fields
    and groups."""
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1],
                    [1, 1, 1], [0, 1, 1], [2, 0, 0], [2, 1, 0], [2, 0, 1], [2, 1, 1],
                    [0.5, 0.5, 2.0]], dtype=float) + 0.125
    hexes = np.array([[0, 1, 2, 3, 4, 5, 6, 7]])
    wedges = np.array([[1, 8, 2, 5, 10, 6], [8, 9, 2, 10, 11, 6]])  # gmsh's orientation
    tets = np.array([[4, 5, 6, 12]])
    tris = np.array([[0, 1, 2], [0, 2, 3]])
    cells = [("hexahedron", hexes), ("wedge", wedges), ("tetra", tets), ("triangle", tris)]
    point_data = {"u": np.arange(39, dtype=float).reshape(13, 3), "t": np.linspace(0, 1, 13)}
    cell_data = {"gmsh:physical": [np.array([1]), np.array([2, 2]), np.array([1]),
                                   np.array([7, 7])],
                 "gmsh:geometrical": [np.array([11]), np.array([12, 12]), np.array([13]),
                                      np.array([14, 15])],
                 "w": [np.array([0.5]), np.array([1.5, 2.5]), np.array([3.5]),
                       np.array([4.5, 5.5])]}
    groups = [(3, 1, "solid"), (3, 2, "prisms"), (2, 7, "bottom")]
    return pts, cells, point_data, cell_data, groups


@pytest.mark.parametrize("ext", [".vtu", ".msh", ".vtk"])
def test_arrays_written_read_by_meshio(work, ext):
    pts, cells, point_data, cell_data, groups = small_mesh()
    mesh = cadmorph.Mesh.from_arrays(pts, cells, point_data, cell_data, groups)
    assert mesh.cell_types == ["hex8", "wedge6", "wedge6", "tet4", "tri3", "tri3"]
    assert cadmorph.quality(mesh).inverted == 0  # the wedges came in meshio's order
    assert mesh.groups == groups
    assert list(mesh.physical) == [1, 2, 2, 1, 7, 7]
    cadmorph.write_mesh(work / ("m" + ext), mesh)
    ref = meshio.read(work / ("m" + ext))
    assert np.array_equal(ref.points, pts)
    cells_equal([(b.type, b.data) for b in ref.cells], cells)
    for name in ("gmsh:physical", "gmsh:geometrical"):
        ours = per_type_data(ref, name)  # meshio reads a .vtu's 1-component arrays as (n, 1)
        for t in ours:
            expect = np.concatenate([d for (tt, _), d in zip(cells, cell_data[name]) if tt == t])
            assert np.array_equal(ours[t].ravel(), expect), (name, t)
    if ext == ".msh":  # gmsh keeps the names of physical groups, not fields
        assert {k: (int(v[1]), int(v[0])) for k, v in ref.field_data.items()} == \
            {n: (d, t) for d, t, n in groups}
    else:
        assert np.array_equal(ref.point_data["u"], point_data["u"])
        assert np.array_equal(ref.point_data["t"].ravel(), point_data["t"])
        assert np.array_equal(np.concatenate(ref.cell_data["w"]).ravel(),
                              np.concatenate(cell_data["w"]))


def test_from_arrays_of_a_mesh(data):
    """A mesh's own arrays (cadmorph's names, polygons and polyhedra included) rebuild it."""
    mesh = cadmorph.read_mesh(data / "vtk/vtk_ascii.vtu")
    tags = {"gmsh:physical": mesh.physical, "gmsh:geometrical": mesh.entity}
    copy = cadmorph.Mesh.from_arrays(mesh.points, mesh.cells, mesh.point_data,
                                     {**mesh.cell_data, **tags}, mesh.groups)
    assert copy.cell_types == mesh.cell_types
    assert np.array_equal(copy._cell_arrays()[2], mesh._cell_arrays()[2])
    assert np.array_equal(cadmorph.quality(copy).per_cell, cadmorph.quality(mesh).per_cell,
                          equal_nan=True)
    assert not np.shares_memory(copy.points, mesh.points)


def test_node_order_against_meshio(data, work):
    # linear wedges: meshio's gmsh reader keeps gmsh's order, cadmorph VTK's
    for name in ("vtk/gmsh_blocks.msh", "msh/hybrid_o2_41.msh"):
        ours = cadmorph.read_mesh(data / name)
        theirs = cadmorph.Mesh.from_meshio(meshio.read(data / name))
        same = {t for t in set(ours.cell_types) if t not in ("wedge18", "pyramid14")}
        mine, other = by_type(ours.cells), by_type(theirs.cells)
        for t in same:  # tet10, hex27, quad9, tri6: the two gmsh permutations agree
            assert np.array_equal(mine[t], other[t]), (name, t)
    # wedge18 through VTK (meshio's gmsh reader leaves it in gmsh's order: documented)
    mesh = cadmorph.read_mesh(data / "msh/hybrid_o2_41.msh")
    cadmorph.write_mesh(work / "o2.vtu", mesh)
    theirs = meshio.read(work / "o2.vtu")  # meshio skips pyramid14 (VTK 37) with a warning
    wedge18 = np.concatenate([b.data for b in theirs.cells if b.type == "wedge18"])
    assert np.array_equal(wedge18, by_type(mesh.cells)["wedge18"])
    # hex20, quad8, tet10, tri6 through gmsh 2.2 and 4.1 files: both permutations again
    src = cadmorph.read_mesh(data / "msh/hybrid_o2i_22b.msh")
    keep = [(t, a) for t, a in src.cells if t in ("hex20", "quad8", "tet10", "tri6")]
    sub = cadmorph.Mesh.from_arrays(src.points, keep)
    assert cadmorph.quality(sub).inverted == 0
    for version in (22, 41):
        cadmorph.write_mesh(work / "o2i.msh", sub, binary=False, msh_version=version)
        back = cadmorph.Mesh.from_meshio(meshio.read(work / "o2i.msh"))
        assert np.array_equal(back.points, sub.points)
        cells_equal(back.cells, sub.cells)


def test_polyhedra_through_meshio(data):
    mesh = cadmorph.read_mesh(data / "vtk/vtk_ascii.vtu")
    m = mesh.to_meshio()
    poly = [b for b in m.cells if b.type.startswith("polyhedron")]
    assert len(poly) == 1 and poly[0].type == "polyhedron%d" % len(
        {v for face in poly[0].data[0] for v in face})
    back = cadmorph.Mesh.from_meshio(m)
    assert np.array_equal(back._cell_arrays()[2], mesh._cell_arrays()[2])


def test_polygons():
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0, 0], [2, 1, 0],
                    [3, 0.5, 0]], float)
    mesh = cadmorph.Mesh.from_arrays(pts, [("polygon", [[0, 1, 2, 3], [1, 4, 6, 5, 2]]),
                                           ("polygon", np.array([[4, 6, 5]]))])
    assert mesh.cell_types == ["polygon"] * 3
    m = mesh.to_meshio()
    assert [(b.type, b.data.shape) for b in m.cells] == [("polygon", (1, 4)),
                                                         ("polygon", (1, 5)),
                                                         ("polygon", (1, 3))]
    assert cadmorph.Mesh.from_meshio(m).cells[0][1][1].tolist() == [1, 4, 6, 5, 2]


def test_cell_sets_become_groups():
    pts, cells, *_ = small_mesh()
    m = meshio.Mesh(pts, cells, cell_sets={"volume": [np.array([0]), np.array([0, 1]),
                                                      np.array([0]), np.array([], int)],
                                           "floor": [None, None, None, np.array([1])]})
    mesh = cadmorph.Mesh.from_meshio(m)
    assert mesh.groups == [(3, 1, "volume"), (2, 2, "floor")]
    assert list(mesh.physical) == [1, 1, 1, 1, 0, 2]
    m.cell_sets["again"] = [np.array([0]), None, None, None]
    with pytest.raises(ValueError, match="'volume' and 'again'"):
        cadmorph.Mesh.from_meshio(m)


def test_to_meshio_refuses_what_meshio_cannot_hold(data):
    mesh = cadmorph.read_mesh(data / "msh/hybrid_o2i_22b.msh")
    if "wedge15" in meshio._mesh.topological_dimension:
        pytest.skip("this meshio holds wedge15")
    with pytest.raises(ValueError, match="wedge15"):
        mesh.to_meshio()


PTS = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
TET = [("tetra", np.array([[0, 1, 2, 3]]))]


def nan_points():
    p = PTS.copy()
    p[2, 1] = np.nan
    return p


@pytest.mark.parametrize("kwargs, exc, match", [
    (dict(points=np.zeros((4, 4))), ValueError, r"shape \(n, 3\)"),
    (dict(points=np.zeros(12)), ValueError, "shape"),
    (dict(points=np.zeros((0, 3)), cells=[]), ValueError, "no points"),
    (dict(points=[["a", "b", "c"]] * 4), TypeError, "real numbers"),
    (dict(points=PTS.astype(complex)), TypeError, "complex"),
    (dict(points=nan_points()), ValueError, "points row 2 is not finite"),
    (dict(points=np.full((4, 3), np.inf)), ValueError, "row 0"),
    (dict(points=[[0, 0, 0], [1, 0]]), ValueError, "rectangular"),
    (dict(cells=[("tetra", [[0, 1, 2, 4]])]), ValueError,
     r"block 0 \(tetra\) row 0: node index 4 out of range \[0, 4\)"),
    (dict(cells=[("triangle", [[0, 1, 2]]), ("tetra", [[0, 1, 2, 3], [0, 1, -1, 3]])]),
     ValueError, r"block 1 \(tetra\) row 1: node index -1"),
    (dict(cells=[("tetra", np.array([[0, 1, 2, 2**63 + 5]], np.uint64))]), ValueError,
     "out of range"),
    (dict(cells=[("tetra", [[0.0, 1.0, 2.0, 3.0]])]), TypeError, "integer node indices"),
    (dict(cells=[("tetra", [["0", "1", "2", "3"]])]), TypeError, "integer node indices"),
    (dict(cells=[("tetra", [[0, 1, 2]])]), ValueError, r"shape \(k, 4\)"),
    (dict(cells=[("tetra", [[0, 1, 2, 3], [0, 1]])]), ValueError, "rectangular"),
    (dict(cells=[("tetrahedron", [[0, 1, 2, 3]])]), ValueError, "unknown cell type"),
    (dict(cells=[(10, [[0, 1, 2, 3]])]), TypeError, "type name"),
    (dict(cells="tetra"), TypeError, "list"),
    (dict(cells=[("tetra",)]), TypeError, "pair"),
    (dict(cells=[("polygon", [[0, 1]])]), ValueError, "3 node indices or more"),
    (dict(cells=[("polyhedron", [[4, 3, 0, 1, 2, 3, 0, 1, 3]])]), ValueError, "face 2"),
    (dict(cells=[("polyhedron", [[3, 3, 0, 1, 2, 3, 0, 1, 3, 3, 1, 2, 3]])]), ValueError,
     "at least 4 faces"),
    (dict(point_data={"u": np.zeros(3)}), ValueError, "4 values expected"),
    (dict(point_data={"u": np.zeros(4, complex)}), TypeError, "real numbers"),
    (dict(point_data={"u": ["a"] * 4}), TypeError, "real numbers"),
    (dict(point_data={3: np.zeros(4)}), TypeError, "field name must be a str"),
    (dict(point_data={"": np.zeros(4)}), ValueError, "field name must be a non-empty str"),
    (dict(point_data=[np.zeros(4)]), TypeError, "dicts"),
    (dict(cell_data={"w": np.zeros(2)}), ValueError, "1 values expected"),
    (dict(cell_data={"gmsh:physical": [1.5]}), ValueError, "32-bit integer tag"),
    (dict(cell_data={"gmsh:physical": [2**40]}), ValueError, "32-bit integer tag"),
    (dict(groups=[(3, 1)]), TypeError, r"\(dim, tag, name\)"),
    (dict(groups=[(5, 1, "x")]), ValueError, r"groups\[0\]: dim must be in 0\.\.3"),
    (dict(groups=[(3, 1, None)]), TypeError, r"groups\[0\]: name must be a str"),
    (dict(groups={"x": (1, 3)}), TypeError, "groups"),
])
def test_bad_arrays(kwargs, exc, match):
    args = dict(points=PTS, cells=TET)
    args.update(kwargs)
    with pytest.raises(exc, match=match):
        cadmorph.Mesh.from_arrays(**args)


def test_from_meshio_needs_a_meshio_mesh():
    with pytest.raises(TypeError, match="meshio.Mesh"):
        cadmorph.Mesh.from_meshio({"points": PTS})


def test_points_only_and_2d_points():
    mesh = cadmorph.Mesh.from_arrays(PTS[:, :2], [])
    assert mesh.n_cells == 0 and np.array_equal(mesh.points[:, 2], np.zeros(4))
    assert np.array_equal(mesh.points[:, :2], PTS[:, :2])
    empty_block = cadmorph.Mesh.from_arrays(PTS, [("triangle", np.zeros((0, 3), int))] + TET)
    assert empty_block.cell_types == ["tet4"]
