#!/usr/bin/python3
"""The two-body set of the RBF solver benchmarks: two copies of one boundary set (the second
moved along x by GAP x the set's bounding-box diagonal, with the same real displacements) and
N points on a regular grid in the bounding box of both, standing in for the interior nodes of a
1e6-node mesh (evaluation cost does not depend on where they are).
Reads PREFIX.centres / .values of bench_rbf_iterative_data.py, writes OUT.centres / .values /
.interior (raw float64, m x 3).
usage: bench_rbf_twobody_data.py PREFIX OUT [N [GAP]]   (N 1000000, GAP 1.0)"""
import sys

import numpy as np

prefix, out = sys.argv[1], sys.argv[2]
n = int(sys.argv[3]) if len(sys.argv) > 3 else 1000000
gap = float(sys.argv[4]) if len(sys.argv) > 4 else 1.0
c = np.fromfile(prefix + ".centres").reshape(-1, 3)
v = np.fromfile(prefix + ".values").reshape(-1, 3)
lo, hi = c.min(axis=0), c.max(axis=0)
shift = np.array([(hi[0] - lo[0]) + gap * np.linalg.norm(hi - lo), 0.0, 0.0])
c2 = np.concatenate([c, c + shift])
v2 = np.concatenate([v, v])
lo2, hi2 = c2.min(axis=0), c2.max(axis=0)
ext = hi2 - lo2
h = (np.prod(ext) / n) ** (1.0 / 3.0)  # cubic cells: about n points in the box
axes = [np.linspace(lo2[d], hi2[d], max(2, int(round(ext[d] / h)) + 1)) for d in range(3)]
grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
c2.tofile(out + ".centres")
v2.tofile(out + ".values")
grid.tofile(out + ".interior")
print(f"m={len(c2)} interior={len(grid)} shift={shift[0]:.6g} range={np.ptp(v2):.6g}")
