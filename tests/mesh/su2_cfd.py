#!/usr/bin/env python3
"""An SU2 user's CFD case: a body in a box meshed by gmsh with a volume group ("fluid") and
boundary groups ("wall", "farfield", "symmetry"), written by gmsh to .su2 and as .msh.

- Used as SU2_DEF is: the wall marker's nodes are moved (the body scaled about its centre)
  and the volume follows (`cadmorph warp`), written to mesh_out.su2 beside the input; the
  input carries the FFD block SU2_DEF appends to its outputs. mesh_out.su2 is the input with
  only coordinate numbers changed (FFD block, markers and cells byte for byte); the farfield
  and symmetry points keep their bytes; the wall points are exactly where they were sent;
  meshio reads it with the input's cells and marker elements; no cell is inverted. The output
  is morphed again (a design loop reads its last mesh) the same way.
- The .msh with its volume and boundary groups written to a new .su2 by cadmorph: the
  boundary groups are the markers (by name, with their elements), the volume group's cells
  the NELEM section; meshio reads it.

usage: su2_cfd.py CADMORPH WORK
"""
import contextlib
import csv
import os
import re
import subprocess
import sys

import numpy as np

import gmsh
import meshio

CLI = sys.argv[1]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from su2_files import check, finish, markers, point_lines  # noqa: E402
WORK = os.path.join(sys.argv[2], "su2_cfd")
os.makedirs(WORK, exist_ok=True)
FFD = b"FFD_NBOX= 0\nFFD_NLEVEL= 0\n"


def w(name):
    return os.path.join(WORK, name)


def quiet_read(path):
    with open(os.devnull, "w") as null, contextlib.redirect_stderr(null):
        return meshio.read(path)


def make_case():
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("cfd")
    box = gmsh.model.occ.addBox(-2, -2, 0, 6, 4, 2)
    body = gmsh.model.occ.addSphere(0, 0, 1, 0.5)
    fluid, _ = gmsh.model.occ.cut([(3, box)], [(3, body)])
    gmsh.model.occ.synchronize()
    wall, sym, far = [], [], []
    for _, s in gmsh.model.getBoundary(fluid, oriented=False):
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(2, s)
        if x1 - x0 < 1.1 and y1 - y0 < 1.1:
            wall.append(s)
        elif z1 - z0 < 1e-3 and z0 < 1e-3:
            sym.append(s)
        else:
            far.append(s)
    for dim, tags, name in ((3, [t for _, t in fluid], "fluid"), (2, wall, "wall"), (2, sym, "symmetry"),
                            (2, far, "farfield")):
        gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, tags), name)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.6)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.1)
    gmsh.model.mesh.setSize(gmsh.model.getBoundary([(2, s) for s in wall], recursive=True), 0.1)
    gmsh.model.mesh.generate(3)
    gmsh.write(w("mesh.su2"))
    gmsh.write(w("mesh.msh"))
    gmsh.finalize()
    with open(w("mesh.su2"), "ab") as f:
        f.write(FFD)


def deform_like_su2_def(src, dst, scale):
    """The wall scaled about the body's centre; every other boundary node fixed."""
    nodes, _ = markers(src)
    x = quiet_read(src).points
    wall = sorted(nodes["wall"])
    centre = np.array([0.0, 0.0, 1.0])
    target = centre + scale * (x[wall] - centre)
    with open(w("wall.csv"), "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["node", "dx", "dy", "dz"])
        for n, t in zip(wall, target):
            out.writerow([n] + [repr(v) for v in (t - x[n])])
    p = subprocess.run([CLI, "warp", "--mesh", src, "--displacements", w("wall.csv"), "-o", dst],
                       capture_output=True, text=True)
    check(p.returncode == 0 and re.search(r" inverted=0 cells=\d+", p.stdout) is not None,
          "warp %s -> %s: exit %d, no inverted cell %s" % (os.path.basename(src), os.path.basename(dst),
                                                            p.returncode, p.stderr.strip()))
    if p.returncode != 0:
        return
    # only coordinate numbers changed: the cells, markers and FFD block byte for byte
    head0, pts0, tail0 = point_lines(src)
    head1, pts1, tail1 = point_lines(dst)
    check(head0 == head1 and tail0 == tail1 and len(pts0) == len(pts1) and open(dst, "rb").read().endswith(FFD),
          "%s: cells, markers and the FFD block byte for byte" % os.path.basename(dst))
    check(all(a.split()[3:] == b.split()[3:] for a, b in zip(pts0, pts1)), "%s: point indices kept" % os.path.basename(dst))
    fixed = (nodes["farfield"] | nodes["symmetry"]) - nodes["wall"]
    check(all(pts0[n] == pts1[n] for n in fixed), "%s: %d farfield and symmetry points keep their bytes" % (
        os.path.basename(dst), len(fixed)))
    m0, m1 = quiet_read(src), quiet_read(dst)
    check(np.array_equal(m1.points[wall], x[wall] + (target - x[wall])), "%s: wall points exactly where sent" %
          os.path.basename(dst))
    check(len(m0.cells) == len(m1.cells) and all(a.type == b.type and np.array_equal(a.data, b.data)
                                                 for a, b in zip(m0.cells, m1.cells)),
          "%s: meshio reads the input's cells and marker elements" % os.path.basename(dst))


def main():
    make_case()
    nodes, elems = markers(w("mesh.su2"))
    check(sorted(nodes) == ["farfield", "symmetry", "wall"], "gmsh's markers: %s" % sorted(nodes))
    deform_like_su2_def(w("mesh.su2"), w("mesh_out.su2"), 1.15)
    deform_like_su2_def(w("mesh_out.su2"), w("mesh_out2.su2"), 0.9)

    # the .msh with volume and boundary groups, written as a new .su2 by cadmorph
    p = subprocess.run([CLI, "warp", "--mesh", w("mesh.msh"), "--displacements", w("wall.csv"), "-o", w("new.su2")],
                       capture_output=True, text=True)
    check(p.returncode == 0, "warp mesh.msh -> new.su2: exit %d %s" % (p.returncode, p.stderr.strip()))
    new_nodes, new_elems = markers(w("new.su2"))
    check(sorted(new_nodes) == sorted(nodes) and all(len(new_elems[k]) == len(elems[k]) for k in elems),
          "new.su2: the boundary groups are the markers, with gmsh's element counts")
    ref, new = quiet_read(w("mesh.msh")), quiet_read(w("new.su2"))
    n_tets = sum(len(c.data) for c in ref.cells if c.type == "tetra")
    check(sum(len(c.data) for c in new.cells if c.type == "tetra") == n_tets and len(new.points) == len(ref.points),
          "new.su2: meshio reads the %d tets of the fluid group and every point" % n_tets)
    return finish()


if __name__ == "__main__":
    sys.exit(main())
