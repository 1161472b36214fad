#!/usr/bin/env python3
"""The sampling of G and the boundary distance a morph reports, on the FreeCAD shaft.

check_sampling.py CADMORPH BREP_DISTANCE DATA WORK MODE

A TetGen mesh of the shaft has a boundary edge 1/3000 of the part (the grooves' fillets):
a quarter of it as the sampling step asks for 10^7..10^10 samples. MODE:
  samples   cadmorph morph -v samples G at most 64 per boundary node (at least 250,000;
            before, the 4e6 cap on G and on G', 0.8 GB), says nothing about it (no
            warning line) and prints each distinct stderr line once;
  distance  the largest distance to G1 that cadmorph reports agrees with an independent
            measurement (tests/cad/brep_distance.cpp: OpenCASCADE's reader and
            BRepExtrema_DistShapeShape) within 1e-12 x diagonal; before, the distance through
            the sampled G' reported 2e-9 where BRepExtrema finds 2e-14.
"""
import os
import re
import subprocess
import sys


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    if p.returncode != 0:
        sys.exit("FAIL: %s exited %d:\n%s%s" % (" ".join(cmd), p.returncode, p.stdout, p.stderr))
    return p


def main():
    cadmorph, brep, data, work, mode = sys.argv[1:6]
    os.makedirs(work, exist_ok=True)
    g0 = os.path.join(data, "freecad", "shaft_0.step")
    g1 = os.path.join(data, "freecad", "shaft_1.step")
    m0 = os.path.join(work, "shaft_coarse_%s.vtu" % mode)
    m1 = os.path.join(work, "shaft_coarse_%s_m.vtu" % mode)
    run([cadmorph, "mesh", g0, "-o", m0, "--mesher", "tetgen", "--size", "10", "--threads", "1"])
    p = run([cadmorph, "morph", "--from", g0, "--to", g1, "--mesh", m0, "-o", m1, "-v",
             "--threads", "2"])
    if mode == "samples":
        counts = [int(n) for n in re.findall(r"^sampling: (\d+) samples", p.stderr, re.M)]
        nb = re.search(r"^boundary nodes: (\d+) on vertices, (\d+) on edges, (\d+) on faces",
                       p.stdout, re.M)
        if not counts or not nb:
            sys.exit("FAIL: no sampling or boundary line:\n" + p.stderr + p.stdout)
        boundary = sum(int(x) for x in nb.groups())
        cap = max(250000, 64 * boundary)
        print("sampled %s times: %s samples; %d boundary nodes, cap %d"
              % (len(counts), counts, boundary, cap))
        if len(counts) != 1 or counts[0] > cap:
            sys.exit("FAIL: G' is sampled too, or G beyond %d samples" % cap)
        warnings = [l for l in p.stderr.splitlines() if l.startswith("warning:")]
        if warnings:
            sys.exit("FAIL: warnings on a clean morph:\n" + "\n".join(warnings))
        lines = [l for l in p.stderr.splitlines() if not l.startswith("cm_rbf")]
        twice = sorted({l for l in lines if lines.count(l) > 1 and "sampl" in l})
        if twice:
            sys.exit("FAIL: printed more than once:\n" + "\n".join(twice))
    elif mode == "distance":
        fig = re.search(r"largest distance to G1: (\S+) \(", p.stdout, re.M)
        if not fig:
            sys.exit("FAIL: no distance line:\n" + p.stdout)
        q = subprocess.run([brep, g1, m1, "--compare", fig.group(1), "--tol", "1e-12"],
                           capture_output=True, text=True, timeout=600)
        print(q.stdout + q.stderr, end="")
        if q.returncode != 0:
            sys.exit("FAIL: cadmorph's figure %s is not BRepExtrema's" % fig.group(1))
    else:
        sys.exit("unknown mode " + mode)
    print("PASS")


if __name__ == "__main__":
    main()
