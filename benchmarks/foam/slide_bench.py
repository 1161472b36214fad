#!/usr/bin/python3
"""Boundary motion by patch kind, timed: `cadmorph warp` of the body of the shared 2-D and
wedge OpenFOAM cases (tests/helpers/foam_cases.py) with the default motion (the empty/wedge
planes slide, the mesh morphed exactly 2-D) against `--no-slide` (every boundary node but
the body's fixed: the motion before patch kinds), alternated in one run; wall and CPU
seconds and peak RSS by GNU time, checkMesh's verdict on each result.

  benchmarks/foam/slide_bench.py CADMORPH WORKDIR [--scale S] [--reps N] [--threads T]
"""
import argparse
import math
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "tests", "helpers"))
import foam_cases as fc  # noqa: E402

ap = argparse.ArgumentParser()
ap.add_argument("cli")
ap.add_argument("work")
ap.add_argument("--scale", type=float, default=16)
ap.add_argument("--reps", type=int, default=2)
ap.add_argument("--threads", type=int, default=2)
a = ap.parse_args()
os.makedirs(a.work, exist_ok=True)

rows = []
for kind in ("channel2d", "wedge"):
    src = fc.make_case(kind, os.path.join(a.work, "%s_s%g" % (kind, a.scale)), scale=a.scale)
    pts = fc.read_points(src)
    body = fc.patch_points(src, "body")
    cx = sum(pts[i][0] for i in body) / len(body)
    cy = sum(pts[i][1] for i in body) / len(body)
    csv = src + ".csv"
    with open(csv, "w") as f:
        f.write("node,dx,dy,dz\n")
        for i in body:
            x, y, z = pts[i]
            if kind == "channel2d":  # 5 degrees about the body's centre
                t, dx, dy = math.radians(5), x - cx, y - cy
                d = (math.cos(t) * dx - math.sin(t) * dy - dx, math.sin(t) * dx + math.cos(t) * dy - dy, 0)
            else:  # radius x 1.1, 0.01 along the axis
                d = (0.01, 0.1 * y, 0.1 * z)
            f.write("%d,%.17g,%.17g,%.17g\n" % (i, *d))
    cells = fc.checkmesh(src)["cells"]
    for rep in range(a.reps):
        for label, extra in (("default (slide, 2-D)", []), ("--no-slide", ["--no-slide"])):
            out = os.path.join(a.work, "%s_%s" % (kind, "noslide" if extra else "slide"))
            r = subprocess.run(["/usr/bin/time", "-f", "TIME %e %U %S %M", a.cli, "warp", "--mesh", src,
                                "--displacements", csv, "-o", out + "/", "--threads",
                                str(a.threads)] + extra, capture_output=True, text=True)
            m = re.search(r"TIME ([\d.]+) ([\d.]+) ([\d.]+) (\d+)", r.stderr)
            for d in ("system",):
                if not os.path.exists(os.path.join(out, d)):
                    subprocess.run(["cp", "-r", os.path.join(src, d), out])
            cm = fc.checkmesh(out)
            inv = re.search(r"inverted=(\d+)", r.stdout)
            rows.append((kind, cells, label, float(m.group(1)), float(m.group(2)) + float(m.group(3)),
                         int(m.group(4)) / 1024, inv.group(1) if inv else "?",
                         "OK" if cm["ok"] else "FAIL (%d)" % cm["failed"]))

print("| case | cells | motion | wall s | CPU s | peak MiB | inverted | checkMesh |")
print("|---|---:|---|---:|---:|---:|---:|---|")
for r in rows:
    print("| %s | %d | %s | %.2f | %.2f | %.0f | %s | %s |" % r)
