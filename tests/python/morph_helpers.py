"""Shared by test_morph.py and test_warp.py: STEP models as Geometry objects, the bore's
files made by the CLI, and the CLI's own runs."""
import pathlib
import subprocess
from typing import List

import cadmorph
from cadmorph._capi import ffi, lib


class _Model:
    """A STEP model owned by Python, for a package without cadmorph.read_step: what Morpher
    needs of a Geometry (its cm_cad_model * as `_ptr`)."""

    def __init__(self, path) -> None:
        ctx = cadmorph._context.Context(1, False, "test read_step")
        out = ffi.new("cm_cad_model *[1]")
        ctx.call(lib.cm_cad_read, str(path).encode(), ffi.NULL, out)
        self._ptr = ffi.gc(out[0], lambda p: lib.cm_cad_destroy(ffi.new("cm_cad_model *[1]", [p])))


def read_step(path):
    """cadmorph.read_step(path) (millimetre), or the stand-in above where it is missing."""
    if hasattr(cadmorph, "read_step"):
        return cadmorph.read_step(str(path))
    return _Model(path)


def run(cli: str, *args) -> str:
    """Runs the CLI; its stdout (an AssertionError with stderr if it fails)."""
    r = subprocess.run([cli] + [str(a) for a in args], capture_output=True, text=True)
    assert r.returncode == 0, "%s %s: exit %d\n%s" % (cli, " ".join(map(str, args)),
                                                      r.returncode, r.stderr)
    return r.stdout


def bore(cli: str, work: pathlib.Path, ts: List[float], scale: float = 0.5) -> List[pathlib.Path]:
    """The built-in bore model G(t) for each t as STEP, and the hex mesh of G(0) at scale
    (M0.vtu), in work: [M0.vtu, G(t0).step, ...]."""
    mesh = work / ("bore_M0_%g.vtu" % scale)
    run(cli, "model", "bore", 0, work / "bore_0.step", "--hex-mesh", mesh, "--scale", scale)
    out = [mesh]
    for t in ts:
        p = work / ("bore_%g.step" % t)
        run(cli, "model", "bore", t, p)
        out.append(p)
    return out
