"""cffi's out-of-line ABI module of the package, cadmorph/_ffi.py, from cdef.h.

The declarations are parsed once, here, at build time (CMake's build, or pip through
cffi_modules in setup.py), so `import cadmorph` does not parse a thousand lines of C; no C
compiler is involved (ABI mode: the library is opened with dlopen at import).

    python3 ffi_build.py OUT.py
"""
import os
import sys

import cffi

HERE = os.path.dirname(os.path.abspath(__file__))

ffibuilder = cffi.FFI()
with open(os.path.join(HERE, "cdef.h")) as f:
    ffibuilder.cdef(f.read())
ffibuilder.set_source("cadmorph._ffi", None)

if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: ffi_build.py OUT.py")
    ffibuilder.emit_python_code(sys.argv[1])
