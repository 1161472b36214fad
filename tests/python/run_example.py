#!/usr/bin/python3
"""Runs one script of examples/python as a user would, into a fresh output directory, and
checks what its docstring promises: exit code 0 and every listed file written (each .vtu
read back by cadmorph with nodes, each other file non-empty).

  run_example.py SCRIPT OUTDIR FILE [FILE ...]
"""
import os
import shutil
import subprocess
import sys

import cadmorph


def main() -> int:
    script, outdir, files = sys.argv[1], sys.argv[2], sys.argv[3:]
    shutil.rmtree(outdir, ignore_errors=True)
    r = subprocess.run([sys.executable, script, outdir])
    if r.returncode != 0:
        print("FAIL: %s exited with %d" % (os.path.basename(script), r.returncode))
        return 1
    bad = []
    for f in files:
        p = os.path.join(outdir, f)
        if not os.path.isfile(p) or os.path.getsize(p) == 0:
            bad.append(f + ": not written")
        elif f.endswith(".vtu") and cadmorph.read_mesh(p).n_nodes == 0:
            bad.append(f + ": no nodes")
    for b in bad:
        print("FAIL: " + b)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
