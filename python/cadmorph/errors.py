"""The library's status as Python exceptions.

A cm_status below 0 becomes an exception of the class its code maps to, carrying the status
and the library's message (which names the file and the place); a status above 0 (a complete
result with something odd about it) becomes a CadmorphWarning.
"""
from ._capi import ffi, lib


class Error(Exception):
    """An error reported by libcadmorph.

    Attributes:
        status: the library's cm_status code (an int below 0).
        status_name: its short fixed name, e.g. "format error".
        message: the library's message, e.g. "cm_mesh_read: M.msh:12: expected ...".
    """

    def __init__(self, status: int, message: str) -> None:
        self.status: int = status
        self.status_name: str = ffi.string(lib.cm_status_name(status)).decode()
        self.message: str = message
        super().__init__(status, message)  # both, so that the exception pickles

    def __str__(self) -> str:
        return self.message or self.status_name


class BadInputError(Error):
    """The input is bad: a file that cannot be read or is malformed, valid input cadmorph
    does not handle, a CAD or numeric failure on it (exit code 2 of the CLI)."""


class MismatchError(BadInputError):
    """Inputs that do not belong together: a mesh and a geometry, G and G'."""


class RejectedError(Error):
    """A result refused by a quality guard (exit code 3 of the CLI)."""


class ResourceError(Error):
    """Out of memory, a request beyond what the machine can hold, or an output another
    process is writing (exit code 4)."""


class InterruptedCall(Error):
    """The call stopped on a cm_context_interrupt that no Python exception asked for (a
    Ctrl-C or an exception of the progress callable is raised as itself instead)."""


class CadmorphWarning(UserWarning):
    """A complete result about which the library reports something odd."""


def error_class(status: int) -> type:
    """The exception class of an error status (< 0): the CLI's exit codes, by class."""
    if status == lib.CM_ERR_MISMATCH:
        return MismatchError
    if status == lib.CM_ERR_REJECTED:
        return RejectedError
    if status in (lib.CM_ERR_NOMEM, lib.CM_ERR_BUSY):
        return ResourceError
    if status == lib.CM_ERR_INTERRUPTED:
        return InterruptedCall
    if lib.cm_status_is_input_error(status):
        return BadInputError
    return Error  # CM_ERR_ARGUMENT, CM_ERR_INTERNAL: a bug here or in the library
