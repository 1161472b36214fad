"""cadmorph.Warp and cadmorph.warp: bit for bit what `cadmorph warp` writes, the constrained
nodes, the checks of arrays and options before the library sees them, the library's errors,
progress and its interruption."""
import json
import threading
import time

import numpy as np
import pytest

import cadmorph
from morph_helpers import CtrlC, bore, in_child, run


@pytest.fixture(scope="module")
def bore_mesh(cli, tmp_path_factory):
    """The bore's hex mesh at scale 0.5 (4752 nodes, 1728 on the boundary)."""
    work = tmp_path_factory.mktemp("warp_bore")
    return bore(cli, work, [])[0]


def motion(x: np.ndarray) -> np.ndarray:
    """A smooth displacement of the points x (k, 3), small against the bore's cells."""
    return np.column_stack([0.05 * np.sin(x[:, 0]), 0.03 * x[:, 1] * x[:, 2],
                            -0.02 * x[:, 0] ** 2])


def write_csv(path, nodes, D) -> None:
    """The D.csv of `cadmorph warp` (repr: the shortest text that reads back exactly)."""
    with open(path, "w") as f:
        f.write("node,dx,dy,dz\n")
        for i, d in zip(nodes, D):
            f.write("%d,%r,%r,%r\n" % (i, d[0], d[1], d[2]))


def boundary_and_pins(mesh):
    """The boundary nodes and three interior ones: what `cadmorph warp` constrains for a
    D.csv listing them, unsorted (interior first) so that the row order matters."""
    b = cadmorph.Warp(mesh, progress=False).nodes
    interior = np.setdiff1d(np.arange(mesh.n_nodes), b)[[5, 100, 2000]]
    return np.concatenate([interior, b])


@pytest.mark.parametrize("method", ["rbf", "femwarp", "lbwarp"])
def test_warp_equals_cli_bit_for_bit(cli, bore_mesh, work, method):
    mesh = cadmorph.read_mesh(bore_mesh)
    nodes = boundary_and_pins(mesh)
    D = motion(mesh.points[nodes])
    write_csv(work / "D.csv", nodes, D)
    run(cli, "warp", "--mesh", bore_mesh, "--displacements", work / "D.csv",
        "-o", work / "W.vtu", "--method", method, "--threads", 1)
    ref = cadmorph.read_mesh(work / "W.vtu")  # binary vtu: lossless
    # the Python side as the CLI runs: OpenBLAS started on one thread (morph_helpers.child_env)
    np.save(work / "nodes.npy", nodes)
    np.save(work / "D.npy", D)
    in_child("warp", work / "out.npy", bore_mesh, work / "nodes.npy", work / "D.npy",
             json.dumps({"method": method, "threads": 1, "progress": False}))
    out = np.load(work / "out.npy")
    assert np.array_equal(out, ref.point_data["displacement"])
    assert np.array_equal(mesh.points + out, ref.points)
    if method == "rbf":  # the dense RBF sets OpenBLAS's threads itself: in this process too
        w = cadmorph.Warp(mesh, nodes, method=method, threads=1, progress=False)
        assert np.array_equal(w.apply(D), out)
        assert np.array_equal(cadmorph.warp(mesh, nodes, D, threads=1, progress=False), out)


def test_warp_constrained_nodes_and_properties(bore_mesh):
    mesh = cadmorph.read_mesh(bore_mesh)
    w = cadmorph.Warp(mesh, progress=False)
    b = w.nodes
    assert len(b) == 1728 and np.all(np.diff(b) > 0)  # the boundary, ascending
    assert not b.flags.writeable
    assert w.method == "rbf" and w.n_nodes == mesh.n_nodes
    D = motion(mesh.points[b])
    out = w.apply(D)
    assert out.shape == (mesh.n_nodes, 3) and out.dtype == np.float64
    assert np.array_equal(out[b], D)  # the prescribed rows exactly
    assert w.residual == 0.0 and w.fallback_nodes == 0
    assert 1e-10 <= w.tolerance <= 1e-6  # from the mesh (tests/volume/test_warp_tolerance.c)
    assert cadmorph.Warp(mesh, tolerance=3e-8, progress=False).tolerance == 3e-8
    free = np.setdiff1d(np.arange(mesh.n_nodes), b)
    assert np.abs(out[free]).max() > 1e-3  # the interior follows
    # explicitly listing the boundary (in another order) is the same warp
    perm = np.random.default_rng(1).permutation(len(b))
    w2 = cadmorph.Warp(mesh, b[perm], progress=False)
    assert np.array_equal(w2.apply(D[perm]), out)
    # the warp is reused: a second motion on the same factorisation, and the first again
    out2 = w.apply(2 * D)
    assert np.allclose(out2, 2 * out, rtol=1e-9, atol=1e-12)
    assert np.array_equal(w.apply(D), out)
    # dmffd misses by a residual; its Warp says which method it is
    wd = cadmorph.Warp(mesh, method="dmffd", lattice=5, progress=False)
    wd.apply(D)
    assert wd.method == "dmffd" and wd.residual > 0 and wd.tolerance == 0
    # kernel= is the CLI's other name for the RBF methods
    assert cadmorph.Warp(mesh, kernel="biharmonic", progress=False).method == "rbf-biharmonic"
    # solves= only weighs AUTO's choice: 1728 centres are dense either way, the same warp
    assert np.array_equal(cadmorph.Warp(mesh, solves=20, progress=False).apply(D), out)


def test_warp_apply_many_equals_applies(bore_mesh):
    """k motions in one call: each as apply gives it (to rounding with the dense solver, to
    the tolerance with the iterative one, also in warm groups), from a (k, n, 3) array or a
    sequence; checked as apply checks D."""
    mesh = cadmorph.read_mesh(bore_mesh)
    w = cadmorph.Warp(mesh, progress=False)
    D = motion(mesh.points[w.nodes])
    Ds = np.stack([D, 2 * D + 0.01, -D, D[::-1]])
    many = w.apply_many(Ds)
    assert many.shape == (4, mesh.n_nodes, 3) and many.dtype == np.float64
    for j in range(4):
        one = w.apply(Ds[j])
        assert np.array_equal(many[j, w.nodes], Ds[j])
        # the same weights but for the rounding of a multi-column solve (its blocked
        # triangular solves), which the interpolant's sums of large weights amplify
        assert np.abs(many[j] - one).max() <= 1e-9 * np.abs(Ds[j]).max()
    assert np.array_equal(w.apply_many(list(Ds)), many)  # a sequence
    assert w.apply_many([]).shape == (0, mesh.n_nodes, 3)
    wi = cadmorph.Warp(mesh, solver="iterative", warm_groups=2, progress=False)
    many = wi.apply_many(Ds)
    for j in range(4):
        one = wi.apply(Ds[j])
        assert np.abs(many[j] - one).max() <= 1e-8 * np.abs(Ds[j]).max()
    with pytest.raises(ValueError, match=r"Ds\[1\] must have shape \(1728, 3\)"):
        w.apply_many([D, D[:5]])
    with pytest.raises(TypeError, match="Ds must be an array-like"):
        w.apply_many(3.0)
    with pytest.raises(ValueError, match="warm_groups"):
        cadmorph.Warp(mesh, warm_groups=-1)


def test_warp_accepts_array_likes_without_copy(bore_mesh):
    mesh = cadmorph.read_mesh(bore_mesh)
    w = cadmorph.Warp(mesh, progress=False)
    D = motion(mesh.points[w.nodes])
    out = w.apply(D.tolist())  # lists
    assert np.array_equal(out, w.apply(D))
    assert np.array_equal(w.apply(np.asfortranarray(D)), out)  # any layout
    assert np.array_equal(w.apply(D.astype(np.float32)), w.apply(D.astype(np.float32)
                                                                   .astype(np.float64)))
    w_int = cadmorph.Warp(mesh, list(map(int, w.nodes)), progress=False)  # a list of ints
    assert np.array_equal(w_int.apply(D), out)
    w_u32 = cadmorph.Warp(mesh, w.nodes.astype(np.uint32), progress=False)
    assert np.array_equal(w_u32.apply(D), out)


def test_warp_bad_arrays_raise_before_the_library(bore_mesh):
    mesh = cadmorph.read_mesh(bore_mesh)
    n = mesh.n_nodes
    w = cadmorph.Warp(mesh, progress=False)
    k = len(w.nodes)
    with pytest.raises(ValueError, match=r"D must have shape \(1728, 3\), not \(1728, 2\)"):
        w.apply(np.zeros((k, 2)))
    with pytest.raises(ValueError, match="shape"):
        w.apply(np.zeros((n, 3)))  # every node: pass D[w.nodes]
    with pytest.raises(ValueError, match="shape"):
        w.apply(np.zeros(3 * k))
    with pytest.raises(TypeError, match="real numbers"):
        w.apply(np.full((k, 3), "x"))
    with pytest.raises(TypeError, match="real numbers"):
        w.apply(np.zeros((k, 3), complex))
    bad = np.zeros((k, 3))
    bad[7, 1] = np.nan
    with pytest.raises(ValueError, match="row 7 is not finite"):
        w.apply(bad)
    bad[7, 1] = np.inf
    with pytest.raises(ValueError, match="row 7 is not finite"):
        w.apply(bad)
    # the hostile table's displacement, refused as `cadmorph warp` refuses it (squares of it
    # overflow in the warp: LAPACK's error for the RBF, inf in the DM-FFD's result)
    bad[7, 1] = 1.7e308
    with pytest.raises(ValueError, match=r"row 7 is .* beyond any mesh \(\|d\| <= 1e\+150\)"):
        w.apply(bad)
    bad[7, 1] = -1e150
    assert np.isfinite(w.apply(bad)).all()  # the bound itself is fine
    for nodes, kind, msg in [([0, n], ValueError, r"nodes\[1\]: node index %d out of range" % n),
                             ([-1, 3], ValueError, r"nodes\[0\]: node index -1 out of range"),
                             ([3, 5, 3], ValueError, "lists node 3 2 times"),
                             ([[1, 2], [3, 4]], ValueError, "1-D"),
                             ([], ValueError, "empty"),
                             ([0.0, 1.0], TypeError, "integer node indices"),
                             (["a"], TypeError, "integer node indices")]:
        with pytest.raises(kind, match=msg):
            cadmorph.Warp(mesh, nodes, progress=False)
    with pytest.raises(TypeError, match="cadmorph.Mesh"):
        cadmorph.Warp(mesh.points)
    closed = cadmorph.read_mesh(bore_mesh)
    closed.close()
    with pytest.raises(ValueError, match="closed"):
        cadmorph.Warp(closed)


def test_warp_bad_options(bore_mesh):
    mesh = cadmorph.read_mesh(bore_mesh)
    for kw, kind, msg in [({"method": "spline"}, ValueError, "method must be one of rbf, "),
                          ({"method": 3}, TypeError, "method must be a str"),
                          ({"kernel": "quintic"}, ValueError, "kernel must be one of"),
                          ({"kernel": "biharmonic", "method": "femwarp"}, ValueError,
                           "kernel='biharmonic' is method='rbf-biharmonic'"),
                          ({"solver": "lu"}, ValueError, "solver must be one of auto, dense"),
                          ({"tolerance": 0.6}, ValueError, r"tolerance must be .* in \[0.0, 0.5\]"),
                          ({"tolerance": float("nan")}, ValueError, "tolerance"),
                          ({"lattice": 3}, ValueError, "lattice must be in 4..200"),
                          ({"lattice": 5.0}, TypeError, "lattice must be an int"),
                          ({"clamp": 0}, ValueError, "clamp"),
                          ({"cover": 0}, ValueError, "cover must be in 1..64"),
                          ({"stretch": -1}, ValueError, "stretch"),
                          ({"graded": 2}, ValueError, "graded"),
                          ({"samples": 0}, ValueError, "samples"),
                          ({"solves": 0}, ValueError, "solves"),
                          ({"threads": -1}, ValueError, "threads"),
                          ({"threads": 1.5}, TypeError, "threads"),
                          ({"progress": 5}, TypeError, "progress must be a callable")]:
        with pytest.raises(kind, match=msg):
            cadmorph.Warp(mesh, **kw)
    with pytest.raises(TypeError):
        cadmorph.Warp(mesh, methd="rbf")  # a misspelt option is not ignored


def test_warp_library_errors_carry_its_message(data):
    # a component whose boundary is flat: the RBF's numeric error, the component named
    flat = cadmorph.read_mesh(data / "warp" / "flat.vtk")
    with pytest.raises(cadmorph.BadInputError, match="component 0") as e:
        cadmorph.Warp(flat, progress=False)
    assert e.value.status == cadmorph._lib.CM_ERR_NUMERIC
    # second-order cells have no FEMWARP element: unsupported, the cell named
    o2 = cadmorph.read_mesh(data / "msh" / "hybrid_o2_41.msh")
    with pytest.raises(cadmorph.BadInputError, match=r"femwarp: cell \d+ is \w+; only linear"):
        cadmorph.Warp(o2, method="femwarp", progress=False)


def test_warp_progress_reports_and_a_raising_callable_stops(bore_mesh):
    mesh = cadmorph.read_mesh(bore_mesh)
    reports = []
    w = cadmorph.Warp(mesh, solver="dense",
                      progress=lambda stage, done, total: reports.append((stage, done, total)))
    stages = {r[0] for r in reports}
    assert "rbf factor" in stages or "warp factorise" in stages, reports
    assert all(isinstance(s, str) and isinstance(d, float) and isinstance(t, float)
               for s, d, t in reports)
    assert reports[-1][1] == reports[-1][2]  # the last report says done
    w.apply(np.zeros((len(w.nodes), 3)))

    def refuse(stage, done, total):
        raise ValueError("stop at %s" % stage)

    with pytest.raises(ValueError, match="stop at "):
        cadmorph.Warp(mesh, solver="dense", progress=refuse)


def test_warp_releases_the_gil(bore_mesh):
    """While one thread is inside the library (a dense factorisation, without progress
    callbacks), this thread runs Python: with the GIL held it could not tick in between."""
    mesh = cadmorph.read_mesh(bore_mesh)
    window = []

    def build():
        t0 = time.perf_counter()
        cadmorph.Warp(mesh, solver="dense", threads=1, progress=False)
        window.extend([t0, time.perf_counter()])

    ticks = []
    t = threading.Thread(target=build)
    t.start()
    while t.is_alive():
        ticks.append(time.perf_counter())
    t.join()
    t0, t1 = window
    inside = [x for x in ticks if t0 < x < t1]
    assert t1 - t0 > 0.01
    assert len(inside) > 100, (len(inside), t1 - t0)


def test_keyboard_interrupt_stops_a_long_warp(cli, tmp_path_factory):
    """Ctrl-C (SIGINT from a timer thread) during the dense factorisation of a warp of the
    bore's 6912 boundary nodes (about 6 s on one thread): KeyboardInterrupt from the call at
    its next progress point (counted in reports, not seconds), nothing made, and the next
    call runs."""
    m0 = bore(cli, tmp_path_factory.mktemp("warp_interrupt"), [], scale=1)[0]
    mesh = cadmorph.read_mesh(m0)
    with CtrlC(0.3) as ctrl_c:
        with pytest.raises(KeyboardInterrupt):
            cadmorph.Warp(mesh, solver="dense", threads=1, progress=ctrl_c)
        stopped = time.perf_counter()
    assert ctrl_c.sent is not None
    after = ctrl_c.after()
    assert len(after) <= 1, after
    # the warp's factorisation did not finish (it reports "warp factorise" when it does);
    # the report at which the KeyboardInterrupt is raised is not recorded
    assert not any(s == "warp factorise" for _, s, d, t in ctrl_c.reports), ctrl_c.reports
    assert stopped - ctrl_c.sent < 5.0
    w = cadmorph.Warp(mesh, method="simplex", threads=1, progress=False)
    D = motion(mesh.points[w.nodes])
    assert np.array_equal(w.apply(D)[w.nodes], D)
