#!/usr/bin/python3
"""A structured hex mesh of the sphere-handle case at any size ([CMLS §7.3]'s ~1M-node
volume, where gmsh/TetGen tets are too slow on a loaded 2-core machine): the cube [0,4]^3 with
a spherical cavity of radius 1 at its centre, as six blocks between the cube's faces and the
sphere (a "cubed sphere" shell); each block is n x n nodes on its face by m + 1 layers,
x = (1 - t) sphere(u, v) + t cube(u, v) with t graded towards the sphere. Nodes shared by two
blocks are merged. Writes OUT/shell.vtu (hexes), shell_H.csv (the cavity's nodes moved by
(DX, 0, 0)) and shell_F.csv (the cube's faces).
usage: make_cubed_shell.py OUT N M [DX]"""
import os
import sys

import meshio
import numpy as np

out, n, m = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
dx = float(sys.argv[4]) if len(sys.argv) > 4 else 0.5
os.makedirs(out, exist_ok=True)
u = np.linspace(-1, 1, n)
t = np.linspace(0, 1, m + 1) ** 1.3  # finer layers at the cavity
U, V = np.meshgrid(u, u, indexing="ij")
faces = []  # (axis, sign): the cube face x_axis = sign
for axis in range(3):
    for sign in (-1, 1):
        faces.append((axis, sign))
pts, hexes, off = [], [], 0
for axis, sign in faces:
    a, b = [k for k in range(3) if k != axis]
    cube = np.zeros((n, n, 3))
    cube[..., axis] = sign
    cube[..., a] = U
    cube[..., b] = V
    # equal-angle projection: the sphere's nodes at tan-spaced directions keep cells even
    dirn = np.zeros((n, n, 3))
    dirn[..., axis] = sign
    dirn[..., a] = np.tan(U * np.pi / 4)
    dirn[..., b] = np.tan(V * np.pi / 4)
    sph = dirn / np.linalg.norm(dirn, axis=2, keepdims=True)
    P = (1 - t[None, None, :, None]) * sph[:, :, None, :] + t[None, None, :, None] * 2 * cube[:, :, None, :]
    pts.append(P.reshape(-1, 3) + 2.0)
    idx = np.arange(n * n * (m + 1)).reshape(n, n, m + 1) + off
    c = [idx[:-1, :-1, :-1], idx[1:, :-1, :-1], idx[1:, 1:, :-1], idx[:-1, 1:, :-1],
         idx[:-1, :-1, 1:], idx[1:, :-1, 1:], idx[1:, 1:, 1:], idx[:-1, 1:, 1:]]
    h = np.stack([x.ravel() for x in c], axis=1)
    hexes.append(h)
    off += n * n * (m + 1)
pts = np.vstack(pts)
hexes = np.vstack(hexes)
# merge the nodes the blocks share (their block edges)
key = np.round(pts * 1e9).astype(np.int64)
_, first, inv = np.unique(key, axis=0, return_index=True, return_inverse=True)
inv = inv.ravel()
order = np.argsort(first)  # keep file order of first appearance
rank = np.empty_like(order)
rank[order] = np.arange(len(order))
pts = pts[first[order]]
hexes = rank[inv[hexes]]
# orient every hex so that its Jacobian at node 0 is positive
P = pts[hexes]
J = np.einsum("ij,ij->i", np.cross(P[:, 1] - P[:, 0], P[:, 3] - P[:, 0]), P[:, 4] - P[:, 0])
flip = J < 0
hexes[flip] = hexes[flip][:, [0, 3, 2, 1, 4, 7, 6, 5]]
meshio.write(os.path.join(out, "shell.vtu"), meshio.Mesh(pts, [("hexahedron", hexes)]))
r = np.linalg.norm(pts - 2, axis=1)
cavity = np.abs(r - 1) < 1e-9
outer = (np.min(pts, axis=1) < 1e-9) | (np.max(pts, axis=1) > 4 - 1e-9)
with open(os.path.join(out, "shell_H.csv"), "w") as f:
    f.write("node,dx,dy,dz\n" + "".join("%d,%.17g,0,0\n" % (i, dx) for i in np.nonzero(cavity)[0]))
with open(os.path.join(out, "shell_F.csv"), "w") as f:
    f.write("node\n" + "".join("%d\n" % i for i in np.nonzero(outer)[0]))
print("shell: %d nodes, %d hexes, %d handle, %d fixed" % (len(pts), len(hexes), cavity.sum(), outer.sum()))
