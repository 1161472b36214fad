#!/usr/bin/env python3
"""SU2 native .su2 against the files gmsh and meshio write (Debian gmsh/python3-gmsh 4.8,
python3-meshio).

- gmsh writes a tet box with named boundary groups, a mixed mesh (hex, prism, pyramid, tet)
  and a 2-D rectangle of triangles and quads to .su2 and to .vtk: cadmorph's reading of the
  .su2 has the points and the connectivity of the .vtk (so SU2's node order is VTK's, as gmsh
  writes it; SU2's own prism faces {0,1,2} and {5,4,3} are outward in VTK's wedge), and
  gmsh's groups as markers.
- meshio writes the same meshes to .su2 (its number format, no index columns): cadmorph reads
  them alike.
- Written back, an affine image of every node: every byte but the coordinate numbers of the
  point lines is the input's, and meshio reads the affine image exactly; an unmoved mesh is
  written byte for byte.
- A new .su2 from a mesh read from .vtk: meshio reads it with the same points and cells.
gmsh 4.8 has no .su2 reader (it writes the format only), so meshio is the independent reader.

usage: su2_crosscheck.py WORK   (with the built cadmorph package on PYTHONPATH)
"""
import os
import sys
import warnings

import numpy as np

import cadmorph
import gmsh
import meshio

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from su2_files import check, finish  # noqa: E402
WORK = os.path.join(sys.argv[1], "su2_crosscheck")
os.makedirs(WORK, exist_ok=True)
A = np.array([[0.9, 0.1, -0.2], [0.05, 1.1, 0.0], [0.0, -0.3, 1.2]])
B = np.array([0.3, -1.0 / 3.0, 2.5])


def path(name):
    return os.path.join(WORK, name)


def gmsh_write(name, build, names):
    """Builds a model with build(), writes NAME.su2 and NAME.vtk; returns {group: elements}."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    build()
    counts = {}
    for dim, tag in gmsh.model.getPhysicalGroups():
        pname = gmsh.model.getPhysicalName(dim, tag)
        if pname.replace(" ", "_") in names:
            n = 0
            for e in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                for t in gmsh.model.mesh.getElements(dim, e)[1]:
                    n += len(t)
            counts[pname.replace(" ", "_")] = n
    gmsh.write(path(name + ".su2"))
    gmsh.write(path(name + ".vtk"))
    gmsh.finalize()
    return counts


def box():
    gmsh.model.occ.addBox(0, 0, 0, 1, 2, 0.5)
    gmsh.model.occ.synchronize()
    for _, t in gmsh.model.getEntities(2):
        gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [t]), "wall %d" % t if t == 1 else "face_%d" % t)
    gmsh.model.addPhysicalGroup(3, [1])
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
    gmsh.model.mesh.generate(3)


def mixed():
    """One element of each volume type (random corners: the test is about node order)."""
    v = gmsh.model.addDiscreteEntity(3)
    pts = np.random.RandomState(1).rand(18, 3)
    gmsh.model.mesh.addNodes(3, v, list(range(1, 19)), pts.ravel().tolist())
    gmsh.model.mesh.addElementsByType(v, 4, [1], [1, 2, 3, 4])
    gmsh.model.mesh.addElementsByType(v, 5, [2], [5, 6, 7, 8, 9, 10, 11, 12])
    gmsh.model.mesh.addElementsByType(v, 6, [3], [13, 14, 15, 16, 17, 18])
    gmsh.model.mesh.addElementsByType(v, 7, [4], [1, 5, 9, 13, 17])
    s = gmsh.model.addDiscreteEntity(2)
    gmsh.model.mesh.addElementsByType(s, 2, [5], [13, 14, 15])
    gmsh.model.mesh.addElementsByType(s, 3, [6], [5, 6, 7, 8])
    gmsh.model.addPhysicalGroup(3, [v])
    gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, [s]), "inlet")


def rect():
    gmsh.model.occ.addRectangle(0, 0, 0, 2, 1)
    gmsh.model.occ.synchronize()
    for _, t in gmsh.model.getEntities(1):
        gmsh.model.setPhysicalName(1, gmsh.model.addPhysicalGroup(1, [t]), "edge%d" % t)
    gmsh.model.addPhysicalGroup(2, [1])
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
    gmsh.option.setNumber("Mesh.RecombineAll", 1)
    gmsh.model.mesh.generate(2)


CM_TYPES = {"tetra": "tet4", "hexahedron": "hex8", "wedge": "wedge6", "pyramid": "pyramid5",
            "triangle": "tri3", "quad": "quad4", "line": "line2"}


def blocks(cm):
    """cadmorph mesh -> {meshio type: connectivity in file order}."""
    out = {}
    for t, conn in cm.cells:
        out.setdefault(t, []).append(np.asarray(conn))
    return {t: np.vstack(v) for t, v in out.items()}


def same_cells(cm, mio, types, what, vtk_order=False):
    """cadmorph's cells as meshio's. meshio's wedge is gmsh's order (its .vtk reader permutes
    VTK's wedge into it); vtk_order turns it back. meshio's .su2 reader and writer take the
    file's order as is, so a .su2 read by meshio is compared without it."""
    have = blocks(cm)
    for t in types:
        want = [c.data for c in mio.cells if c.type == t]
        if not want:
            continue
        want = np.vstack(want)
        if vtk_order and t == "wedge":
            want = want[:, [0, 2, 1, 3, 5, 4]]
        got = have.get(CM_TYPES[t])
        check(got is not None and np.array_equal(got, want), "%s: %s cells as meshio's %s" % (what, t, len(want)))


def point_block(lines):
    """Indices of the point lines (after NPOIN=, skipping comments and blanks)."""
    idx, i = [], 0
    while i < len(lines):
        if lines[i].strip().upper().startswith(b"NPOIN"):
            n = int(lines[i].split(b"=")[1].split()[0])
            i += 1
            while n and i < len(lines):
                s = lines[i].strip()
                if s and not s.startswith(b"%"):
                    idx.append(i)
                    n -= 1
                i += 1
        else:
            i += 1
    return set(idx)


def only_coordinates_changed(src, dst, dim, what):
    a = open(src, "rb").read().split(b"\n")
    b = open(dst, "rb").read().split(b"\n")
    pts = point_block(a)
    ok = len(a) == len(b) and len(pts) > 0
    changed = 0
    for i in range(min(len(a), len(b))):
        if i in pts:
            ta, tb = a[i].split(), b[i].split()
            # the index columns and the blanks between the numbers as they were
            ok &= ta[dim:] == tb[dim:] and [c for c in a[i] if c in b" \t\r"] == [c for c in b[i] if c in b" \t\r"]
            changed += ta[:dim] != tb[:dim]
        else:
            ok &= a[i] == b[i]
    check(ok and changed > 0, "%s: only coordinate numbers changed (%d point lines)" % (what, changed))


def write_back(src, dim, what):
    """cadmorph writes src back unmoved (byte for byte) and moved by an affine map."""
    cm = cadmorph.read_mesh(src)
    same = path("same_" + os.path.basename(src))
    cadmorph.write_mesh(same, cm)
    check(open(same, "rb").read() == open(src, "rb").read(), "%s: unmoved, written byte for byte" % what)
    x = cm.points.copy()
    if dim == 3:
        y = x @ A.T + B
    else:
        y = x.copy()
        y[:, :2] = x[:, :2] @ A[:2, :2].T + B[:2]
    cm.points = y
    moved = path("moved_" + os.path.basename(src))
    cadmorph.write_mesh(moved, cm)
    only_coordinates_changed(src, moved, dim, what)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        back = meshio.read(moved)
    check(np.array_equal(back.points[:, :dim], y[:, :dim]), "%s: meshio reads the affine image exactly" % what)
    again = cadmorph.read_mesh(moved)
    check(np.array_equal(again.points, y), "%s: cadmorph reads the affine image exactly" % what)


def main():
    cases = [("box", box, 3, {"wall_1", "face_2", "face_3", "face_4", "face_5", "face_6"}),
             ("mixed", mixed, 3, {"inlet"}),
             ("rect", rect, 2, {"edge1", "edge2", "edge3", "edge4"})]
    for name, build, dim, names in cases:
        counts = gmsh_write(name, build, names)
        su2, vtk = path(name + ".su2"), path(name + ".vtk")
        cm = cadmorph.read_mesh(su2)
        ref = meshio.read(vtk)
        check(cm.n_nodes == len(ref.points) and np.allclose(cm.points, ref.points, rtol=0, atol=1e-15),
              "%s: gmsh's .su2 points as its .vtk" % name)
        vol = ["tetra", "hexahedron", "wedge", "pyramid"] if dim == 3 else ["triangle", "quad"]
        same_cells(cm, ref, vol, name + " (gmsh)", vtk_order=True)
        groups = {g[2]: g for g in cm.groups}
        # gmsh writes a blank of a group name as '_'
        check(set(groups) == names, "%s: markers %s" % (name, sorted(groups)))
        for gname, n in counts.items():
            g = groups.get(gname)
            check(g is not None and g[0] == dim - 1 and int(np.sum(cm.physical == g[1])) == n,
                  "%s: marker '%s' has gmsh's %d elements" % (name, gname, n))
        write_back(su2, dim, name + " (gmsh)")

        # meshio's .su2 of the same mesh: its volume cells only (meshio 5.0's marker writer
        # fails on its own CellBlocks)
        mio_mesh = meshio.Mesh(ref.points[:, :dim], [c for c in ref.cells if c.type in vol])
        mio = path(name + "_meshio.su2")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            meshio.write(mio, mio_mesh, file_format="su2")
        cmm = cadmorph.read_mesh(mio)
        check(np.array_equal(cmm.points[:, :dim], ref.points[:, :dim]), "%s: meshio's .su2 points exactly" % name)
        same_cells(cmm, meshio.read(mio), vol, name + " (meshio)")
        write_back(mio, dim, name + " (meshio)")

        # a new .su2 from the mesh read from .vtk: meshio reads it back
        new = path(name + "_new.su2")
        try:
            cadmorph.write_mesh(new, cadmorph.read_mesh(vtk))
        except cadmorph.Error as e:  # a warning (lower-dimensional cells skipped) still writes
            print("note: %s" % e)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            back = meshio.read(new)
        check(np.array_equal(back.points[:, :dim], ref.points[:, :dim]), "%s: new .su2 points exactly (meshio)" % name)
        same_cells(cadmorph.read_mesh(new), back, vol, name + " (new file, meshio)")
    return finish()


if __name__ == "__main__":
    sys.exit(main())
