"""Runs `cadmorph sweep` (or `cadmorph demo`) and checks what it wrote.

sweep.csv: exactly one row per mode x method x step 1..N with t = k/N, finite values,
min <= mean scaled Jacobian, at most --max-inverted inverted cells and a boundary distance to
G(t) of at most --max-distance-rel x the model diagonal at every step. The meshes at 100 %:
their min scaled Jacobian and inverted count recomputed by VTK's vtkMeshQuality (code nobody
here wrote) agree with the CSV's last row. sweep.svg parses as XML, is an <svg> with one
polyline of N + 1 points per mode x method and a legend entry for each.
Usage: check_sweep.py --dir DIR --steps N --modes absolute[,relative] --methods a[,b]
       [--max-inverted K] [--max-distance-rel R] -- COMMAND...
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

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
    ap.add_argument("--steps", type=int, required=True)
    ap.add_argument("--modes", required=True)
    ap.add_argument("--methods", required=True)
    ap.add_argument("--max-inverted", type=int, default=None)
    ap.add_argument("--max-distance-rel", type=float, default=None)
    ap.add_argument("command", nargs=argparse.REMAINDER)
    a = ap.parse_args()
    cmd = a.command[1:] if a.command and a.command[0] == "--" else a.command
    for name in ("sweep.csv", "sweep.svg"):  # stale outputs must not pass the test
        if os.path.exists(os.path.join(a.dir, name)):
            os.remove(os.path.join(a.dir, name))
    p = subprocess.run(cmd, capture_output=True, text=True)
    sys.stdout.write(p.stdout)
    sys.stderr.write(p.stderr)
    if p.returncode != 0:
        print("FAIL: exit code", p.returncode)
        return 1
    modes, methods, n = a.modes.split(","), a.methods.split(","), a.steps

    with open(os.path.join(a.dir, "sweep.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    check(len(rows) == n * len(modes) * len(methods),
          f"{len(rows)} rows, expected {n * len(modes) * len(methods)}")
    for mode in modes:
        for method in methods:
            series = [r for r in rows if r["mode"] == mode and r["method"] == method]
            check([int(r["step"]) for r in series] == list(range(1, n + 1)),
                  f"{method} {mode}: steps {[r['step'] for r in series]}")
            for r in series:
                k = int(r["step"])
                where = f"{method} {mode} step {k}"
                check(abs(float(r["t"]) - k / n) < 1e-5, f"{where}: t {r['t']}")
                lo, mean = float(r["min_scaled_jacobian"]), float(r["mean_scaled_jacobian"])
                check(math.isfinite(lo) and lo <= mean <= 1 + 1e-12, f"{where}: min {lo} mean {mean}")
                if a.max_inverted is not None:
                    check(int(r["inverted"]) <= a.max_inverted,
                          f"{where}: {r['inverted']} inverted cells")
                if a.max_distance_rel is not None:
                    d = float(r["max_distance_rel"])
                    check(0 <= d <= a.max_distance_rel,
                          f"{where}: boundary {d} x diagonal from G(t)")
            if len(series) == n:
                path = os.path.join(a.dir, f"{method}_{mode}_100.vtu")
                check(os.path.exists(path), f"{path} missing")
                if os.path.exists(path):
                    vmin, vinv, vcells = vtk_min_sj(path)
                    last = series[-1]
                    check(vcells == int(last["cells"]), f"{path}: {vcells} cells vs CSV")
                    check(abs(vmin - float(last["min_scaled_jacobian"])) <= 1e-6,
                          f"{path}: VTK min scaled Jacobian {vmin} vs CSV "
                          f"{last['min_scaled_jacobian']}")
                    check(vinv == int(last["inverted"]),
                          f"{path}: VTK {vinv} inverted vs CSV {last['inverted']}")
                pct = round(100 * ((n + 1) // 2) / n)
                half = os.path.join(a.dir, f"{method}_{mode}_{pct:03d}.vtu")
                check(os.path.exists(half), f"{half} missing")

    root = ET.parse(os.path.join(a.dir, "sweep.svg")).getroot()
    check(root.tag == "{http://www.w3.org/2000/svg}svg", f"root element {root.tag}")
    ns = "{http://www.w3.org/2000/svg}"
    lines = root.findall(f".//{ns}polyline")
    check(len(lines) == len(modes) * len(methods),
          f"{len(lines)} polylines, expected {len(modes) * len(methods)}")
    for pl in lines:
        check(len(pl.get("points").split()) == n + 1, "polyline without N + 1 points")
    text = " ".join("".join(t.itertext()) for t in root.iter(f"{ns}text"))
    for mode in modes:
        for method in methods:
            check(f"{method}, {mode}" in text, f"legend entry '{method}, {mode}' missing")
    check("parameter change" in text and "min scaled Jacobian" in text, "axis labels missing")

    print(f"{len(failures)} failed" if failures else "sweep outputs OK")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
