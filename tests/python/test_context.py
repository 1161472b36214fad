"""The context every call runs in (cadmorph._context): progress reports reach the callable,
an exception of the callable or a Ctrl-C stops the call at its next progress point and is
raised again, and the library's warnings become CadmorphWarning. The long call here is the
interior optimisation (cm_mesh_optimize reports each sweep) with every cell selected."""
import _thread
import warnings

import numpy as np
import pytest

import cadmorph
from cadmorph._capi import ffi, lib
from cadmorph._context import Context


def optimize(data, progress):
    """cm_mesh_optimize on a copy of box_hole_41 through a Context with this progress; the
    reports seen and the sweeps made."""
    mesh = cadmorph.read_mesh(data / "msh" / "box_hole_41.msh")
    seen = []

    def report(stage, done, total):
        seen.append((stage, done, total))
        if progress is not None:
            progress(stage, done, total)

    opt = ffi.new("cm_optimize_options *")
    lib.cm_optimize_options_init(opt)
    opt.target_sj = 1.0  # every cell: every sweep moves something and reports
    stats = ffi.new("cm_optimize_stats *")
    before = mesh.points.copy()
    try:
        Context(1, report).call(lib.cm_mesh_optimize, mesh._ptr, ffi.NULL, opt, stats)
    finally:
        moved = not np.array_equal(before, mesh.points)
    return seen, stats.sweeps, moved


def test_progress_reaches_the_callable(data):
    seen, sweeps, moved = optimize(data, None)
    assert sweeps >= 2 and moved
    assert [s for s, _, _ in seen] == ["optimize"] * len(seen)
    assert [d for _, d, _ in seen] == list(range(1, len(seen) + 1))
    assert all(t == seen[0][2] for _, _, t in seen)


def test_exception_in_the_callable_stops_the_call(data):
    def boom(stage, done, total):
        raise ValueError("stop at %s %g" % (stage, done))

    with pytest.raises(ValueError, match="stop at optimize 1"):
        optimize(data, boom)


def test_keyboard_interrupt_during_the_call(data):
    """A Ctrl-C while the library runs (here: raised in the main thread by the callback
    itself, as a SIGINT is) comes out of the call as KeyboardInterrupt."""
    with pytest.raises(KeyboardInterrupt):
        optimize(data, lambda stage, done, total: _thread.interrupt_main())


def test_the_context_is_usable_after_an_interrupt(data):
    mesh = cadmorph.read_mesh(data / "msh" / "box_hole_41.msh")
    ctx = Context(1, lambda *a: _thread.interrupt_main())
    opt = ffi.new("cm_optimize_options *")
    lib.cm_optimize_options_init(opt)
    opt.target_sj = 1.0
    with pytest.raises(KeyboardInterrupt):
        ctx.call(lib.cm_mesh_optimize, mesh._ptr, ffi.NULL, opt, ffi.NULL)
    # no request is left behind: the next call on the same context runs to its end
    ctx._state.progress = None
    assert ctx.call(lib.cm_mesh_quality, mesh._ptr,
                    ffi.from_buffer("double[]", np.empty(int(mesh._ptr.n_cells)))) == 0


def test_progress_argument_checked():
    with pytest.raises(TypeError, match="progress must be a callable"):
        Context(0, "yes")
    with pytest.raises(ValueError, match="threads"):
        Context(-1)


def test_library_warning_is_a_cadmorph_warning():
    """A warning the library logs reaches Python as CadmorphWarning, and a warning status
    with the same message does not warn a second time."""
    ctx = Context(1, False)
    text = ffi.new("char[]", b"something odd")
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        ctx.call(lambda c: (lib.cm_log(c, lib.CM_LOG_WARNING, b"%s", text),
                            lib.cm_error(c, lib.CM_WARNING, b"%s", text))[1])
    assert [(str(x.message), x.category) for x in w] == [("something odd",
                                                         cadmorph.CadmorphWarning)]
