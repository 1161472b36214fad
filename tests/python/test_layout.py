"""The structs as cffi declares them (cadmorph._capi) against the C compiler's layout of the
public headers (the program tests/python/layout.c, CADMORPH_LAYOUT)."""
import os
import subprocess

import pytest

from cadmorph._capi import ffi


def test_layout_matches_the_headers():
    prog = os.environ.get("CADMORPH_LAYOUT")
    if not prog:
        pytest.fail("CADMORPH_LAYOUT must name the built layout program (tests/python)")
    lines = subprocess.run([prog], capture_output=True, text=True, check=True).stdout.split("\n")
    checked = 0
    for line in filter(None, lines):
        name, value = line.split()
        if "." in name:
            struct, field = name.split(".")
            assert ffi.offsetof(struct, field) == int(value), name
        else:
            assert ffi.sizeof(name) == int(value), name
        checked += 1
    assert checked > 30
