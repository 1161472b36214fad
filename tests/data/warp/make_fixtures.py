#!/usr/bin/python3
"""Writes the small fixtures of the warp CLI tests (run from anywhere; rewrites them here):
bad_*.csv   one defect each; none.csv: the header alone (nothing moves), for `cadmorph warp` on the sphere mesh (3000+ nodes), and
flat.vtk    a cube split into 12 tets around its centre, then flattened to z = 0: every
            boundary node is coplanar, so the warp has no unique linear part (exit 2).
sphere_in_box.geo (the real mesh) is written by hand; the tests mesh it with gmsh."""
import os

HERE = os.path.dirname(os.path.abspath(__file__))
HEADER = "node,dx,dy,dz\n"
NONE = HEADER  # no node listed: every boundary node stays
BAD = {
    "bad_header.csv": "node,ux,uy,uz\n0,0,0,0\n",
    "bad_columns.csv": HEADER + "0,0.01,0,0\n1,0.01,0\n",
    "bad_number.csv": HEADER + "0,0.01,abc,0\n",
    "bad_node.csv": HEADER + "0,0,0,0\n1,0,0,0\nseven,0,0,0\n",
    "bad_range.csv": HEADER + "0,0,0,0\n99999999,0,0,0\n",
    "bad_duplicate.csv": HEADER + "5,0,0,0\n6,0,0,0\n5,0,0,0\n",
    "bad_nan.csv": HEADER + "0,NaN,0,0\n",
    "bad_inf.csv": HEADER + "\n0,0,inf,0\n",
}


def flat_vtk():
    corners = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
    pts = [(x, y, 0.0) for x, y, z in corners] + [(0.5, 0.5, 0.0)]
    # cube faces (corner ids, x fastest), each split into two triangles, coned to the centre 8
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tets = []
    for a, b, c, d in quads:
        tets += [(a, b, c, 8), (a, c, d, 8)]
    lines = ["# vtk DataFile Version 3.0", "cube flattened to z=0 (cadmorph warp test)", "ASCII",
             "DATASET UNSTRUCTURED_GRID", "POINTS %d double" % len(pts)]
    lines += ["%g %g %g" % p for p in pts]
    lines.append("CELLS %d %d" % (len(tets), 5 * len(tets)))
    lines += ["4 %d %d %d %d" % t for t in tets]
    lines.append("CELL_TYPES %d" % len(tets))
    lines += ["10"] * len(tets)
    return "\n".join(lines) + "\n"


def main():
    for name, text in BAD.items():
        with open(os.path.join(HERE, name), "w") as f:
            f.write(text)
    with open(os.path.join(HERE, "none.csv"), "w") as f:
        f.write(NONE)
    with open(os.path.join(HERE, "flat.vtk"), "w") as f:
        f.write(flat_vtk())


if __name__ == "__main__":
    main()
