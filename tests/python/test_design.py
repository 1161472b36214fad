"""Design tables, design velocities and gradients (cadmorph.DesignTable, Morpher.design_velocity,
Morpher.gradient, `cadmorph sensitivity`): the table reader as CAD exports write tables and its
errors; velocities that geometry fixes exactly (a face translated by a length parameter, a
bore growing with its radius: a two-parameter gmsh family); the gradient of a linear
functional equals sum c . V; a held-out parameter value's velocity agrees with central
differences of two full `cadmorph morph` runs to O(delta^2)."""
import csv
import pathlib
import subprocess

import numpy as np
import pytest

import cadmorph
from morph_helpers import read_step, run


def gmsh_block(path: pathlib.Path, lx: float, r: float) -> None:
    """A block lx x 8 x 4 with a bore of radius r along z at (lx/2 - 1, 4): gmsh's
    OpenCASCADE writer, an independent maker of a two-parameter family."""
    gmsh = pytest.importorskip("gmsh")
    gmsh.initialize(["-noenv"])
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("block")
    occ = gmsh.model.occ
    block = occ.addBox(0, 0, 0, lx, 8, 4)
    occ.cut([(3, block)], [(3, occ.addCylinder(4, 4, -1, 0, 0, 6, r))])
    occ.synchronize()
    gmsh.write(str(path))
    gmsh.finalize()


@pytest.fixture(scope="module")
def block(cli, tmp_path_factory):
    """Two parameters, lx (central) and r (forward only), one row changing both, and M0."""
    d = tmp_path_factory.mktemp("design_block")
    rows = [("base.step", 10.0, 2.0), ("lx_p.step", 10.1, 2.0), ("lx_m.step", 9.9, 2.0),
            ("r_p.step", 10.0, 2.05), ("both.step", 10.1, 2.05)]
    for name, lx, r in rows:
        gmsh_block(d / name, lx, r)
    # CRLF, a quoted header name and a quoted path, blank lines: as spreadsheets export
    text = 'step,"lx",r\r\n\r\n' + "".join('"%s",%g,%g\r\n' % row for row in rows)
    (d / "T.csv").write_bytes(text.encode())
    run(cli, "mesh", d / "base.step", "-o", d / "M0.vtu", "--size", "1.2")
    return d


def test_table_as_exported(block):
    t = cadmorph.DesignTable.read(block / "T.csv")
    assert t.parameters == ["lx", "r"]
    rows = t.rows
    assert len(rows) == 5 and rows[1].values == {"lx": 10.1, "r": 2.0}
    assert rows[0].path == str(block / "base.step") and rows[0].line == 3
    assert t.row_of(block / "r_p.step") == 3


@pytest.mark.parametrize("text,where,what", [
    ("name,a\nx.step,1\n", ":1:", "expected the header step"),
    ("step,a,a\nx.step,1,2\n", ":1:", "named twice"),
    ("step,a\nx.step,1,2\n", ":2:", "expected 2 columns"),
    ("step,a\nx.step,abc\n", ":2:", "a: expected a finite number, got 'abc'"),
    ("step,a\nmissing.step,1\n", ":2:", "missing.step"),
    ("step,a\n", "", "no rows"),
])
def test_table_errors_name_path_and_line(block, work, text, where, what):
    (work / "x.step").write_bytes((block / "base.step").read_bytes())
    p = work / "T.csv"
    p.write_text(text)
    with pytest.raises(cadmorph.BadInputError) as e:
        cadmorph.DesignTable.read(p)
    assert str(p) + where in e.value.message and what in e.value.message


def test_two_parameter_velocities_that_geometry_fixes(block):
    t = cadmorph.DesignTable.read(block / "T.csv")
    g0, m0 = read_step(block / "base.step"), cadmorph.read_mesh(block / "M0.vtu")
    mp = cadmorph.Morpher(g0, m0, threads=1, progress=False)
    with _no_warning():
        v = mp.design_velocity(t)
    assert set(v) == {"lx", "r"}
    diff = mp.design_differences
    assert diff["lx"][0] == "central" and diff["r"][0] == "forward"
    x = m0.points
    # the face x = lx moves with lx, rigidly: dX/dlx = (1, 0, 0) there, 0 on x = 0
    far, near = np.abs(x[:, 0] - 10) < 1e-9, np.abs(x[:, 0]) < 1e-9
    assert far.sum() > 10 and near.sum() > 10
    assert np.abs(v["lx"][far] - [1, 0, 0]).max() < 1e-6
    assert np.abs(v["lx"][near]).max() < 1e-6
    # the bore's nodes move radially by dr: (dX/dr) . e_r = 1, and the block's faces not at all
    rho = np.hypot(x[:, 0] - 4, x[:, 1] - 4)
    on_bore = np.abs(rho - 2) < 1e-7
    assert on_bore.sum() > 10
    e_r = np.stack([(x[:, 0] - 4) / rho, (x[:, 1] - 4) / rho], axis=1)
    radial = (v["r"][on_bore, :2] * e_r[on_bore]).sum(axis=1)
    assert np.abs(radial - 1).max() < 1e-5
    assert np.abs(v["r"][far]).max() < 1e-6
    # the interior follows: some interior node moves with each parameter
    assert np.abs(v["lx"][~(far | near | on_bore)]).max() > 0.05


class _no_warning:
    """Warnings off (the library's notes on ignored rows are CadmorphWarnings only when
    parameters are skipped; none here, but a mesher's warning is not this test's subject)."""

    def __enter__(self):
        import warnings
        self.w = warnings.catch_warnings()
        self.w.__enter__()
        warnings.simplefilter("ignore")

    def __exit__(self, *exc):
        self.w.__exit__(*exc)


def test_gradient_of_a_linear_functional(block):
    """J = sum c . X: dJ/dp = sum c . V, to 1e-10 relative, whichever product computes it;
    a sensitivity on the boundary only gives sum over the boundary."""
    t = cadmorph.DesignTable.read(block / "T.csv")
    g0, m0 = read_step(block / "base.step"), cadmorph.read_mesh(block / "M0.vtu")
    mp = cadmorph.Morpher(g0, m0, threads=1, progress=False)
    with _no_warning():
        v = mp.design_velocity(t)
        c = np.random.default_rng(3).normal(size=(m0.n_nodes, 3))
        g = mp.gradient(t, c)
        gb = mp.gradient(t, c, boundary_only=True)
    vb = {k: a.copy() for k, a in v.items()}
    for k in v:
        ref = float((c * v[k]).sum())
        assert abs(g[k] - ref) <= 1e-10 * abs(ref), (k, g[k], ref)
    # boundary only: the boundary nodes are those the warp pins (the classification's)
    flags = np.frombuffer(cadmorph._ffi.buffer(cadmorph._lib.cm_morpher_boundary_flags(mp._mp),
                                               m0.n_nodes), np.uint8).astype(bool)
    for k in v:
        ref = float((c[flags] * vb[k][flags]).sum())
        assert abs(gb[k] - ref) <= 1e-10 * abs(ref)
        assert abs(gb[k] - g[k]) > 1e-6 * abs(g[k])  # the interior does count


def test_held_out_parameter_value_against_full_morphs(cli, tmp_path_factory):
    """The bore at T0 = 0.5 (table rows 0.5 +- 0.01): its velocity against central
    differences of `cadmorph morph` onto G(0.5 +- delta) at two held-out deltas; the error
    falls like delta^2 (ratio about (0.08^2 - 0.01^2) / ... = 0.24 between the deltas)."""
    d = tmp_path_factory.mktemp("design_bore")
    run(cli, "model", "bore", 0, d / "b0.step", "--hex-mesh", d / "m0.vtu", "--scale", 0.3)
    ts = [0.5, 0.49, 0.51, 0.46, 0.54, 0.42, 0.58]
    for t in ts:
        run(cli, "model", "bore", t, d / ("b%g.step" % t))
    run(cli, "morph", "--from", d / "b0.step", "--to", d / "b0.5.step", "--mesh", d / "m0.vtu",
        "-o", d / "M0.vtu", "--threads", 1)
    (d / "T.csv").write_text("step,t\nb0.5.step,0.5\nb0.51.step,0.51\nb0.49.step,0.49\n")
    run(cli, "sensitivity", "--from", d / "b0.5.step", "--mesh", d / "M0.vtu", "--design-table",
        d / "T.csv", "-o", d / "out", "--threads", 1)
    vel = cadmorph.read_mesh(d / "out" / "velocity.vtu").point_data["dX_dt"]
    errs = []
    for delta in (0.04, 0.08):
        xs = []
        for t in (0.5 + delta, 0.5 - delta):
            out = d / ("M_%g.vtu" % t)
            run(cli, "morph", "--from", d / "b0.5.step", "--to", d / ("b%g.step" % t), "--mesh",
                d / "M0.vtu", "-o", out, "--threads", 1)
            xs.append(cadmorph.read_mesh(out).points)
        fd = (xs[0] - xs[1]) / (2 * delta)
        errs.append(np.abs(fd - vel).max() / np.abs(vel).max())
    print("held-out errors (delta 0.04, 0.08):", errs)
    assert errs[0] < 1e-2, errs
    assert 0.1 < errs[0] / errs[1] < 0.4, errs  # O(delta^2): 0.24 expected


def test_cli_outputs_and_errors(cli, block, work):
    out = work / "out"
    c = np.random.default_rng(5).normal(size=(cadmorph.read_mesh(block / "M0.vtu").n_nodes, 3))
    with open(work / "S.csv", "w") as f:
        f.write("node,gx,gy,gz\n")
        for k, row in enumerate(c):
            f.write("%d,%.17g,%.17g,%.17g\n" % (k, *row))
    stdout = run(cli, "sensitivity", "--from", block / "base.step", "--mesh", block / "M0.vtu",
                 "--design-table", block / "T.csv", "-o", out, "--dJdX", work / "S.csv",
                 "--threads", 1)
    assert "central" in stdout and "forward" in stdout
    rows = list(csv.DictReader(open(out / "gradient.csv")))
    assert [r["parameter"] for r in rows] == ["lx", "r"]
    assert rows[0]["difference"] == "central" and rows[1]["difference"] == "forward"
    vel = np.loadtxt(out / "velocity.csv", delimiter=",", skiprows=1)
    header = open(out / "velocity.csv").readline().strip().split(",")
    assert header == ["node", "x", "y", "z", "dx_dlx", "dy_dlx", "dz_dlx", "dx_dr", "dy_dr",
                      "dz_dr"]
    for j, r in enumerate(rows):
        ref = float((c * vel[:, 4 + 3 * j:7 + 3 * j]).sum())
        assert abs(float(r["dJdp"]) - ref) <= 1e-10 * abs(ref)
    m = cadmorph.read_mesh(out / "velocity.vtu")
    assert np.array_equal(m.point_data["dX_dlx"], vel[:, 4:7])
    # the same sensitivity as the point field dJdX of a mesh of M0's nodes
    m0 = cadmorph.read_mesh(block / "M0.vtu")
    cadmorph.write_mesh(work / "S.vtu", cadmorph.Mesh.from_arrays(m0.points, m0.cells,
                                                                   point_data={"dJdX": c}))
    run(cli, "sensitivity", "--from", block / "base.step", "--mesh", block / "M0.vtu",
        "--design-table", block / "T.csv", "-o", work / "out_vtu", "--dJdX", work / "S.vtu",
        "--threads", 1)
    assert (work / "out_vtu" / "gradient.csv").read_text() == (out / "gradient.csv").read_text()
    # a bad sensitivity file: exit 2 naming path:line, no output directory made
    (work / "bad.csv").write_text("node,gx,gy,gz\n0,1,2\n")
    r = subprocess.run([cli, "sensitivity", "--from", block / "base.step", "--mesh",
                        block / "M0.vtu", "--design-table", block / "T.csv", "-o", work / "none",
                        "--dJdX", work / "bad.csv"], capture_output=True, text=True)
    assert r.returncode == 2 and "bad.csv:2:" in r.stderr and not (work / "none").exists()
    h = subprocess.run([cli, "sensitivity", "--help"], capture_output=True, text=True)
    assert h.returncode == 0 and "dX_d<p>" in h.stdout and "mesh unit" in h.stdout


def test_arguments_checked_before_the_library(block):
    t = cadmorph.DesignTable.read(block / "T.csv")
    g0, m0 = read_step(block / "base.step"), cadmorph.read_mesh(block / "M0.vtu")
    mp = cadmorph.Morpher(g0, m0, threads=1, progress=False)
    with pytest.raises(ValueError):
        mp.gradient(t, np.zeros((3, 3)))
    with pytest.raises(TypeError):
        mp.design_velocity("T.csv")
    with pytest.raises(TypeError):
        cadmorph.DesignTable()
    for name in ("DesignTable", "DesignRow"):
        assert getattr(cadmorph, name).__doc__
    for f in (cadmorph.Morpher.design_velocity, cadmorph.Morpher.gradient,
              cadmorph.DesignTable.read):
        assert f.__doc__ and f.__annotations__


def test_reverse_product_with_the_shared_factorisation(block):
    """<v, J d> = <J^T v, d> through the Morpher's own factorisation, and the gradient by
    the reverse product is the forward one (1e-10)."""
    from cadmorph._capi import ffi, lib
    g0, m0 = read_step(block / "base.step"), cadmorph.read_mesh(block / "M0.vtu")
    mp = cadmorph.Morpher(g0, m0, threads=1, progress=False)
    rng = np.random.default_rng(7)
    flags = np.frombuffer(ffi.buffer(lib.cm_morpher_boundary_flags(mp._mp), m0.n_nodes),
                          np.uint8).astype(bool)
    d = np.where(flags[:, None], rng.normal(size=(m0.n_nodes, 3)), 0.0)
    jd = d.copy()
    mp._ctx.call(lib.cm_morpher_warp_forward, mp._mp, ffi.from_buffer("double[]", jd))
    v = rng.normal(size=(m0.n_nodes, 3))
    jtv = np.zeros_like(v)
    mp._ctx.call(lib.cm_morpher_warp_transpose, mp._mp, ffi.from_buffer("double[]", v),
                 ffi.from_buffer("double[]", jtv))
    lhs, rhs = float((v * jd).sum()), float((jtv * d).sum())
    assert abs(lhs - rhs) <= 1e-10 * abs(lhs)
    assert np.all(jtv[~flags] == 0)


def test_study_accepts_a_design_table(cli, block, work):
    """`cadmorph study --variants T.csv`: every row but G0's is a variant, study.csv gains the
    parameter columns; two parameters vary: the plot is against the variant; with one, against
    that parameter (its name on the x axis, M0 at G0's value)."""
    run(cli, "study", "--from", block / "base.step", "--mesh", block / "M0.vtu", "--variants",
        block / "T.csv", "-o", work / "two", "--write-meshes", "none", "--threads", 1)
    rows = list(csv.DictReader(open(work / "two" / "study.csv")))
    assert [r["variant"] for r in rows] == ["lx_p", "lx_m", "r_p", "both"]
    assert [(float(r["lx"]), float(r["r"])) for r in rows] == \
        [(10.1, 2.0), (9.9, 2.0), (10.0, 2.05), (10.1, 2.05)]
    assert all(r["status"] == "ok" for r in rows)
    assert ">variant</text>" in (work / "two" / "study.svg").read_text()
    one = work / "one.csv"
    one.write_text('step,lx,r\n"%s",10,2\n"%s",10.1,2\n"%s",9.9,2\n'
                   % (block / "base.step", block / "lx_p.step", block / "lx_m.step"))
    run(cli, "study", "--from", block / "base.step", "--mesh", block / "M0.vtu", "--variants",
        one, "-o", work / "one", "--write-meshes", "none", "--threads", 1)
    svg = (work / "one" / "study.svg").read_text()
    assert ">lx</text>" in svg and "over the sweep" in svg
    # the polyline runs in the order of lx: 9.9, M0 at 10, 10.1
    import re
    pts = re.search(r'<polyline[^>]*points="([^"]*)"', svg).group(1).split()
    xs = [float(p.split(",")[0]) for p in pts]
    assert len(xs) == 3 and xs[0] < xs[1] < xs[2]


def test_velocities_of_several_parameters_in_one_forward_product(block):
    """design_velocity carries the parameters' boundary velocities into the interior together
    (cm_morpher_warp_forward_many): each equals its own forward product (cm_morpher_warp_forward)
    of the same boundary velocity, to rounding (dense solve)."""
    from cadmorph._capi import ffi, lib
    t = cadmorph.DesignTable.read(block / "T.csv")
    g0, m0 = read_step(block / "base.step"), cadmorph.read_mesh(block / "M0.vtu")
    mp = cadmorph.Morpher(g0, m0, threads=1, progress=False)
    with _no_warning():
        v = mp.design_velocity(t)
        vb = mp._velocities("test", t, None, False)
    n, nn = int(vb.n_parameters), int(vb.n_nodes)
    data = np.frombuffer(ffi.buffer(vb.v, 8 * n * nn * 3), np.float64).reshape(n, nn, 3)
    assert len(v) == 2
    for j, name in enumerate(t.parameters):
        if name not in v:
            continue
        one = data[j].copy()
        mp._ctx.call(lib.cm_morpher_warp_forward, mp._mp, ffi.from_buffer("double[]", one))
        scale = np.abs(one).max()
        assert scale > 0
        assert np.abs(v[name] - one).max() <= 1e-10 * scale, name
