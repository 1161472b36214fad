"""The cm_context every call runs in: threads, the library's messages as exceptions and
warnings, progress to a Python callable, and Ctrl-C.

Long calls report progress at points where they can stop cleanly (core.h, cm_progress). The
context hands each report to the caller's `progress` callable; whatever that callable raises,
and a KeyboardInterrupt that arrives while the library runs (Python delivers it in the
callback, the next Python code that runs on the main thread), asks the library to stop
(cm_context_interrupt): the call returns at its next progress point with nothing written, and
the exception is raised again from the call. The library's log goes to the logger
"cadmorph" (debug and info) and to CadmorphWarning (warnings).
"""
import logging
import sys
import time
import warnings
from typing import Any, Callable, Optional, Union

from ._capi import ffi, lib
from ._inputs import integer
from .errors import CadmorphWarning, ResourceError, error_class

ProgressFn = Callable[[str, float, float], Any]
"""progress(stage, done, total): stage a short name ("surface", "rbf factor", "study"), done
and total units of work; raising in it stops the call (the exception propagates)."""

Progress = Union[None, bool, ProgressFn]

_log = logging.getLogger("cadmorph")
_LOG_LEVELS = {0: logging.DEBUG, 1: logging.INFO}


class _TerminalProgress:
    """The CLI's progress line on stderr ("stage  42.0%"), drawn only when stderr is a
    terminal and at most ten times a second."""

    def __init__(self) -> None:
        self.last = 0.0

    def __call__(self, stage: str, done: float, total: float) -> None:
        stream = sys.stderr
        if stream is None or not stream.isatty():
            return
        now, finished = time.monotonic(), done >= total
        if not finished and now - self.last < 0.1:
            return
        self.last = now
        stream.write("\r\033[K%s %5.1f%%" % (stage, 100.0 * done / total if total > 0 else 100.0))
        if finished:
            stream.write("\r\033[K")
        stream.flush()


class _State:
    """What the callbacks need, without a reference back to the Context (no cycle)."""

    def __init__(self, progress: Optional[ProgressFn]) -> None:
        self.progress = progress
        self.ptr = None
        self.pending: Optional[BaseException] = None
        self.warned: set = set()  # warnings the log gave during the current call

    def stop(self, exc: BaseException) -> None:
        if self.pending is None:
            self.pending = exc
        lib.cm_context_interrupt(self.ptr)


def _progress_fn(progress: Progress) -> Optional[ProgressFn]:
    """The callable that receives progress, or None."""
    if progress is None or progress is True:
        return _TerminalProgress()
    if progress is False:
        return None
    if not callable(progress):
        raise TypeError("progress must be a callable (stage, done, total), None or False, "
                        "not %s" % type(progress).__name__)
    return progress


class Context:
    """A cm_context for one call or for one object's calls (a Morpher, a Warp): not shared
    between threads, as the C API requires.

    threads: OpenMP/BLAS threads of its calls, 0 = all. progress: a callable
    (stage, done, total), None for the CLI's progress line when stderr is a terminal, False
    for none. what: the Python name that argument errors start with.
    """

    def __init__(self, threads: int = 0, progress: Progress = None,
                 what: str = "cadmorph") -> None:
        p = ffi.new("cm_context *[1]")
        s = lib.cm_context_create(p)
        if s != lib.CM_OK:
            raise ResourceError(s, "cm_context_create failed")
        self.ptr = owned(p[0], lib.cm_context_destroy)
        # 0: all the machine has
        lib.cm_context_set_threads(self.ptr, integer(what, "threads", threads, 0, 4096))
        state = self._state = _State(_progress_fn(progress))
        state.ptr = self.ptr

        def on_progress(user, stage, done, total):
            # Python code on the main thread: a pending KeyboardInterrupt is raised here
            if state.progress is not None:
                state.progress(ffi.string(stage).decode("utf-8", "replace"), done, total)

        def on_error(exc_type, exc, tb):
            state.stop(exc if exc is not None else exc_type())

        def on_log(user, level, message):
            text = ffi.string(message).decode("utf-8", "replace")
            if level >= lib.CM_LOG_WARNING:
                state.warned.add(text)
                warnings.warn(text, CadmorphWarning, stacklevel=2)
            else:
                _log.log(_LOG_LEVELS.get(level, logging.DEBUG), "%s", text)

        self._callbacks = (ffi.callback("cm_progress_fn", on_progress, onerror=on_error),
                           ffi.callback("cm_log_fn", on_log, onerror=on_error))
        lib.cm_context_set_progress(self.ptr, self._callbacks[0], ffi.NULL)
        lib.cm_context_set_log(self.ptr, self._callbacks[1], ffi.NULL)

    def message(self) -> str:
        """The library's message of the last error or warning ("" if none)."""
        return ffi.string(lib.cm_context_message(self.ptr)).decode("utf-8", "replace")

    def call(self, fn: Callable[..., int], *args: Any) -> int:
        """fn(ctx, *args), a function of the C API returning a cm_status, with its status
        checked (check); an exception raised by the progress callable or a Ctrl-C during the
        call is raised again once the library has stopped."""
        self._state.pending = None
        self._state.warned.clear()
        status = fn(self.ptr, *args)
        pending, self._state.pending = self._state.pending, None
        if pending is not None:
            # the request may have come after the last progress point: drop it
            lib.cm_context_clear(self.ptr)
            raise pending
        return self.check(status)

    def create(self, fn: Callable[..., int], ctype: str, destroy: Callable[[Any], None],
               *args: Any) -> Any:
        """fn(ctx, *args, &out) for a function of the C API that makes an object of type
        ctype ("cm_mesh", ...): the object is owned by Python (owned(out, destroy)) as soon as
        fn returns, so that whatever call raises next (a Ctrl-C that came after the last
        progress point, a warning turned into an error) frees it; returns the owned pointer."""
        out = ffi.new(ctype + " *[1]")
        made = []

        def run(ctx_ptr, *a):
            status = fn(ctx_ptr, *a)
            if out[0] != ffi.NULL:
                made.append(owned(out[0], destroy))
            return status

        self.call(run, *args, out)
        return made[0]

    def check(self, status: int) -> int:
        """Raises the exception of an error status; a warning status becomes a
        CadmorphWarning unless the log gave the same message already; returns status."""
        if status < 0:
            raise error_class(status)(status, self.message())
        if status > 0 and self.message() not in self._state.warned:
            warnings.warn(self.message(), CadmorphWarning, stacklevel=3)
        return status


def owned(ptr: Any, destroy: Callable[[Any], None]) -> Any:
    """ptr, a `T *` the library made, freed by destroy (its cm_T_destroy, which takes the
    address of the pointer) once Python holds no reference to it (ffi.gc)."""
    slot = ffi.getctype(ffi.typeof(ptr), "[1]")
    return ffi.gc(ptr, lambda p: destroy(ffi.new(slot, [p])))
