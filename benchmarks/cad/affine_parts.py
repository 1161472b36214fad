#!/usr/bin/python3
"""affine_parts.py CADMORPH DIR OUT [--size-fraction F] [PART ...]: affine edits of STEP parts reproduced
(benchmarks/RESULTS.md, "Affine edits").

For each DIR/PART.step (default: every .step of DIR), gmsh's OpenCASCADE kernel writes
OUT/PART_0.step (the part as read, so that G0 and G1 share gmsh's reading of the file) and
OUT/PART_1.step = A PART_0 + b (gmsh.model.occ.affineTransform, i.e.
BRepBuilderAPI_GTransform: a non-uniform scale with shear, the map of the general affine test).
Then `cadmorph mesh PART_0.step --mesher tetgen [--size F x diagonal]` and `cadmorph morph --steps 1` onto
PART_1.step, and the largest |x' - (A x + b)| over every node of the morphed mesh, as a
fraction of the diagonal of the morphed mesh's bounding box. One line per part:
  PART nodes=N max_dev=D (x diagonal) morph=exit-code [message]"""
import os
import subprocess
import sys
import time

import gmsh

# the general map of tests/surface/affine_maps.h
A = [[1.3, 0.25, 0.1, 0.6], [0.0, 0.8, 0.2, -1.1], [0.15, 0.0, 1.5, 0.4]]


def write_pair(src, g0, g1):
    # OpenCASCADE's STEP writer prints its statistics on the process's stdout
    saved = os.dup(1)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
    try:
        return write_pair_quiet(src, g0, g1)
    finally:
        os.dup2(saved, 1)
        os.close(saved)


def write_pair_quiet(src, g0, g1):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.model.occ.importShapes(src)
        gmsh.model.occ.synchronize()
        gmsh.write(g0)
        box = gmsh.model.getBoundingBox(-1, -1)
        diag = sum((box[i + 3] - box[i]) ** 2 for i in range(3)) ** 0.5
        gmsh.model.occ.affineTransform(gmsh.model.getEntities(3) or gmsh.model.getEntities(2),
                                       [v for row in A for v in row])
        gmsh.model.occ.synchronize()
        gmsh.write(g1)
    finally:
        gmsh.finalize()
    return diag


def read_medit_nodes(path):
    with open(path) as f:
        words = f.read().split()
    i = words.index("Vertices")
    n = int(words[i + 1])
    v = words[i + 2:i + 2 + 4 * n]
    return [(float(v[4 * k]), float(v[4 * k + 1]), float(v[4 * k + 2])) for k in range(n)]


def diagonal(nodes):
    lo = [min(p[i] for p in nodes) for i in range(3)]
    hi = [max(p[i] for p in nodes) for i in range(3)]
    return sum((h - l) ** 2 for l, h in zip(lo, hi)) ** 0.5


def run(cmd, log):
    with open(log, "w") as f:
        return subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, timeout=1800).returncode


def last_line(path):
    with open(path) as f:
        lines = [l.strip() for l in f if l.strip()]
    return lines[-1][:160] if lines else ""


def main():
    cli, src, out = sys.argv[1:4]
    rest, fraction = sys.argv[4:], 0
    if rest[:1] == ["--size-fraction"]:
        fraction, rest = float(rest[1]), rest[2:]
    parts = rest or sorted(f[:-5] for f in os.listdir(src) if f.endswith(".step"))
    os.makedirs(out, exist_ok=True)
    for p in parts:
        g0, g1 = os.path.join(out, p + "_0.step"), os.path.join(out, p + "_1.step")
        m0, m1 = os.path.join(out, p + "_0.mesh"), os.path.join(out, p + "_1.mesh")
        diag = write_pair(os.path.join(src, p + ".step"), g0, g1)
        size = ["--size", "%.6g" % (fraction * diag)] if fraction > 0 else []
        rc = run([cli, "mesh", g0, "-o", m0, "--mesher", "tetgen"] + size,
                 os.path.join(out, p + "_mesh.log"))
        if rc != 0:
            print("%-12s mesh exit %d: %s" % (p, rc, last_line(os.path.join(out, p + "_mesh.log"))))
            continue
        t = time.time()
        log = os.path.join(out, p + "_morph.log")
        rc = run([cli, "morph", "--from", g0, "--to", g1, "--mesh", m0, "-o", m1, "--steps", "1"], log)
        t = time.time() - t
        if not os.path.exists(m1):
            print("%-12s morph exit %d, no mesh: %s" % (p, rc, last_line(log)))
            continue
        x0, x1 = read_medit_nodes(m0), read_medit_nodes(m1)
        worst = 0.0
        for a, b in zip(x0, x1):
            y = [A[i][0] * a[0] + A[i][1] * a[1] + A[i][2] * a[2] + A[i][3] for i in range(3)]
            worst = max(worst, sum((y[i] - b[i]) ** 2 for i in range(3)) ** 0.5)
        print("%-12s nodes=%d max_dev=%.2e (x diagonal) morph=%d %.1fs %s" %
              (p, len(x0), worst / diagonal(x1), rc, t, last_line(log)), flush=True)


if __name__ == "__main__":
    main()
