"""No inverted mesh unless asked: Morpher, morph and study on the FreeCAD bracket whose
shoulder edit (bracket_2) inverts interior cells in one step (tests/cad/freecad.cmake).
The plain one-step morph raises RejectedError with the last valid mesh (the Morpher's own);
allow_inverted=True returns the inverted mesh, bit for bit what `cadmorph morph --steps 1
--allow-inverted` writes; the default (adaptive steps with the escalation) is valid."""
import numpy as np
import pytest

import cadmorph
from cadmorph._capi import lib
from morph_helpers import read_step, run


@pytest.fixture(scope="module")
def bracket(cli, data, tmp_path_factory):
    """(G0, G2 the shoulder edit, G_re the re-export: paths), M0.msh by gmsh."""
    d = data / "freecad"
    mesh = tmp_path_factory.mktemp("guard") / "bracket_0.msh"
    run(cli, "mesh", d / "bracket_0.step", "-o", mesh, "--mesher", "gmsh", "--threads", 1)
    return d / "bracket_0.step", d / "bracket_2.step", d / "bracket_re.step", mesh


def test_one_step_refused_with_the_last_valid_mesh(bracket):
    g0_path, g2_path, _, m0 = bracket
    g0, g2, mesh = read_step(g0_path), read_step(g2_path), cadmorph.read_mesh(m0)
    m = cadmorph.Morpher(g0, mesh, steps=1, threads=1, progress=False)
    with pytest.raises(cadmorph.RejectedError,
                       match="step 1 of 1: the one-step morph leaves [1-9][0-9]* inverted") as e:
        m.apply(g2)
    assert e.value.status == lib.CM_ERR_REJECTED
    # nothing was valid but the start: the Morpher's own mesh
    assert np.array_equal(e.value.points, mesh.points)
    (row,) = e.value.steps
    assert not row.accepted and row.inverted > 0 and row.note.startswith("%d inverted: cell "
                                                                         % row.inverted)
    with pytest.raises(cadmorph.RejectedError) as e2:
        cadmorph.morph(g0, g2, mesh, steps=1, threads=1, progress=False)
    assert np.array_equal(e2.value.mesh.points, mesh.points)


def test_allow_inverted_returns_what_the_cli_writes(cli, bracket, work):
    g0_path, g2_path, _, m0 = bracket
    run(cli, "morph", "--from", g0_path, "--to", g2_path, "--mesh", m0, "-o", work / "M1.vtu",
        "--steps", 1, "--allow-inverted", "--threads", 1)
    ref = cadmorph.read_mesh(work / "M1.vtu")
    g0, g2, mesh = read_step(g0_path), read_step(g2_path), cadmorph.read_mesh(m0)
    out = cadmorph.morph(g0, g2, mesh, steps=1, allow_inverted=True, threads=1, progress=False)
    assert np.array_equal(out.points, ref.points)
    assert cadmorph.quality(out).inverted > 0
    m = cadmorph.Morpher(g0, mesh, steps=1, allow_inverted=True, threads=1, progress=False)
    assert np.array_equal(m.apply(g2), ref.points)
    assert m.steps[-1].accepted and m.steps[-1].inverted > 0
    with pytest.raises(TypeError, match="allow_inverted must be a bool"):
        cadmorph.Morpher(g0, mesh, allow_inverted=1)


def test_default_is_valid(bracket):
    g0_path, g2_path, _, m0 = bracket
    g0, g2, mesh = read_step(g0_path), read_step(g2_path), cadmorph.read_mesh(m0)
    # no step length saves the squeezed cell: the rest is morphed with interior optimisation
    with pytest.warns(cadmorph.CadmorphWarning, match="the rest is morphed with it"):
        out = cadmorph.morph(g0, g2, mesh, threads=1, progress=False)
    assert cadmorph.quality(out).inverted == 0
    # without the escalation: refused
    with pytest.raises(cadmorph.RejectedError, match="no valid step"):
        cadmorph.Morpher(g0, mesh, escalate=False, threads=1, progress=False).apply(g2)


def test_study_row_of_a_refused_morph(bracket, work):
    g0_path, g2_path, re_path, m0 = bracket
    g0, mesh = read_step(g0_path), cadmorph.read_mesh(m0)
    with pytest.warns(cadmorph.CadmorphWarning, match="1 of 2 rows failed"):
        r = cadmorph.study(g0, mesh, [re_path, g2_path], steps=1, write_meshes="all",
                           out_dir=work, threads=1, progress=False)
    assert r.n_failed == 1
    ok, bad = r.rows
    assert ok.ok and ok.inverted == 0 and (work / "rbf-s_absolute_bracket_re.vtu").exists()
    assert bad.status == lib.CM_ERR_REJECTED and bad.status_name == "result rejected"
    assert "inverted" in bad.message
    assert not (work / "rbf-s_absolute_bracket_2.vtu").exists()
    r = cadmorph.study(g0, mesh, [g2_path], steps=1, allow_inverted=True, threads=1,
                       progress=False)
    assert r.n_failed == 0 and r.rows[0].inverted > 0
