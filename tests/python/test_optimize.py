"""cadmorph.optimize against `cadmorph optimize` (bit for bit, and its first line), on a
tet mesh and on the same mesh with tangled interior nodes; copies, in place, fixed nodes."""
import subprocess

import numpy as np
import pytest

import cadmorph


def run_cli(cli, *args):
    r = subprocess.run([cli, "optimize", *map(str, args)], capture_output=True, text=True)
    assert r.returncode in (0, 3), r.stderr
    return r.stdout.splitlines()[0]


@pytest.fixture
def tangled(data, work):
    """box_hole_41 with interior nodes pushed about: inverted cells."""
    mesh = cadmorph.read_mesh(data / "msh/box_hole_41.msh")
    b = cadmorph.Deformer(mesh, [0], "boundary").fixed  # the boundary nodes
    free = np.setdiff1d(np.arange(mesh.n_nodes), np.r_[b, 0])
    rng = np.random.default_rng(7)
    mesh.points[free] += 0.08 * rng.standard_normal((len(free), 3))
    path = work / "tangled.vtu"
    cadmorph.write_mesh(path, mesh)
    return path


@pytest.mark.parametrize("opts,kw", [([], {}), (["--sweeps", "2", "--target-sj", "0.6"],
                                                {"sweeps": 2, "target_sj": 0.6})])
def test_optimize_equals_cli(cli, data, work, tangled, opts, kw):
    for path in (data / "msh/box_hole_41.msh", tangled):
        out = work / "opt.vtu"
        line = run_cli(cli, path, "-o", out, *opts)
        mesh = cadmorph.read_mesh(path)
        before = mesh.points.copy()
        pts, st = cadmorph.optimize(mesh, progress=False, **kw)
        assert np.array_equal(pts, cadmorph.read_mesh(out).points)
        assert np.array_equal(mesh.points, before)  # a copy was optimised
        assert not pts.flags.writeable
        want = ("optimize: %d interior nodes worked on, %d moves in %d passes; min scaled "
                "Jacobian %.6g -> %.6g, inverted %d -> %d"
                % (st.nodes_selected, st.moves, st.sweeps, st.min_sj_before, st.min_sj_after,
                   st.inverted_before, st.inverted_after))
        assert line == want
        assert st.moves > 0


def test_optimize_untangles_in_place(tangled):
    mesh = cadmorph.read_mesh(tangled)
    assert cadmorph.quality(mesh).inverted > 0
    pts, st = cadmorph.optimize(mesh, in_place=True, sweeps=20, progress=False)
    assert st.inverted_before > 0 and st.inverted_after < st.inverted_before
    assert np.shares_memory(pts, mesh.points)
    assert cadmorph.quality(mesh).inverted == st.inverted_after


def test_optimize_fixed(tangled):
    mesh = cadmorph.read_mesh(tangled)
    pts0, _ = cadmorph.optimize(mesh, progress=False)
    moved = np.flatnonzero(np.any(pts0 != mesh.points, axis=1))
    keep = moved[: len(moved) // 2]
    b = cadmorph.Deformer(mesh, [0], "boundary").fixed
    pts, _ = cadmorph.optimize(mesh, fixed=np.r_[b, 0, keep], progress=False)
    assert np.array_equal(pts[keep], mesh.points[keep])
    assert np.array_equal(pts[b], mesh.points[b])
    assert not np.array_equal(pts, mesh.points)


def test_optimize_errors(data, work):
    mesh = cadmorph.read_mesh(data / "msh/box_hole_41.msh")
    with pytest.raises(ValueError, match="sweeps"):
        cadmorph.optimize(mesh, sweeps=0)
    with pytest.raises(ValueError, match="target_sj"):
        cadmorph.optimize(mesh, target_sj=-1)
    with pytest.raises(ValueError, match="out of range"):
        cadmorph.optimize(mesh, fixed=[mesh.n_nodes])
    with pytest.raises(TypeError, match="cadmorph.Mesh"):
        cadmorph.optimize(mesh.points)
    off = work / "tri.off"
    off.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    with pytest.raises(cadmorph.BadInputError, match="volume"):
        cadmorph.optimize(cadmorph.read_mesh(off), progress=False)
    for obj in (cadmorph.optimize, cadmorph.OptimizeStats):
        assert obj.__doc__ and obj.__doc__.strip()
