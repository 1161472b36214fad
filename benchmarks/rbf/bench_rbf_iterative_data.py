#!/usr/bin/python3
"""Boundary node sets for bench_rbf_iterative: reads a morphed mesh written by
`cadmorph morph ... -o M1.vtu` (per-node 'displacement') and writes raw float64 files
PREFIX.centres (m x 3, the boundary nodes at G(0)), PREFIX.values (m x 3, their
displacements) and PREFIX.interior (n x 3, the other nodes).
usage: bench_rbf_iterative_data.py M1.vtu PREFIX [M0.vtu]
  (with M0, whose nodes are M1's in the same order, the G(0) positions come from it exactly)
       bench_rbf_iterative_data.py --synthetic M0.vtu PREFIX
  (no morph: a smooth displacement of the size of the real ones, a bend plus a bump, for
  meshes whose morph is too slow to run here)"""
import sys

import meshio
import numpy as np


def boundary(mesh):
    tri = np.concatenate([c.data for c in mesh.cells if c.type == "triangle"])
    return np.unique(tri.ravel())


if sys.argv[1] == "--synthetic":
    mesh = meshio.read(sys.argv[2])
    prefix = sys.argv[3]
    x0 = np.asarray(mesh.points, dtype=np.float64)
    lo, hi = x0.min(axis=0), x0.max(axis=0)
    u = (x0 - lo) / (hi - lo).max()
    disp = np.stack([0.05 * np.sin(2.0 * u[:, 1]) + 0.02 * u[:, 2] ** 2,
                     0.03 * np.exp(-8.0 * ((u[:, 0] - 0.5) ** 2 + (u[:, 2] - 0.3) ** 2)),
                     0.04 * u[:, 0] * u[:, 1]], axis=1) * (hi - lo).max()
else:
    mesh = meshio.read(sys.argv[1])
    prefix = sys.argv[2]
    disp = np.asarray(mesh.point_data["displacement"], dtype=np.float64)
    if len(sys.argv) > 3:
        x0 = np.asarray(meshio.read(sys.argv[3]).points, dtype=np.float64)
        assert x0.shape == disp.shape
    else:
        x0 = np.asarray(mesh.points, dtype=np.float64) - disp
bnd = boundary(mesh)
inner = np.setdiff1d(np.arange(len(x0)), bnd)
x0[bnd].tofile(prefix + ".centres")
disp[bnd].tofile(prefix + ".values")
x0[inner].tofile(prefix + ".interior")
print(f"m={len(bnd)} interior={len(inner)} range={np.ptp(disp[bnd]):.6g}")
