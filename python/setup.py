"""setuptools' half of `pip install ./python` (the metadata is in pyproject.toml): cffi's
setuptools integration runs ffi_build.py, which parses cdef.h into the module cadmorph/_ffi.py
(ABI mode: no extension is compiled, the wheel is pure Python). The installed package finds
libcadmorph through CADMORPH_LIBRARY or its soname through the dynamic loader (_capi.py).
"""
from setuptools import setup

setup(cffi_modules=["ffi_build.py:ffibuilder"])
