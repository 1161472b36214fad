#!/usr/bin/python3
"""Boundary node sets for bench_rbf_iterative: reads a morphed mesh written by
`cadmorph morph ... -o M1.vtu` (per-node 'displacement') and writes raw float64 files
PREFIX.centres (m x 3, the boundary nodes at G(0): M1 minus its displacement),
PREFIX.values (m x 3, their displacements) and PREFIX.interior (n x 3, the other nodes).
usage: bench_rbf_iterative_data.py M1.vtu PREFIX [M0.vtu]
(with M0, whose nodes are M1's in the same order, the G(0) positions come from it exactly)"""
import sys

import meshio
import numpy as np

mesh = meshio.read(sys.argv[1])
disp = np.asarray(mesh.point_data["displacement"], dtype=np.float64)
if len(sys.argv) > 3:
    x0 = np.asarray(meshio.read(sys.argv[3]).points, dtype=np.float64)
    assert x0.shape == disp.shape
else:
    x0 = np.asarray(mesh.points, dtype=np.float64) - disp
tri = np.concatenate([c.data for c in mesh.cells if c.type == "triangle"])
bnd = np.unique(tri.ravel())
inner = np.setdiff1d(np.arange(len(x0)), bnd)
x0[bnd].tofile(sys.argv[2] + ".centres")
disp[bnd].tofile(sys.argv[2] + ".values")
x0[inner].tofile(sys.argv[2] + ".interior")
print(f"m={len(bnd)} interior={len(inner)} range={np.ptp(disp[bnd]):.6g}")
