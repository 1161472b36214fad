#!/usr/bin/python3
"""Boundary point sets of 1e5..1e6 nodes for the fast-summation benchmarks (a volume mesh
with that many boundary nodes is too big here): gmsh meshes only the surfaces (2D) of a STEP
file at a fine size; the nodes get the synthetic displacement of
bench_rbf_iterative_data.py --synthetic (a bend plus a bump of the real morphs' size).
Writes PREFIX.centres / .values (m x 3 raw float64) and PREFIX.interior: n points on a
regular grid in the bounding box (evaluation cost does not depend on whether they are inside).
usage: bench_rbf_surface_data.py MODEL.step SIZE PREFIX [N_INTERIOR]"""
import sys

import gmsh
import numpy as np

step, size, prefix = sys.argv[1], float(sys.argv[2]), sys.argv[3]
n_int = int(sys.argv[4]) if len(sys.argv) > 4 else 1000000
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.occ.importShapes(step)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMin", size)
gmsh.option.setNumber("Mesh.MeshSizeMax", size)
gmsh.model.mesh.generate(2)
_, xyz, _ = gmsh.model.mesh.getNodes()
gmsh.finalize()
x0 = np.unique(np.asarray(xyz, dtype=np.float64).reshape(-1, 3), axis=0)
lo, hi = x0.min(axis=0), x0.max(axis=0)
L = (hi - lo).max()
u = (x0 - lo) / L
disp = np.stack([0.05 * np.sin(2.0 * u[:, 1]) + 0.02 * u[:, 2] ** 2,
                 0.03 * np.exp(-8.0 * ((u[:, 0] - 0.5) ** 2 + (u[:, 2] - 0.3) ** 2)),
                 0.04 * u[:, 0] * u[:, 1]], axis=1) * L
k = max(2, round((n_int * (hi - lo)[0] ** 2 / ((hi - lo)[1] * (hi - lo)[2])) ** (1 / 3)))
ext = hi - lo
nd = [max(2, round(k * ext[d] / ext[0])) for d in range(3)]
g = np.meshgrid(*[np.linspace(lo[d] + 0.5 * ext[d] / nd[d], hi[d] - 0.5 * ext[d] / nd[d], nd[d])
                  for d in range(3)], indexing="ij")
interior = np.stack([a.ravel() for a in g], axis=1)
x0.tofile(prefix + ".centres")
disp.tofile(prefix + ".values")
interior.tofile(prefix + ".interior")
print(f"m={len(x0)} interior={len(interior)} range={np.ptp(disp):.6g}")
