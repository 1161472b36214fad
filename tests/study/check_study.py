"""Runs `cadmorph study` and checks what it wrote.

study.csv: one row per variant x method x mode; the --odd variant's rows have status
"mismatch" and a message saying the topology differs, every other row is complete (ok or
warning), min <= mean scaled Jacobian, its boundary within --max-distance-rel x diagonal of
its G, and no inverted cell for rbf-s. Each complete row's mesh exists and its quality
recomputed by VTK's vtkMeshQuality (code nobody here wrote) agrees with the row; the odd
variant has no mesh; the exit code is --exit (3: the odd variant's rows failed). study.svg parses as XML with one polyline per mode x method of
(complete variants + 1) points, a legend entry for each, and a mark for the odd variant.
Usage: check_study.py --dir DIR --variants N --odd LABEL --modes a[,b] --methods m[,n]
       [--max-distance-rel R] [--exit N] -- COMMAND...
"""
import argparse
import csv
import math
import os
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET

import vtk

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "helpers"))
from vtk_quality import vtk_min_sj  # noqa: E402

failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL:", msg)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dir", required=True)
    ap.add_argument("--variants", type=int, required=True)
    ap.add_argument("--odd", required=True)
    ap.add_argument("--modes", required=True)
    ap.add_argument("--methods", required=True)
    ap.add_argument("--max-distance-rel", type=float, default=1e-9)
    ap.add_argument("--exit", type=int, default=0)
    ap.add_argument("command", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    cmd = a.command[1:] if a.command and a.command[0] == "--" else a.command
    shutil.rmtree(a.dir, ignore_errors=True)  # stale outputs must not pass the test
    p = subprocess.run(cmd, capture_output=True, text=True)
    sys.stdout.write(p.stdout)
    sys.stderr.write(p.stderr)
    if p.returncode != a.exit:
        print("FAIL: exit code", p.returncode, "expected", a.exit)
        return 1
    check(a.odd in p.stderr, "no warning about the odd variant on stderr")
    modes, methods = a.modes.split(","), a.methods.split(",")
    with open(os.path.join(a.dir, "study.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    check(len(rows) == a.variants * len(modes) * len(methods),
          f"{len(rows)} rows, expected {a.variants * len(modes) * len(methods)}")
    labels = sorted({r["variant"] for r in rows})
    check(len(labels) == a.variants, f"variants {labels}")
    complete = {}
    for r in rows:
        where = f"{r['variant']} {r['method']} {r['mode']}"
        check(r["mode"] in modes and r["method"] in methods, f"{where}: unexpected row")
        mesh = os.path.join(a.dir, f"{r['method']}_{r['mode']}_{r['variant']}.vtu")
        if r["variant"] == a.odd:
            check(r["status"] == "mismatch" and "differs" in r["message"],
                  f"{where}: status {r['status']} message {r['message']!r}")
            check(not os.path.exists(mesh), f"{mesh} written for a failed row")
            continue
        check(r["status"] in ("ok", "warning"), f"{where}: status {r['status']} {r['message']}")
        lo, mean = float(r["min_scaled_jacobian"]), float(r["mean_scaled_jacobian"])
        check(math.isfinite(lo) and lo <= mean <= 1 + 1e-12, f"{where}: min {lo} mean {mean}")
        d = float(r["max_distance_rel"])
        check(0 <= d <= a.max_distance_rel, f"{where}: boundary {d} x diagonal from its G")
        if r["method"] == "rbf-s":
            check(int(r["inverted"]) == 0, f"{where}: {r['inverted']} inverted cells")
        complete.setdefault((r["mode"], r["method"]), []).append(r)
        check(os.path.exists(mesh), f"{mesh} missing")
        if os.path.exists(mesh) and r["variant"] == labels[-1]:
            vmin, vinv, vcells = vtk_min_sj(mesh, (vtk.VTK_TETRA,))
            check(vcells == int(r["cells"]), f"{mesh}: {vcells} cells vs CSV")
            check(abs(vmin - lo) <= 1e-6, f"{mesh}: VTK min scaled Jacobian {vmin} vs CSV {lo}")
            check(vinv == int(r["inverted"]), f"{mesh}: VTK {vinv} inverted vs CSV")

    root = ET.parse(os.path.join(a.dir, "study.svg")).getroot()
    ns = "{http://www.w3.org/2000/svg}"
    check(root.tag == ns + "svg", f"root element {root.tag}")
    lines = root.findall(f".//{ns}polyline")
    check(len(lines) == len(modes) * len(methods),
          f"{len(lines)} polylines, expected {len(modes) * len(methods)}")
    for pl in lines:
        check(len(pl.get("points").split()) == a.variants,  # M0 + the complete variants
              f"polyline of {len(pl.get('points').split())} points")
    text = " ".join("".join(t.itertext()) for t in root.iter(f"{ns}text"))
    for mode in modes:
        for method in methods:
            check(f"{method}, {mode}" in text, f"legend entry '{method}, {mode}' missing")
    marks = [t for t in root.iter(f"{ns}title") if (t.text or "").startswith(a.odd)]
    check(len(marks) == 1, f"{len(marks)} marks for {a.odd}")
    print(f"{len(failures)} failed" if failures else "study outputs OK")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
