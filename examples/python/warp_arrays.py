#!/usr/bin/python3
"""A warp of given boundary motion, everything from NumPy arrays: a tet mesh of a beam built
as arrays (cadmorph.Mesh.from_arrays), its boundary nodes, a displacement of each (the beam
bent and twisted), and the displacement of every node from one factorised Warp.

Warp(mesh, nodes, method="rbf") fits the interior motion to the listed nodes once; each
apply(D) with D of shape (len(nodes), 3) returns the (n_nodes, 3) displacement of every node,
equal to D on the listed nodes. Two load cases reuse the one factorisation; the second is also
computed by the one-shot cadmorph.warp to show that the two agree.

    PYTHONPATH=build/python python3 examples/python/warp_arrays.py OUTDIR [--cells N]

OUTDIR (or $CADMORPH_EXAMPLE_OUT) gets beam_0.vtu, beam_bent.vtu and beam_twisted.vtu.
"""
import argparse
import os

import numpy as np

import cadmorph


def beam(n: int):
    """A 4 x 1 x 1 box of (4n) x n x n cubes, each cut into six tets (Kuhn's subdivision):
    the points (k, 3) and the tets (c, 4) as arrays, every tet positively oriented."""
    nx, ny, nz = 4 * n, n, n
    x, y, z = np.meshgrid(np.linspace(0, 4, nx + 1), np.linspace(0, 1, ny + 1),
                          np.linspace(0, 1, nz + 1), indexing="ij")
    points = np.column_stack([x.ravel(), y.ravel(), z.ravel()])
    idx = np.arange(points.shape[0]).reshape(nx + 1, ny + 1, nz + 1)
    corner = [idx[i:i + nx, j:j + ny, k:k + nz].ravel()
              for i, j, k in np.ndindex(2, 2, 2)]  # corner (i, j, k) of every cube
    c = lambda i, j, k: corner[4 * i + 2 * j + k]  # noqa: E731
    # the six paths from corner (0,0,0) to (1,1,1), one tet each
    tets = []
    for a, b in ((0, 1), (0, 2), (1, 0), (1, 2), (2, 0), (2, 1)):
        p = [0, 0, 0]
        path = [c(*p)]
        for axis in (a, b, 3 - a - b):
            p[axis] = 1
            path.append(c(*p))
        tets.append(np.column_stack(path))
    tets = np.vstack(tets).astype(np.int64)
    e = points[tets[:, 1:]] - points[tets[:, :1]]
    flip = np.einsum("ij,ij->i", np.cross(e[:, 0], e[:, 1]), e[:, 2]) < 0
    tets[flip, 2], tets[flip, 3] = tets[flip, 3], tets[flip, 2].copy()
    return points, tets


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("outdir", nargs="?", default=os.environ.get("CADMORPH_EXAMPLE_OUT"))
    ap.add_argument("--cells", type=int, default=6, help="cubes across the beam (default 6)")
    a = ap.parse_args()
    if not a.outdir:
        ap.error("give OUTDIR or set CADMORPH_EXAMPLE_OUT")
    os.makedirs(a.outdir, exist_ok=True)

    points, tets = beam(a.cells)
    mesh = cadmorph.Mesh.from_arrays(points, [("tetra", tets)])
    cadmorph.write_mesh(os.path.join(a.outdir, "beam_0.vtu"), mesh)
    x, y, z = points.T
    on_surface = (x == 0) | (x == 4) | (y == 0) | (y == 1) | (z == 0) | (z == 1)
    nodes = np.flatnonzero(on_surface)
    print("beam: %d nodes, %d tets, %d boundary nodes, min scaled Jacobian %.4f"
          % (len(points), len(tets), len(nodes), cadmorph.quality(mesh).min_sj))

    # load case 1: bent about y, the end x = 0 clamped (D = 0 there)
    s = x[nodes] / 4
    bent = np.zeros((len(nodes), 3))
    bent[:, 2] = 0.6 * s * s
    # load case 2: twisted about the beam's axis, 45 degrees at x = 4
    phi = np.pi / 4 * s
    yc, zc = y[nodes] - 0.5, z[nodes] - 0.5
    twisted = np.column_stack([np.zeros_like(s), yc * np.cos(phi) - zc * np.sin(phi) - yc,
                               yc * np.sin(phi) + zc * np.cos(phi) - zc])

    w = cadmorph.Warp(mesh, nodes, method="rbf")  # factorised once for both load cases
    for name, d in (("bent", bent), ("twisted", twisted)):
        u = w.apply(d)
        if not np.array_equal(u[nodes], d):  # the listed nodes move exactly by D
            raise SystemExit("%s: the boundary nodes do not follow D" % name)
        moved = cadmorph.Mesh.from_arrays(points + u, [("tetra", tets)])
        q = cadmorph.quality(moved)
        cadmorph.write_mesh(os.path.join(a.outdir, "beam_%s.vtu" % name), moved)
        print("%s: max interior displacement %.4f, min scaled Jacobian %.4f, %d inverted"
              % (name, np.abs(np.delete(u, nodes, axis=0)).max(), q.min_sj, q.inverted))
    once = cadmorph.warp(mesh, nodes, twisted, method="rbf")
    print("one-shot cadmorph.warp vs Warp.apply: max difference %.3g" % np.abs(once - u).max())


if __name__ == "__main__":
    main()
