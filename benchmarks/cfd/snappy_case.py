#!/usr/bin/python3
"""The snappyHexMesh case of the CFD benchmark on its own: tests/helpers/foam_cases.py's
make_snappy_case with body "sphere" (snappyHexMesh's own searchableSphere: no STL needed)
in a tunnel, castellated, snapped and with 2 boundary layers on the body, a runnable
simpleFoam (laminar) case (patches inlet outlet walls body).
usage: snappy_case.py CASE_DIR [--base N]
  --base N   background cells across the tunnel's height (default 24: ~54k cells; the
             benchmark's 32: 126,912)"""
import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "helpers"))
import foam_cases as fc  # noqa: E402

if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("case")
    ap.add_argument("--base", type=int, default=24)
    a = ap.parse_args()
    fc.make_snappy_case(a.case, body="sphere", base=a.base)
