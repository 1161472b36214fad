#!/usr/bin/python3
"""Meshes and cross-checks for Staten's comparators (volume/warp_femwarp.c and friends).

  warp_staten.py setup WORK     gmsh writes WORK/staten/: mixed.msh (tets, hexes, wedges,
                                pyramids), tets.msh (a box with a cylindrical hole), hexes.msh
                                (a graded structured block), and for the last two a D.csv of
                                a smooth non-affine motion of every boundary node
  warp_staten.py femwarp WORK NAME OUT
                                assembles the linear FE Laplacian of WORK/staten/NAME.msh
                                independently (numpy: P1 tets, Q1 hexes with 2x2x2 Gauss),
                                solves K_II x = -K_IB d_B with scipy's spsolve and compares
                                with the displacement field of cadmorph's OUT (<= 1e-10 rel.)
  warp_staten.py affine-csv MESH CSV
                                writes CSV: the affine motion AFFINE of MESH's boundary nodes
  warp_staten.py affine MESH OUT...
                                every node of each OUT (cadmorph warp of MESH with that CSV)
                                moved by AFFINE, to 1e-10 of the diagonal
"""
import os
import sys

import numpy as np


AFFINE = np.array([[0.02, -0.05, 0.01], [0.03, 0.04, -0.02], [-0.01, 0.02, 0.05]])
SHIFT = np.array([0.1, -0.2, 0.05])


def boundary_nodes(cells):
    """Nodes of faces used by exactly one cell (tets and hexes, VTK node order)."""
    faces = {"tetra": [(0, 1, 2), (0, 1, 3), (1, 2, 3), (0, 2, 3)],
             "hexahedron": [(0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5),
                            (2, 3, 7, 6), (3, 0, 4, 7)]}
    count = {}
    for kind, conn in cells.items():
        for f in faces[kind]:
            for row in conn[:, f]:
                key = tuple(sorted(row))
                count[key] = count.get(key, 0) + 1
    nodes = set()
    for key, n in count.items():
        if n == 1:
            nodes.update(key)
    return np.array(sorted(nodes), dtype=np.int64)


def smooth_motion(x, size):
    return 0.05 * size * np.column_stack([np.sin(2 * x[:, 0] / size) * x[:, 1] / size,
                                          np.cos(3 * x[:, 1] / size) * x[:, 2] / size,
                                          (x[:, 0] * x[:, 1] / size ** 2) ** 2])


def write_csv(path, nodes, d):
    with open(path, "w") as f:
        f.write("node,dx,dy,dz\n")
        for v, row in zip(nodes, d):
            f.write("%d,%.17g,%.17g,%.17g\n" % (v, row[0], row[1], row[2]))


def volume_cells(mesh):
    return {k: v for k, v in mesh.cells_dict.items() if k in ("tetra", "hexahedron")}


def setup(work):
    import gmsh
    import meshio
    out = os.path.join(work, "staten")
    os.makedirs(out, exist_ok=True)
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)

    # mixed: a wedge block (extruded triangles), a hex block (extruded quads) and a tet block
    # meshed against the hex block's quad face, where gmsh puts pyramids
    gmsh.model.add("mixed")
    g = gmsh.model.geo
    n = 5
    p = [g.addPoint(x, y, 0) for x, y in
         [(-1, 0), (0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1), (-1, 1)]]
    line = lambda a, b: g.addLine(p[a], p[b])
    b0, b1, b2, r, t2, t1, t0, le = (line(0, 1), line(1, 2), line(2, 3), line(3, 4),
                                     line(4, 5), line(5, 6), line(6, 7), line(7, 0))
    m0, m1 = line(1, 6), line(2, 5)
    sw = g.addPlaneSurface([g.addCurveLoop([b0, m0, t0, le])])
    sh = g.addPlaneSurface([g.addCurveLoop([b1, m1, t1, -m0])])
    st = g.addPlaneSurface([g.addCurveLoop([b2, r, t2, -m1])])
    for c in [b0, b1, b2, r, t2, t1, t0, le, m0, m1]:
        g.mesh.setTransfiniteCurve(c, n)
    g.mesh.setTransfiniteSurface(sh)
    g.mesh.setRecombine(2, sh)
    g.extrude([(2, sw), (2, sh)], 0, 0, 1, [n - 1], recombine=True)
    g.extrude([(2, st)], 0, 0, 1)
    g.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
    gmsh.model.mesh.generate(3)
    gmsh.write(os.path.join(out, "mixed.msh"))

    # tets: a box with a cylindrical hole (a concave domain)
    gmsh.model.add("tets")
    occ = gmsh.model.occ
    box = occ.addBox(0, 0, 0, 2, 1, 1)
    hole = occ.addCylinder(1, 0.5, -0.1, 0, 0, 1.2, 0.25)
    occ.cut([(3, box)], [(3, hole)])
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.15)
    gmsh.model.mesh.generate(3)
    gmsh.write(os.path.join(out, "tets.msh"))

    # hexes: a graded transfinite block
    gmsh.model.add("hexes")
    occ = gmsh.model.occ
    occ.addBox(0, 0, 0, 2, 1, 1)
    occ.synchronize()
    for dim, tag in gmsh.model.getEntities(1):
        gmsh.model.mesh.setTransfiniteCurve(tag, 9, "Progression", 1.15)
    for dim, tag in gmsh.model.getEntities(2):
        gmsh.model.mesh.setTransfiniteSurface(tag)
        gmsh.model.mesh.setRecombine(2, tag)
    for dim, tag in gmsh.model.getEntities(3):
        gmsh.model.mesh.setTransfiniteVolume(tag)
    gmsh.model.mesh.generate(3)
    gmsh.write(os.path.join(out, "hexes.msh"))
    gmsh.finalize()

    for name in ("tets", "hexes"):
        mesh = meshio.read(os.path.join(out, name + ".msh"))
        nodes = boundary_nodes(volume_cells(mesh))
        write_csv(os.path.join(out, name + "_D.csv"), nodes,
                  smooth_motion(mesh.points[nodes], 2.0))
        if name == "tets":
            affine_csv(os.path.join(out, "tets.msh"), os.path.join(out, "affine.csv"))


def stiffness(points, cells, ndof, dof):
    """Linear FE Laplacian assembled by element type, as COO triplets over dof(node)."""
    rows, cols, vals = [], [], []
    if "tetra" in cells:
        t = cells["tetra"]
        x = points[t]                                    # (nt, 4, 3)
        j = np.transpose(x[:, 1:] - x[:, :1], (0, 2, 1))  # columns: edges
        ji = np.linalg.inv(j)
        g = np.concatenate([-ji.sum(axis=1, keepdims=True), ji], axis=1)  # (nt, 4, 3)
        v = np.abs(np.linalg.det(j)) / 6
        k = v[:, None, None] * np.einsum("eai,ebi->eab", g, g)
        rows.append(np.repeat(t, 4, axis=1).ravel())
        cols.append(np.tile(t, (1, 4)).ravel())
        vals.append(k.ravel())
    if "hexahedron" in cells:
        h = cells["hexahedron"]
        x = points[h]                                    # (nh, 8, 3)
        s = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                      [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], float)
        k = np.zeros((len(h), 8, 8))
        for gp in s / np.sqrt(3):
            f = 1 + s * gp                               # (8, 3)
            dn = np.column_stack([s[:, 0] * f[:, 1] * f[:, 2], s[:, 1] * f[:, 0] * f[:, 2],
                                  s[:, 2] * f[:, 0] * f[:, 1]]) / 8   # (8, 3) d/dxi
            jac = np.einsum("eai,aj->eij", x, dn)        # dx_i / dxi_j
            g = np.einsum("eji,aj->eai", np.linalg.inv(jac), dn)
            k += np.abs(np.linalg.det(jac))[:, None, None] * np.einsum("eai,ebi->eab", g, g)
        rows.append(np.repeat(h, 8, axis=1).ravel())
        cols.append(np.tile(h, (1, 8)).ravel())
        vals.append(k.ravel())
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)


def read_csv(path):
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return data[:, 0].astype(np.int64), data[:, 1:]


def femwarp(work, name, out):
    import meshio
    import scipy.sparse as sp
    import scipy.sparse.linalg as spl
    d = os.path.join(work, "staten")
    m0 = meshio.read(os.path.join(d, name + ".msh"))
    cells = volume_cells(m0)
    nodes, disp = read_csv(os.path.join(d, name + "_D.csv"))
    fixed = np.zeros(len(m0.points), bool)
    fixed[boundary_nodes(cells)] = True
    fixed[nodes] = True
    used = np.zeros(len(m0.points), bool)
    for c in cells.values():
        used[c.ravel()] = True
    free = used & ~fixed
    dB = np.zeros((len(m0.points), 3))
    dB[nodes] = disp
    r, c, v = stiffness(m0.points, cells, len(m0.points), None)
    k = sp.csr_matrix((v, (r, c)), shape=(len(m0.points),) * 2)
    kii = k[free][:, free].tocsc()
    kib = k[free][:, fixed]
    x = spl.spsolve(kii, -(kib @ dB[fixed]))
    got = meshio.read(out).point_data["displacement"]
    err = np.abs(got[free] - x).max() / np.abs(x).max()
    berr = np.abs(got[fixed] - dB[fixed]).max()
    print("femwarp %s: %d free nodes, |cadmorph - scipy| / |scipy| = %.3g, boundary %.3g"
          % (name, free.sum(), err, berr))
    if not (err <= 1e-10 and berr == 0 and free.sum() > 100):
        sys.exit("femwarp %s: cadmorph and scipy's spsolve differ" % name)


def affine_csv(mesh_path, csv):
    import meshio
    mesh = meshio.read(mesh_path)
    nodes = boundary_nodes(volume_cells(mesh))
    write_csv(csv, nodes, mesh.points[nodes] @ AFFINE.T + SHIFT)


def affine(mesh_path, outs):
    import meshio
    m0 = meshio.read(mesh_path)
    want = m0.points @ AFFINE.T + SHIFT
    size = np.linalg.norm(m0.points.max(axis=0) - m0.points.min(axis=0))
    for out in outs:
        got = meshio.read(out).point_data["displacement"]
        err = np.abs(got - want).max() / size
        print("%s: affine error %.3g x diagonal" % (out, err))
        if not err <= 1e-10:
            sys.exit("%s: the affine motion is not reproduced" % out)


def main(argv):
    if len(argv) >= 2 and argv[0] == "setup":
        setup(argv[1])
    elif len(argv) == 4 and argv[0] == "femwarp":
        femwarp(argv[1], argv[2], argv[3])
    elif len(argv) == 3 and argv[0] == "affine-csv":
        affine_csv(argv[1], argv[2])
    elif len(argv) >= 3 and argv[0] == "affine":
        affine(argv[1], argv[2:])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
