"""cadmorph.study against `cadmorph study` and cadmorph.sweep against `cadmorph sweep` on the
bore: the CSV the library writes, every column but the timings, equal; the rows as
dataclasses; targets given as paths and as Geometry objects; a target of another topology
is a row with its error; argument errors."""
import csv
import subprocess

import numpy as np
import pytest

import cadmorph

TIMES = {"t_sample", "t_classify", "t_surface", "t_volume_solve", "t_evaluation", "t_quality",
         "t_distance", "t_write"}


def table(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return [{k: v for k, v in r.items() if k not in TIMES} for r in rows]


def run(cli, *args):
    r = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout


@pytest.fixture(scope="module")
def bore(cli, tmp_path_factory):
    """G0, its gmsh mesh (a file) and three variants: two STEP files of the bore and the
    sheet, which is not a variant of it."""
    d = tmp_path_factory.mktemp("study_bore")
    for t in ("0", "0.5", "1"):
        run(cli, "model", "bore", t, d / ("bore_%s.step" % t))
    run(cli, "mesh", d / "bore_0.step", "-o", d / "M0.vtu", "--size", "0.9")
    return d


def test_study_equals_cli(cli, data, bore, work):
    sheet = (data / "models/sheet.step").resolve()
    targets = [bore / "bore_0.5.step", sheet, bore / "bore_1.step"]
    (work / "list.txt").write_text("".join("%s\n" % p for p in targets))
    out = work / "cli"
    # the one-step morphs with their inverted cells (project inverts some); the sheet's rows
    # fail, so the CLI exits 3 at the end
    p = subprocess.run([cli, "study", "--from", bore / "bore_0.step", "--mesh", bore / "M0.vtu",
                        "--variants", work / "list.txt", "-o", out, "--mode", "both",
                        "--methods", "rbf-s,project", "--write-meshes", "none", "--steps", "1",
                        "--allow-inverted"], capture_output=True, text=True)
    assert p.returncode == 3 and "4 of 12 rows failed" in p.stderr, p.stderr
    g0 = cadmorph.read_step(bore / "bore_0.step")
    mesh = cadmorph.read_mesh(bore / "M0.vtu")
    # the last target as a Geometry: written and read back, named after its file
    with pytest.warns(cadmorph.CadmorphWarning, match="sheet"):
        r = cadmorph.study(g0, mesh, targets[:2] + [cadmorph.read_step(targets[2])],
                           methods=["rbf-s", "project"], mode="both", mesh_name="M0.vtu",
                           steps=1, allow_inverted=True, progress=False)
    r.write_csv(work / "study.csv")
    r.write_svg(work / "study.svg")
    assert table(work / "study.csv") == table(out / "study.csv")
    assert (work / "study.svg").read_text().lstrip().startswith(("<svg", "<?xml"))
    assert r.methods == ["rbf-s", "project"] and r.n_variants == 3
    assert len(r.rows) == 3 * 2 * 2 and r.n_failed == 4
    bad = [w for w in r.rows if not w.ok]
    assert {w.label for w in bad} == {"sheet"} and all(w.status_name != "ok" for w in bad)
    good = [w for w in r.rows if w.ok]
    assert {w.label for w in good} == {"bore_0.5", "bore_1"}
    assert all(w.inverted == 0 and w.cells == r.cells for w in good if w.method == "rbf-s")
    assert all(w.max_dist < 1e-9 * r.diagonal for w in good)
    with pytest.raises(Exception):
        good[0].min_sj = 1.0  # frozen


def test_study_write_meshes(bore, work):
    g0 = cadmorph.read_step(bore / "bore_0.step")
    mesh = cadmorph.read_mesh(bore / "M0.vtu")
    r = cadmorph.study(g0, mesh, [cadmorph.model("bore", 1.0)], write_meshes="all",
                       out_dir=work / "meshes", progress=False)
    (row,) = r.rows
    assert row.ok and row.method == "rbf-s" and row.mode == "absolute"
    written = cadmorph.read_mesh(work / "meshes" / ("rbf-s_absolute_%s.vtu" % row.label))
    assert written.n_nodes == mesh.n_nodes and "displacement" in written.point_data
    assert "%.6g" % cadmorph.quality(written).min_sj == "%.6g" % row.min_sj


def test_study_errors(bore):
    g0 = cadmorph.read_step(bore / "bore_0.step")
    mesh = cadmorph.read_mesh(bore / "M0.vtu")
    t = [bore / "bore_1.step"]
    with pytest.raises(ValueError, match="methods: .*rbf-s"):
        cadmorph.study(g0, mesh, t, methods="spline")
    with pytest.raises(ValueError, match="mode"):
        cadmorph.study(g0, mesh, t, mode="sideways")
    with pytest.raises(ValueError, match="out_dir"):
        cadmorph.study(g0, mesh, t, write_meshes="all")
    with pytest.raises(ValueError, match="steps"):
        cadmorph.study(g0, mesh, t, steps=0)
    with pytest.raises(TypeError, match="list"):
        cadmorph.study(g0, mesh, bore / "bore_1.step")
    with pytest.raises(TypeError, match="Geometry"):
        cadmorph.study(g0, mesh, [1.5])
    with pytest.raises(TypeError, match="Mesh"):
        cadmorph.study(g0, mesh.points, t)
    with pytest.raises(ValueError, match="no target"):
        cadmorph.study(g0, mesh, [])
    with pytest.raises(cadmorph.Error):  # M0 is not a mesh of the pipe
        cadmorph.study(cadmorph.model("pipe", 0.0), mesh, t, progress=False)


def test_study_batch(bore):
    """batch: the rows of one at a time (to rounding: the small mesh's dense solve), in the
    same order, whatever the batch size; bad sizes are ValueErrors before the library."""
    g0 = cadmorph.read_step(bore / "bore_0.step")
    mesh = cadmorph.read_mesh(bore / "M0.vtu")
    t = [bore / "bore_0.5.step", bore / "bore_1.step", bore / "bore_0.5.step"]
    rows = {}
    for b in (1, 3, "auto"):
        r = cadmorph.study(g0, mesh, t, methods="rbf-s,project", batch=b, progress=False)
        rows[b] = r.rows
    assert len(rows[1]) == 3 * 2
    for b in (3, "auto"):
        for x, y in zip(rows[1], rows[b]):
            assert (x.label, x.method, x.mode, x.status, x.inverted) == \
                (y.label, y.method, y.mode, y.status, y.inverted)
            assert abs(x.min_sj - y.min_sj) < 1e-9 and abs(x.mean_sj - y.mean_sj) < 1e-9
    for bad in (0, -2, 1001, "many", 2.5):
        with pytest.raises((ValueError, TypeError), match="batch"):
            cadmorph.study(g0, mesh, t, batch=bad)


def test_sweep_equals_cli(cli, work):
    run(cli, "sweep", "bore", "--mesh", "hex", "--steps", "2", "--size", "0.5", "--methods",
        "project,rbf-s", "--mode", "absolute", "-o", work / "cli")
    r = cadmorph.sweep("bore", "hex", steps=2, size=0.5, methods="project,rbf-s",
                       mode="absolute", progress=False)
    r.write_csv(work / "sweep.csv")
    assert table(work / "sweep.csv") == table(work / "cli" / "sweep.csv")
    assert r.methods == ["rbf-s", "project"]  # the sweeps' order, as the CLI
    assert len(r.rows) == 2 * 2 and r.model == "bore" and r.mesh == "hex"
    assert np.isclose(r.rows[-1].t, 1.0)
    with pytest.raises(ValueError, match="bracket"):
        cadmorph.sweep("bracket", "hex")
    with pytest.raises(ValueError, match="model"):
        cadmorph.sweep("teapot")
    with pytest.raises(ValueError, match="out_dir"):
        cadmorph.sweep("bore", write_step=True)
    for obj in (cadmorph.study, cadmorph.sweep, cadmorph.StudyResult, cadmorph.StudyRow,
                cadmorph.StudyResult.write_csv, cadmorph.StudyResult.write_svg):
        assert obj.__doc__ and obj.__doc__.strip()


def test_study_progress_and_stop(bore):
    g0 = cadmorph.read_step(bore / "bore_0.step")
    mesh = cadmorph.read_mesh(bore / "M0.vtu")
    targets = [bore / "bore_0.5.step", bore / "bore_1.step"]
    calls = []
    cadmorph.study(g0, mesh, targets, progress=lambda *a: calls.append(a))
    assert ("study", 2.0, 2.0) in [(s, float(d), float(t)) for s, d, t in calls]

    class Stop(Exception):
        pass

    def stop(stage, done, total):
        if stage == "study" and done >= 1:
            raise Stop()
    with pytest.raises(Stop):
        cadmorph.study(g0, mesh, targets, progress=stop)
