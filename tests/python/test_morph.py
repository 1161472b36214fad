"""cadmorph.Morpher and cadmorph.morph: bit for bit what `cadmorph morph` writes (the bore of
`cadmorph model`, the held-in STEP fixtures), steps, info and quality, relative morphs,
rejected adaptive steps, lifetimes of the borrowed models, memory over repeated morphs, two
threads, progress, and the checks of arguments before the library sees them."""
import ctypes
import gc
import inspect
import json
import sys
import time
import tracemalloc
import weakref

import numpy as np
import pytest

import cadmorph
from cadmorph._capi import ffi, lib
from morph_helpers import CtrlC, bore, in_child, read_step, reversed_shell, run

MORPH = sys.modules["cadmorph.morph"]  # the module (cadmorph.morph is the function)


@pytest.fixture(scope="module")
def bore_files(cli, tmp_path_factory):
    """[M0.vtu (hex mesh of G(0), scale 0.3: 1344 nodes), G(0), G(1), G(0.5)]."""
    return bore(cli, tmp_path_factory.mktemp("morph_bore"), [0, 1, 0.5], scale=0.3)


def cli_morph(cli, work, g0, g1, m0, *args, name="M1.vtu"):
    """`cadmorph morph` on one thread; the written mesh (binary vtu: lossless), read back."""
    run(cli, "morph", "--from", g0, "--to", g1, "--mesh", m0, "-o", work / name,
        "--threads", 1, *args)
    return cadmorph.read_mesh(work / name)


def test_morph_equals_cli_bit_for_bit_on_the_bore(cli, bore_files, work):
    m0, g0_path, g1_path, _ = bore_files
    ref = cli_morph(cli, work, g0_path, g1_path, m0)
    g0, g1, mesh = read_step(g0_path), read_step(g1_path), cadmorph.read_mesh(m0)
    morpher = cadmorph.Morpher(g0, mesh, threads=1, progress=False)
    pts = morpher.apply(g1)
    assert pts.shape == (mesh.n_nodes, 3) and pts.dtype == np.float64
    assert np.array_equal(pts, ref.points)
    # the per-cell quality is the CLI's scaled_jacobian field, bit for bit
    assert np.array_equal(morpher.quality, ref.cell_data["scaled_jacobian"], equal_nan=True)
    # the one-shot form writes the very file the CLI wrote
    out = cadmorph.morph(g0, g1, mesh, threads=1, progress=False)
    assert np.array_equal(out.points, ref.points)
    assert np.array_equal(out.point_data["displacement"], ref.point_data["displacement"])
    cadmorph.write_mesh(work / "py.vtu", out)
    assert (work / "py.vtu").read_bytes() == (work / "M1.vtu").read_bytes()
    # the input mesh is unchanged (the Morpher works on its own copy)
    assert np.array_equal(mesh.points, cadmorph.read_mesh(m0).points)


@pytest.mark.parametrize("options,args", [
    ({"steps": 3}, ["--steps", "3"]),
    ({"method": "femwarp"}, ["--method", "femwarp"]),
    # the baseline inverts cells: kept on request, as the CLI's --allow-inverted
    ({"steps": 2, "method": "lbwarp", "surface": "project", "allow_inverted": True},
     ["--steps", "2", "--method", "lbwarp", "--surface", "project", "--allow-inverted"]),
    ({"steps": "auto", "optimize": True}, ["--steps", "auto", "--optimize"]),
], ids=["steps3", "femwarp", "lbwarp-project-steps2", "auto-optimize"])
def test_morph_options_equal_cli_bit_for_bit(cli, bore_files, work, options, args):
    m0, g0_path, g1_path, _ = bore_files
    ref = cli_morph(cli, work, g0_path, g1_path, m0, *args)
    # the Python side with OpenBLAS on one thread, as the CLI starts it (child_env)
    in_child("morph", work / "pts.npy", g0_path, g1_path, m0,
             json.dumps(dict(options, threads=1, progress=False)))
    assert np.array_equal(np.load(work / "pts.npy"), ref.points)


@pytest.mark.parametrize("options,args", [
    ({"kernel": "biharmonic", "steps": 2}, ["--kernel", "biharmonic", "--steps", "2"]),
    ({"keep_offset": True, "cad_tol": 1e-3, "off_cad": "fixed"},
     ["--keep-offset", "--cad-tol", "1e-3", "--off-cad", "fixed"]),
    ({"method": "dmffd", "lattice": 6, "clamp": 1e-3}, ["--method", "dmffd", "--lattice", "6",
                                                       "--clamp", "1e-3"]),
], ids=["biharmonic-steps2", "keep-offset-fixed", "dmffd"])
def test_morph_cli_option_names_in_process(cli, bore_files, work, options, args):
    """The CLI's options under their Python names, in this process (the RBF and DM-FFD
    paths set OpenBLAS's threads themselves or use none)."""
    m0, g0_path, g1_path, _ = bore_files
    ref = cli_morph(cli, work, g0_path, g1_path, m0, *args)
    m = cadmorph.Morpher(read_step(g0_path), cadmorph.read_mesh(m0), threads=1,
                         progress=False, **options)
    assert np.array_equal(m.apply(read_step(g1_path)), ref.points)
    if options.get("keep_offset"):  # G' = G moves nothing
        assert np.array_equal(m.apply(read_step(g0_path)), cadmorph.read_mesh(m0).points)


@pytest.fixture(scope="module")
def fixture_meshes(cli, data, tmp_path_factory):
    """Tet meshes (gmsh, through `cadmorph mesh`) of the held-in STEP fixtures bore_a
    (tests/data/cad) and hole_a (tests/data/surface), by name."""
    work = tmp_path_factory.mktemp("fixture_meshes")
    out = {}
    for folder, name in [("cad", "bore_a"), ("surface", "hole_a")]:
        out[name] = work / (name + ".vtu")
        run(cli, "mesh", data / folder / (name + ".step"), "-o", out[name], "--threads", 1)
    return out


@pytest.mark.parametrize("folder,a,b", [("cad", "bore_a", "bore_b"),
                                        ("surface", "hole_a", "hole_b")])
def test_morph_equals_cli_on_held_in_fixtures(cli, data, work, fixture_meshes, folder, a, b):
    g0_path, g1_path = data / folder / (a + ".step"), data / folder / (b + ".step")
    m0 = fixture_meshes[a]
    ref = cli_morph(cli, work, g0_path, g1_path, m0)
    pts = cadmorph.Morpher(read_step(g0_path), cadmorph.read_mesh(m0), threads=1,
                           progress=False).apply(read_step(g1_path))
    assert np.array_equal(pts, ref.points)


def test_target_numbered_otherwise_is_renumbered_as_the_cli_does(cli, data, work,
                                                                 fixture_meshes):
    g0_path = data / "cad" / "bore_a.step"
    reversed_shell(data / "cad" / "bore_b.step", work / "bore_b_rev.step")
    m0 = fixture_meshes["bore_a"]
    ref = cli_morph(cli, work, g0_path, work / "bore_b_rev.step", m0)
    g0, g1 = read_step(g0_path), read_step(work / "bore_b_rev.step")
    assert g0.compare(g1).renumbered
    m = cadmorph.Morpher(g0, cadmorph.read_mesh(m0), threads=1, progress=False)
    assert np.array_equal(m.apply(g1), ref.points)
    comparison = g0.compare(g1)  # g1 now numbered like G, in place
    assert comparison.corresponds and not comparison.renumbered


def test_relative_morph_equals_cli(cli, bore_files, work):
    m0, g0_path, g1_path, gh_path = bore_files
    ref = cli_morph(cli, work, g0_path, g1_path, m0, "--relative", "--via", gh_path)
    g0, g1, gh = read_step(g0_path), read_step(g1_path), read_step(gh_path)
    mesh = cadmorph.read_mesh(m0)
    out = cadmorph.morph(g0, g1, mesh, via=[gh], threads=1, progress=False)
    assert np.array_equal(out.points, ref.points)
    assert np.array_equal(out.point_data["displacement"], ref.point_data["displacement"])
    # by hand: apply, rebase onto the intermediate result, apply
    m = cadmorph.Morpher(g0, mesh, threads=1, progress=False)
    half = m.apply(gh)
    m.rebase(gh, half)
    assert np.array_equal(m.mesh.points, half)
    assert np.array_equal(m.apply(g1), ref.points)
    # a rebase onto a model the mesh is not on fails; apply refuses until a rebase succeeds
    with pytest.raises(cadmorph.MismatchError):
        m.rebase(g1, half)
    with pytest.raises(cadmorph.Error, match="rebase again first"):
        m.apply(g1)
    m.rebase(gh, half)
    assert np.array_equal(m.apply(g1), ref.points)
    # relative differs from absolute (else the test could not tell them apart)
    assert not np.array_equal(cadmorph.Morpher(g0, mesh, threads=1, progress=False).apply(g1),
                              ref.points)


def test_rejected_adaptive_steps_keep_the_last_valid_mesh(cli, bore_files, work):
    m0, g0_path, g1_path, _ = bore_files
    # the whole motion ends at min SJ 0.635: a floor of 0.64 rejects the last steps
    args = ["--steps", "auto", "--min-sj", "0.64", "--no-escalate", "--min-step", "0.25"]
    r = run_status(cli, "morph", "--from", g0_path, "--to", g1_path, "--mesh", m0, "-o",
                   work / "partial.vtu", "--threads", 1, "--keep-partial", *args)
    assert r.returncode == 3
    ref = cadmorph.read_mesh(work / "partial.vtu")
    g0, g1, mesh = read_step(g0_path), read_step(g1_path), cadmorph.read_mesh(m0)
    m = cadmorph.Morpher(g0, mesh, steps="auto", min_sj=0.64, escalate=False, min_step=0.25,
                         threads=1, progress=False)
    with pytest.raises(cadmorph.RejectedError, match="no valid step: from 75 % of the motion") as e:
        m.apply(g1)
    assert e.value.status == lib.CM_ERR_REJECTED
    assert e.value.message in r.stderr  # the library's message, as the CLI prints it
    assert np.array_equal(e.value.points, ref.points)
    rows = e.value.steps
    assert rows == m.steps and len(rows) == 5
    assert [s.accepted for s in rows] == [False, True, False, True, False]
    assert all(s.note.startswith("min SJ ") for s in rows if not s.accepted)
    assert rows[-1].fraction == 1.0 and rows[1].fraction == 0.5
    # the one-shot form carries the mesh --keep-partial writes
    with pytest.raises(cadmorph.RejectedError) as e2:
        cadmorph.morph(g0, g1, mesh, steps="auto", min_sj=0.64, escalate=False,
                       min_step=0.25, threads=1, progress=False)
    assert np.array_equal(e2.value.mesh.points, ref.points)
    assert np.array_equal(e2.value.mesh.cell_data["scaled_jacobian"],
                          ref.cell_data["scaled_jacobian"], equal_nan=True)


def run_status(cli, *args):
    import subprocess
    return subprocess.run([cli] + [str(a) for a in args], capture_output=True, text=True)


def test_steps_info_and_mesh(bore_files):
    m0, g0_path, g1_path, gh_path = bore_files
    mesh = cadmorph.read_mesh(m0)
    m = cadmorph.Morpher(read_step(g0_path), mesh, steps=3, progress=False)
    assert m.steps == []
    q0 = m.quality  # before any apply: the mesh's own
    assert q0.shape == (mesh.n_cells,) and np.allclose(q0, cadmorph.quality(mesh).per_cell,
                                                       equal_nan=True)
    pts = m.apply(read_step(g1_path))
    rows = m.steps
    assert [r.step for r in rows] == [1, 2, 3]
    assert [r.fraction for r in rows] == pytest.approx([1 / 3, 2 / 3, 1])
    assert all(r.accepted and r.cells == 960 and r.inverted == 0 for r in rows)
    assert rows[-1].max_dist < 1e-9 < rows[0].max_dist
    assert rows[-1].min_sj == pytest.approx(np.nanmin(m.quality))
    # every field of the C structs is in the Python records
    names = lambda cls: [f.name for f in MORPH.fields(cls)]
    assert names(cadmorph.MorphStep) == [f for f, _ in ffi.typeof("cm_morph_step").fields]
    assert names(cadmorph.MorpherInfo) == [f for f, _ in ffi.typeof("cm_morpher_info").fields]
    assert names(cadmorph.SurfaceStats) == [f for f, _ in
                                            ffi.typeof("cm_surface_morph_stats").fields]
    info = m.info
    assert (info.nodes, info.cells, info.boundary_nodes, info.components) == (1344, 960,
                                                                              704, 1)
    assert info.counts == (10, 138, 556) and info.diagonal == pytest.approx(6.0)
    assert m.surface_stats.faces_warped == 7
    with pytest.raises(dataclass_frozen_error()):
        rows[0].step = 7
    # mesh: a copy of the start mesh, not a view of the Morpher's
    copy = m.mesh
    assert np.array_equal(copy.points, mesh.points) and copy.n_cells == mesh.n_cells
    copy.points[:] = 0
    assert np.array_equal(m.mesh.points, mesh.points)
    assert np.array_equal(m.apply(read_step(g1_path)), pts)


def dataclass_frozen_error():
    import dataclasses
    return dataclasses.FrozenInstanceError


def test_apply_with_another_method(bore_files):
    m0, g0_path, g1_path, _ = bore_files
    g0, g1, mesh = read_step(g0_path), read_step(g1_path), cadmorph.read_mesh(m0)
    # one step, inverted cells kept: the baseline (project) inverts some
    one = dict(steps=1, allow_inverted=True, progress=False)
    m = cadmorph.Morpher(g0, mesh, **one)
    rbf = m.apply(g1)
    fem = m.apply(g1, method="femwarp")
    assert np.array_equal(fem, cadmorph.Morpher(g0, mesh, method="femwarp", **one).apply(g1))
    assert not np.array_equal(fem, rbf)
    proj = m.apply(g1, surface="project")
    assert np.array_equal(proj, cadmorph.Morpher(g0, mesh, surface="project",
                                                 **one).apply(g1))
    assert np.array_equal(m.apply(g1), rbf)  # the Morpher's own method again, unchanged
    fem_m = cadmorph.Morpher(g0, mesh, method="femwarp", **one)
    assert np.array_equal(fem_m.apply(g1, kernel="triharmonic"), rbf)  # kernel: a method
    with pytest.raises(ValueError, match="method must be one of"):
        m.apply(g1, method="spline")
    with pytest.raises(TypeError, match="unknown option steps"):
        m.apply(g1, steps=2)


def test_defaults_are_the_library_and_cli_defaults():
    o, warp, surface = MORPH._morph_options("t")
    init = ffi.new("cm_morph_options *")
    lib.cm_morph_options_init(init)
    init.target_h_scale = 1.0  # the library's 0 means 1
    assert ffi.buffer(o)[:] == ffi.buffer(init)[:]
    # Morpher's keywords and their defaults are those of the checked options
    sig = inspect.signature(cadmorph.Morpher).parameters
    opts = inspect.signature(MORPH._morph_options).parameters
    for name, p in opts.items():
        if name != "what":
            assert sig[name].default == p.default, name
    w = ffi.new("cm_warp_options *")
    cadmorph._options.WarpSettings("t").fill(w)
    wi = ffi.new("cm_warp_options *")
    lib.cm_warp_options_init(wi)
    assert ffi.buffer(w)[:] == ffi.buffer(wi)[:]


def test_models_deleted_while_the_morpher_lives(bore_files):
    m0, g0_path, g1_path, _ = bore_files
    mesh = cadmorph.read_mesh(m0)
    g0, g1 = read_step(g0_path), read_step(g1_path)
    ref = cadmorph.Morpher(g0, mesh, progress=False).apply(g1)
    m = cadmorph.Morpher(g0, mesh, progress=False)
    m.apply(g1)
    w0, w1 = weakref.ref(g0), weakref.ref(g1)
    del g0, g1
    gc.collect()
    assert w0() is not None and w1() is not None  # held by the Morpher
    # other models now take memory that freed ones would give back
    others = [read_step(g0_path) for _ in range(3)]
    assert np.array_equal(m.apply(w1()), ref)
    del m, others
    gc.collect()
    assert w0() is None and w1() is None  # and let go with it
    # a Morpher holds the last target only: a study does not pile its models up
    g0, mesh = read_step(g0_path), cadmorph.read_mesh(m0)
    m = cadmorph.Morpher(g0, mesh, progress=False)
    first = read_step(g1_path)
    wf = weakref.ref(first)
    m.apply(first)
    del first
    m.apply(read_step(g1_path))
    gc.collect()
    assert wf() is None


def rss_kb() -> int:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    raise AssertionError("no VmRSS")


class _MallInfo2(ctypes.Structure):
    _fields_ = [(n, ctypes.c_size_t) for n in ("arena", "ordblks", "smblks", "hblks", "hblkhd",
                                               "usmblks", "fsmblks", "uordblks", "fordblks",
                                               "keepcost")]


def malloc_in_use() -> int:
    """Bytes the C heap has handed out and not got back (glibc's mallinfo2: arena chunks in
    use and mmapped chunks): unlike the RSS, not blurred by fragmentation or returned pages."""
    f = ctypes.CDLL(None).mallinfo2
    f.restype = _MallInfo2
    m = f()
    return m.uordblks + m.hblkhd


def test_memory_stable_over_200_morphs(cli, tmp_path_factory):
    work = tmp_path_factory.mktemp("morph_small")
    m0, g0_path, g1_path = bore(cli, work, [0, 1], scale=0.2)  # 320 nodes
    g0, g1, mesh = read_step(g0_path), read_step(g1_path), cadmorph.read_mesh(m0)

    def morphs(k):
        for i in range(k):
            if i % 20 == 0:  # new Morphers too: create and destroy
                m = cadmorph.Morpher(g0, mesh, threads=1, progress=False)
            m.apply(g1)
        gc.collect()

    morphs(40)  # warm up: the library's and NumPy's first allocations
    tracemalloc.start()
    rss0, heap0 = rss_kb(), malloc_in_use()
    snap0 = tracemalloc.take_snapshot()
    morphs(200)
    snap1 = tracemalloc.take_snapshot()
    rss1, heap1 = rss_kb(), malloc_in_use()
    tracemalloc.stop()
    grown = sum(s.size_diff for s in snap1.compare_to(snap0, "filename"))
    assert grown < 100_000, grown  # Python objects: no pile-up
    # C heap: keeping one result (7.7 kB) per morph would add 1.5 MB; the heap moves by a
    # few kB between rounds
    assert heap1 - heap0 < 64_000, (heap0, heap1)
    assert rss1 - rss0 < 8192, (rss0, rss1)  # pages: allocator noise of a few MB at most


def test_two_morphers_in_two_threads(bore_files, work):
    """Both results equal the serial ones, and the calls overlap with Python code running in
    a third thread: the GIL is released. In a child with OpenBLAS started on one thread, as
    the CLI starts it: the library sets OpenBLAS's thread count for a dense factorisation
    and restores it after, process-wide, so two morphers that factorise at once on an
    OpenBLAS started with more threads change each other's count and round differently."""
    m0, g0_path, g1_path, gh_path = bore_files
    in_child("threads", work / "threads.json", m0, g0_path, g1_path, gh_path)
    r = json.loads((work / "threads.json").read_text())
    assert r["equal"] == [True, True], r
    assert r["overlap"] > 0, r
    assert r["ticks"] > 100, r


def test_progress_reports_and_a_raising_callable(bore_files):
    m0, g0_path, g1_path, _ = bore_files
    reports = []
    g0, g1, mesh = read_step(g0_path), read_step(g1_path), cadmorph.read_mesh(m0)
    m = cadmorph.Morpher(g0, mesh, steps=2, progress=lambda *r: reports.append(r))
    assert "classify" in {r[0] for r in reports}
    reports.clear()
    ref = m.apply(g1)
    stages = [r[0] for r in reports]
    assert {"surface", "morph"} <= set(stages), stages
    assert ("morph", 2.0, 2.0) in reports
    calls = []

    def refuse(stage, done, total):
        calls.append(stage)
        if stage == "morph":
            raise ValueError("stop in %s" % stage)

    m2 = cadmorph.Morpher(g0, mesh, steps=2, progress=refuse)
    with pytest.raises(ValueError, match="stop in morph"):
        m2.apply(g1)
    # the same Morpher works afterwards, once its callable lets it
    m2._ctx._state.progress = None
    assert np.array_equal(m2.apply(g1), ref)


def test_bad_arguments_raise_before_the_library(bore_files):
    m0, g0_path, g1_path, _ = bore_files
    g0, g1, mesh = read_step(g0_path), read_step(g1_path), cadmorph.read_mesh(m0)
    for kw, kind, msg in [
            ({"steps": 0}, ValueError, "steps must be in 1..4096"),
            ({"steps": "many"}, ValueError, "steps must be 1..4096 or 'auto'"),
            ({"steps": 1.5}, TypeError, "steps must be an int"),
            ({"min_sj": 1.0}, ValueError, "min_sj"),
            ({"min_step": 0}, ValueError, "min_step"),
            ({"keep_fraction": -0.1}, ValueError, "keep_fraction"),
            ({"optimize": 1}, TypeError, "optimize must be a bool"),
            ({"escalate": "no"}, TypeError, "escalate must be a bool"),
            ({"surface": "spline"}, ValueError, "surface must be one of rbf, project"),
            ({"method": "spline"}, ValueError, "method must be one of rbf, rbf-biharmonic"),
            ({"off_cad": "ignore"}, ValueError, "off_cad must be one of refuse, fixed"),
            ({"cad_tol": 0}, ValueError, "cad_tol"),
            ({"max_samples": 0}, ValueError, "max_samples"),
            ({"target_h_scale": 0.5}, ValueError, "target_h_scale"),
            ({"surface_min_per_edge": 1}, ValueError, "surface_min_per_edge"),
            ({"surface_max_per_edge": 4}, ValueError, "surface_max_per_edge"),
            ({"tolerance": -1}, ValueError, "tolerance"),
            ({"optimize_sweeps": -1}, ValueError, "optimize_sweeps"),
            ({"threads": -2}, ValueError, "threads"),
            ({"progress": "yes"}, TypeError, "progress")]:
        with pytest.raises(kind, match=msg):
            cadmorph.Morpher(g0, mesh, **kw)
    with pytest.raises(TypeError):
        cadmorph.Morpher(g0, mesh, stepz=2)
    with pytest.raises(TypeError, match="g0 must be a cadmorph.Geometry"):
        cadmorph.Morpher(g0_path, mesh)
    with pytest.raises(TypeError, match="mesh must be a cadmorph.Mesh"):
        cadmorph.Morpher(g0, mesh.points)
    m = cadmorph.Morpher(g0, mesh, progress=False)
    with pytest.raises(TypeError, match="g1 must be a cadmorph.Geometry"):
        m.apply(mesh)
    pts = m.apply(g1)
    for bad, kind in [(pts[:-1], ValueError), (pts.T, ValueError), (pts.astype(str), TypeError),
                      (np.where(np.arange(len(pts))[:, None] == 9, np.nan, pts), ValueError)]:
        with pytest.raises(kind):
            m.rebase(g1, bad)
    with pytest.raises(TypeError, match="via must be a sequence"):
        cadmorph.morph(g0, g1, mesh, via=g1)


def test_mismatches_carry_the_library_message(cli, data, bore_files, fixture_meshes, work):
    m0, g0_path, g1_path, _ = bore_files
    mesh = cadmorph.read_mesh(m0)
    # a mesh that is not a mesh of G: the held-in bore fixture is another solid
    other = read_step(data / "cad" / "bore_a.step")
    with pytest.raises(cadmorph.MismatchError, match="boundary nodes are off the CAD model") as e:
        cadmorph.Morpher(other, mesh, progress=False)
    r = run_status(cli, "morph", "--from", data / "cad" / "bore_a.step", "--to",
                   data / "cad" / "bore_b.step", "--mesh", m0, "-o", work / "x.vtu")
    assert r.returncode == 2 and e.value.message in r.stderr
    # a target of another topology: the differences named
    g_a = read_step(data / "cad" / "bore_a.step")
    m = cadmorph.Morpher(g_a, cadmorph.read_mesh(fixture_meshes["bore_a"]), progress=False)
    with pytest.raises(cadmorph.MismatchError, match="faces: 9 in G, 10 in G'|faces"):
        m.apply(read_step(data / "cad" / "bore_2holes.step"))
    # and the Morpher still works on a right one
    m.apply(read_step(data / "cad" / "bore_b.step"))
    assert m.steps[-1].accepted
    # hostile: G' in metres (one changed unit in the STEP file), 1000x the mesh's G
    text = g0_path.read_text()
    assert "SI_UNIT(.MILLI.,.METRE.)" in text
    (work / "metres.step").write_text(text.replace("SI_UNIT(.MILLI.,.METRE.)",
                                                   "SI_UNIT($,.METRE.)"))
    r = run_status(cli, "morph", "--from", g0_path, "--to", work / "metres.step", "--mesh", m0,
                   "-o", work / "m.vtu")
    m = cadmorph.Morpher(read_step(g0_path), mesh, progress=False)
    with pytest.raises(cadmorph.MismatchError, match=r"differ in size by 1e\+03x") as e:
        m.apply(read_step(work / "metres.step"))
    assert r.returncode == 2 and e.value.message in r.stderr


def test_keyboard_interrupt_stops_a_long_morph(cli, tmp_path_factory):
    """Ctrl-C during the morph of the bore's full hex mesh with a dense factorisation of its
    6912 boundary nodes (about 7 s on one thread): KeyboardInterrupt from the call at its
    next progress point (whatever the machine's load: counted in progress reports, not
    seconds), and the same Morpher works on."""
    work = tmp_path_factory.mktemp("morph_interrupt")
    m0, g0_path, g1_path = bore(cli, work, [0, 1], scale=1)
    g0, g1, mesh = read_step(g0_path), read_step(g1_path), cadmorph.read_mesh(m0)
    ctrl_c = CtrlC(0.3)
    m = cadmorph.Morpher(g0, mesh, solver="dense", threads=1, progress=ctrl_c)
    quick = m.apply(g1, method="simplex")
    ctrl_c.reports.clear()
    with ctrl_c:
        with pytest.raises(KeyboardInterrupt):
            m.apply(g1)
        stopped = time.perf_counter()
    assert ctrl_c.sent is not None
    after = ctrl_c.after()
    assert len(after) <= 1, after  # stopped at the first progress point after the signal
    # stopped before the warp was factorised (a morph that goes on reports it, and the end
    # of its steps: ("morph", 1, 1))
    assert not any(s in ("warp factorise", "morph") and d == t
                   for _, s, d, t in ctrl_c.reports), ctrl_c.reports
    assert stopped - ctrl_c.sent < 5.0
    assert np.array_equal(m.apply(g1, method="simplex"), quick)
