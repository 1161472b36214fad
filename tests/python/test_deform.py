"""cadmorph.deform and Deformer against `cadmorph deform` (bit for bit: the CLI writes the
moved mesh in full precision), on a tet mesh with a hole and on a quad plate; argument
errors before the library."""
import os
import subprocess

import numpy as np
import pytest

import cadmorph


# The CLI executes itself again with OPENBLAS_NUM_THREADS=1 (cli/blas_reexec.c) unless this
# marker is set; DM-FFD's SVD rounds differently on another OpenBLAS thread count, so the
# bit-for-bit checks run the CLI under this process's BLAS set-up.
SAME_BLAS = dict(os.environ, CADMORPH_BLAS_REEXEC="1")


def run_cli(cli, *args):
    r = subprocess.run([cli, "deform", *map(str, args)], capture_output=True, text=True,
                       env=SAME_BLAS)
    assert r.returncode == 0, r.stderr
    return r.stdout


def write_handles(path, nodes, disp):
    with open(path, "w") as f:
        f.write("node,dx,dy,dz\n")
        for i, d in zip(nodes, disp):
            f.write("%d,%r,%r,%r\n" % (i, d[0], d[1], d[2]))


@pytest.fixture(scope="module")
def box(data):
    return cadmorph.read_mesh(data / "msh/box_hole_41.msh")


def box_handles(mesh):
    x = mesh.points
    nodes = np.flatnonzero(x[:, 0] >= x[:, 0].max() - 1e-9)
    disp = np.c_[0.05 + 0.02 * x[nodes, 1], 0.03 * x[nodes, 2], -0.01 + 0 * x[nodes, 0]]
    return nodes, disp


@pytest.mark.parametrize("method,extra", [("rbf", []), ("dmffd", ["--lattice", "6"]),
                                          ("mls", ["--samples", "60"])])
def test_deform_equals_cli_volume(cli, data, box, work, method, extra):
    path = data / "msh/box_hole_41.msh"
    nodes, disp = box_handles(box)
    write_handles(work / "H.csv", nodes, disp)
    out = work / ("out_%s.vtu" % method)
    line = run_cli(cli, "--mesh", path, "--handles", work / "H.csv",
                   "--fix-unlisted-boundary", "--method", method, *extra, "-o", out)
    kw = {"lattice": 6} if method == "dmffd" else {"samples": 60} if method == "mls" else {}
    d = cadmorph.Deformer(box, nodes, "boundary", method, progress=False, **kw)
    got = d.apply(disp)
    ref = cadmorph.read_mesh(out).points
    assert np.array_equal(got, ref), np.abs(got - ref).max()
    assert "deform: %s, %d handle nodes, %d fixed" % (method, len(nodes), len(d.fixed)) in line
    assert ("residual %.6g" % d.residual) in line
    assert not np.array_equal(got, box.points)  # the mesh moved ...
    assert np.array_equal(box.points, cadmorph.read_mesh(path).points)  # ... a copy


def test_deformer_factorised_once(box):
    nodes, disp = box_handles(box)
    d = cadmorph.Deformer(box, nodes, "boundary", "rbf", progress=False)
    a = d.apply(disp)
    b = d.apply(2 * disp)
    # linear in the displacements: the second apply reuses the factorisation
    np.testing.assert_allclose(b - box.points, 2 * (a - box.points), atol=1e-12)
    assert np.array_equal(d.apply(disp), a)
    one = cadmorph.deform(box, nodes, disp, "rbf", fixed="boundary", progress=False)
    assert np.array_equal(one, a)
    st = d.stats
    assert st["method"] == "rbf" and st["constrained"] == len(nodes) + len(d.fixed)
    assert st["free"] == box.n_nodes - st["constrained"]


def test_deform_points_array(box):
    # rbf and dmffd need no cells: an array of points gives what the mesh gives
    nodes, disp = box_handles(box)
    fixed = cadmorph.Deformer(box, nodes, "boundary", progress=False).fixed
    a = cadmorph.deform(box.points.copy(), nodes, disp, fixed=fixed, progress=False)
    b = cadmorph.deform(box, nodes, disp, fixed="boundary", progress=False)
    assert np.array_equal(a, b)
    assert np.array_equal(a[nodes], box.points[nodes] + disp)
    assert np.array_equal(a[fixed], box.points[fixed])


def plate(work, n=11):
    g = np.linspace(0.0, 1.0, n)
    X, Y = np.meshgrid(g, g)
    pts = np.c_[X.ravel(), Y.ravel(), np.zeros(n * n)]
    quads = [[j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i]
             for j in range(n - 1) for i in range(n - 1)]
    path = work / "plate.off"
    with open(path, "w") as f:
        f.write("OFF\n%d %d 0\n" % (len(pts), len(quads)))
        f.writelines("%r %r %r\n" % tuple(p) for p in pts)
        f.writelines("4 %d %d %d %d\n" % tuple(q) for q in quads)
    centre = [j * n + i for j in range(4, 7) for i in range(4, 7)]
    return path, centre


@pytest.mark.parametrize("method", ["shell", "mls"])
def test_deform_equals_cli_surface(cli, work, method):
    path, centre = plate(work)
    disp = np.tile([0.0, 0.0, 0.1], (len(centre), 1))
    write_handles(work / "H.csv", centre, disp)
    out = work / "plate_out.vtu"
    run_cli(cli, "--mesh", path, "--handles", work / "H.csv", "--fix-unlisted-boundary",
            "--method", method, "--samples", "30", "-o", out)
    mesh = cadmorph.read_mesh(path)
    got = cadmorph.deform(mesh, centre, disp, method, fixed="boundary", samples=30,
                          progress=False)
    assert np.array_equal(got, cadmorph.read_mesh(out).points)
    assert got[:, 2].max() > 0.05


def test_deform_bad_arguments(box):
    nodes, disp = box_handles(box)
    n = box.n_nodes
    with pytest.raises(ValueError, match="out of range"):
        cadmorph.deform(box, [0, n], np.zeros((2, 3)))
    with pytest.raises(ValueError, match="handles lists node 3 2 times"):
        cadmorph.deform(box, [3, 3], np.zeros((2, 3)))
    with pytest.raises(ValueError, match="shape"):
        cadmorph.deform(box, nodes, disp[:-1])
    with pytest.raises(ValueError, match="finite"):
        cadmorph.deform(box, nodes, np.full_like(disp, np.nan))
    with pytest.raises(TypeError, match="dtype"):
        cadmorph.deform(box, nodes, disp.astype(str))
    with pytest.raises(TypeError, match="integer"):
        cadmorph.deform(box, [0.5], np.zeros((1, 3)))
    with pytest.raises(ValueError, match="both a handle and fixed"):
        cadmorph.deform(box, [1, 2], np.zeros((2, 3)), fixed=[2])
    with pytest.raises(ValueError, match="method"):
        cadmorph.deform(box, nodes, disp, method="spline")
    with pytest.raises(ValueError, match="cadmorph.Mesh"):
        cadmorph.deform(box.points, nodes, disp, method="mls")
    with pytest.raises(ValueError, match="surface meshes only"):
        cadmorph.deform(box, nodes, disp, method="shell")
    with pytest.raises(ValueError, match="shape"):
        cadmorph.deform(np.zeros((5, 2)), [0], np.zeros((1, 3)))
    with pytest.raises(ValueError, match="lattice"):
        cadmorph.deform(box, nodes, disp, method="dmffd", lattice=3)
    with pytest.raises(ValueError, match="handles is empty"):
        cadmorph.deform(box, [], np.zeros((0, 3)))
    # the library's own error: coplanar constrained points for the RBF
    with pytest.raises(cadmorph.BadInputError, match="coplanar"):
        cadmorph.deform(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.5, 0.5, 1.0]]),
                        [0, 1, 2, 3], np.zeros((4, 3)), progress=False)


def test_docstrings():
    for obj in (cadmorph.deform, cadmorph.Deformer, cadmorph.Deformer.apply,
                cadmorph.Deformer.displacement, cadmorph.Deformer.stats,
                cadmorph.Deformer.n_points):
        assert obj.__doc__ and obj.__doc__.strip()


def test_deformer_keeps_its_mesh(work):
    # the shell borrows the mesh until the deformation is destroyed: the Deformer holds it
    import gc
    path, centre = plate(work)
    mesh = cadmorph.read_mesh(path)
    disp = np.tile([0.0, 0.0, 0.1], (len(centre), 1))
    d = cadmorph.Deformer(mesh, centre, "boundary", "shell", progress=False)
    ref = d.apply(disp)
    mesh.close()
    del mesh
    gc.collect()
    assert np.array_equal(d.apply(disp), ref)
