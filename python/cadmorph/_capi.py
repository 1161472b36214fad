"""The C API of libcadmorph as cffi sees it (ABI mode: no compiler at install time).

The declarations are the public headers themselves (python/cdef.h, written from
include/cadmorph by scripts/gen_cdef.py; tests/python/test_cdef.py fails when it is not
current), parsed at build time into the out-of-line module _ffi.py (python/ffi_build.py).
The library is CADMORPH_LIBRARY if set, else the one CMake recorded in _libpath.py (the build
tree's, or the installed one relative to this package), else the soname through the dynamic
loader. cffi releases the GIL around every call into the library.
"""
import os

from ._ffi import ffi

# the soname of libcadmorph 0.x when CMake did not record it: the minor version is part of
# it (cmake/library.cmake)
SONAME = "libcadmorph.so.0.1"


def _candidates():
    """CADMORPH_LIBRARY if set, the library CMake recorded, then the soname."""
    try:
        from . import _libpath
    except ImportError:  # a copy of the sources that CMake did not configure
        _libpath = None
    if os.environ.get("CADMORPH_LIBRARY"):
        yield os.environ["CADMORPH_LIBRARY"]
    if getattr(_libpath, "LIBRARY", None):
        yield _libpath.LIBRARY
    yield getattr(_libpath, "SONAME", SONAME)


def _load():
    """The first library that loads, and its path; ImportError naming every attempt."""
    errors = []
    for path in _candidates():
        if os.sep in path and not os.path.exists(path):
            errors.append("%s: no such file" % path)
            continue
        try:
            return ffi.dlopen(path), path
        except OSError as e:
            errors.append(str(e))
    raise ImportError("cadmorph: cannot load libcadmorph (%s); set CADMORPH_LIBRARY to its "
                      "path, or put its directory on LD_LIBRARY_PATH" % "; ".join(errors))


lib, LIBRARY_PATH = _load()
