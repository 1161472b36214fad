"""python/cdef.h, the declarations cffi reads, is the preprocessed public headers of this
tree: scripts/gen_cdef.py run again (with the build's C compiler, CADMORPH_CC) gives the same
text, so a header changed without regenerating it fails here instead of at a user's call."""
import os
import pathlib
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_cdef_is_current():
    cc = os.environ.get("CADMORPH_CC", "cc")
    fresh = subprocess.run(["/usr/bin/python3", str(ROOT / "scripts" / "gen_cdef.py"),
                            "--cc", cc], capture_output=True, text=True, check=True).stdout
    committed = (ROOT / "python" / "cdef.h").read_text()
    assert fresh == committed, ("python/cdef.h is not current: run "
                                "scripts/gen_cdef.py -o python/cdef.h")


def test_cdef_declares_every_api_function():
    """Every CM_API function of the headers is in cdef.h (none lost by the preprocessing)."""
    import re
    text = (ROOT / "python" / "cdef.h").read_text()
    names = set()
    for h in (ROOT / "include" / "cadmorph").glob("*.h"):
        src = h.read_text()
        names.update(re.findall(r"CM_API\s+[^;(]*?\b(cm_\w+)\s*\(", src))
    assert len(names) > 150
    missing = sorted(n for n in names if not re.search(r"\b%s\s*\(" % n, text))
    assert not missing, missing
