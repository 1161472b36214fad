"""cadmorph.ffd and Lattice against `cadmorph ffd` (bit for bit) and PyGeM's stored output
(tests/data/deform, made by make_pygem_fixture.py); the lattice's own calls; errors."""
import os
import subprocess

import meshio
import numpy as np
import pytest

import cadmorph
from pygem_prm import write_prm


def run_ffd(cli, *args):
    r = subprocess.run([cli, "ffd", *map(str, args)], capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


@pytest.mark.parametrize("name", ["bern222", "bern333_rot", "bern444_rot", "bern534_rot"])
def test_ffd_equals_pygem_and_cli(cli, data, work, name):
    rows = np.loadtxt(data / "deform" / (name + ".csv"), delimiter=",", skiprows=1)
    prm = data / "deform" / (name + ".prm")
    got = cadmorph.ffd(rows[:, :3], prm, progress=False)
    assert np.abs(got - rows[:, 3:]).max() <= 1e-13
    src, out = work / "points.vtu", work / "points_ffd.vtu"
    meshio.write(src, meshio.Mesh(rows[:, :3], [("vertex", np.arange(len(rows))[:, None])]))
    rc, so, se = run_ffd(cli, "--mesh", src, "--lattice", prm, "-o", out)
    assert rc == 0, se
    assert np.array_equal(got, cadmorph.read_mesh(out).points)
    d, st = cadmorph.Lattice.from_prm(prm).displacement(rows[:, :3], progress=False)
    assert "%d inside the lattice, %d outside" % (st.inside, st.outside) in so
    assert np.array_equal(rows[:, :3] + d, got)


def test_ffd_mesh_csv_bspline_equals_cli(cli, data, work):
    path = data / "msh/box_hole_41.msh"
    mesh = cadmorph.read_mesh(path)
    lo, hi = mesh.points.min(axis=0), mesh.points.max(axis=0)
    n = [4, 5, 4]
    prm = work / "box.prm"
    rng = np.random.default_rng(3)
    write_prm(prm, n, list(lo - 0.1), list(hi - lo + 0.2), [5.0, -10.0, 20.0],
              [0.05 * rng.standard_normal(n) for _ in range(3)])
    csv = work / "ctrl.csv"
    with open(csv, "w") as f:
        f.write("i,j,k,dx,dy,dz\n")
        for i, j, k in ((1, 1, 1), (2, 3, 2), (1, 2, 1)):
            f.write("%d,%d,%d,%r,%r,%r\n" % (i, j, k, *(0.1 * rng.standard_normal(3))))
    for extra, kw in (([], {}), (["--basis", "bspline"], {"basis": "bspline"}),
                      (["--displacements", csv, "--basis", "bspline"],
                       {"basis": "bspline", "displacements": csv})):
        out = work / "box_ffd.vtu"
        rc, so, se = run_ffd(cli, "--mesh", path, "--lattice", prm, *extra, "-o", out)
        assert rc == 0, se
        got = cadmorph.ffd(mesh, prm, progress=False, **kw)
        assert np.array_equal(got, cadmorph.read_mesh(out).points), extra
        assert not np.array_equal(got, mesh.points)
    assert np.array_equal(mesh.points, cadmorph.read_mesh(path).points)  # not changed


def test_lattice_calls():
    lat = cadmorph.Lattice((4, 4, 5), origin=(-1, -1, -1), axes=np.diag([2.0, 2.0, 2.0]))
    assert lat.n == (4, 4, 5) and lat.n_control == 80 and lat.basis == "bspline"
    c = lat.control_points
    assert c.shape == (80, 3)
    x = np.random.default_rng(1).uniform(-1, 1, (50, 3))
    x[0] = [5, 5, 5]  # outside
    # zero control displacements leave every point bit for bit
    d, st = lat.displacement(x, np.zeros((80, 3)), progress=False)
    assert np.array_equal(d, np.zeros_like(x))
    assert (st.inside, st.outside, st.failed) == (49, 1, 0)
    # a translation of every control point translates every inside point (partition of 1)
    d, st = lat.displacement(x, np.tile([0.1, 0.0, -0.2], (80, 1)), progress=False)
    np.testing.assert_allclose(d[1:], np.tile([0.1, 0.0, -0.2], (49, 1)), atol=1e-14)
    assert np.array_equal(d[0], [0, 0, 0])
    u, flags = lat.local_coords(x, progress=False)
    np.testing.assert_allclose(u[1:], (x[1:] + 1) / 2, atol=1e-14)
    assert flags[0] == 0 and np.all(flags[1:] == 1)
    # a moved lattice: the points find their coordinates by Newton's method
    lat.set_control_points(c * 1.5)
    u2, flags2 = lat.local_coords(1.5 * x[1:], progress=False)
    np.testing.assert_allclose(u2, u[1:], atol=1e-10)
    lat.set_control_points(None)
    assert np.array_equal(lat.control_points, c)
    box = cadmorph.Lattice.box((2, 2, 2), (1.0, 2.0, 3.0), basis="bernstein")
    np.testing.assert_allclose(box.control_points.max(axis=0), [1, 2, 3])


def test_ffd_errors(data, work):
    with pytest.raises(cadmorph.BadInputError, match="missing.prm"):
        cadmorph.ffd(np.zeros((1, 3)), work / "missing.prm")
    assert not os.path.exists(work / "missing.prm")  # unlike PyGeM, nothing written
    prm = work / "three.prm"
    write_prm(prm, [3, 3, 3], [0, 0, 0], [1, 1, 1], [0, 0, 0], [np.zeros((3, 3, 3))] * 3)
    with pytest.raises(cadmorph.BadInputError, match="three.prm: .*at least 4"):
        cadmorph.ffd(np.zeros((1, 3)), prm, basis="bspline")
    lat = cadmorph.Lattice.from_prm(prm)
    csv = work / "bad.csv"
    csv.write_text("i,j,k,dx,dy,dz\n1,1,x,0,0,0\n")
    with pytest.raises(cadmorph.BadInputError, match="bad.csv:2:"):
        lat.read_displacements(csv)
    with pytest.raises(ValueError, match="shape"):
        lat.displacement(np.zeros((2, 3)), np.zeros((5, 3)))
    with pytest.raises(ValueError, match="finite"):
        lat.displacement(np.array([[0, 0, np.inf]]))
    with pytest.raises(ValueError, match="basis"):
        cadmorph.ffd(np.zeros((1, 3)), prm, basis="nurbs")
    with pytest.raises(ValueError, match="n"):
        cadmorph.Lattice((4, 4))
    with pytest.raises(ValueError, match="dc is needed"):
        cadmorph.Lattice().displacement(np.zeros((1, 3)))
    with pytest.raises(cadmorph.Error, match="singular|axis|axes"):
        cadmorph.Lattice(axes=np.zeros((3, 3)))
    for obj in (cadmorph.ffd, cadmorph.Lattice, cadmorph.Lattice.from_prm,
                cadmorph.Lattice.box, cadmorph.Lattice.displacement, cadmorph.FFDStats):
        assert obj.__doc__ and obj.__doc__.strip()
