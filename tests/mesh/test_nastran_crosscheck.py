#!/usr/bin/python3
"""Cross-checks cadmorph's Nastran bulk data I/O against decks and readers nobody here wrote.

usage: test_nastran_crosscheck.py <work dir>   (PYTHONPATH: the built cadmorph package)

1. Decks gmsh writes (small, large and free field; tet4, tet10, and extruded hex20/prism15):
   cadmorph's nodes are gmsh's to the precision of the fields, its cells meshio's reading of the
   same deck (meshio's Nastran -> VTK node order for CHEXA20 included), every solid of positive
   volume and every mid-side node at the middle of its VTK edge.
2. Decks meshio writes (fixed-large, fixed-small and free GRIDs; tets, hexes, wedges,
   pyramids, triangles, quads): the same nodes and cells as meshio's mesh.
3. An affine motion written back into gmsh's small-field deck: every line but the GRIDs' as it
   was, and gmsh reads the affine image to the precision of each field.
4. A mesh not read from Nastran (gmsh's .msh) written as .bdf: gmsh and meshio read it.
"""
import os
import shutil
import sys

import gmsh
import meshio
import numpy as np

import cadmorph

work = os.path.join(sys.argv[1], "nastran_crosscheck")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL:", msg)


def check(cond, msg):
    if not cond:
        fail(msg)


VTK_EDGES = {
    "tet10": (4, [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]),
    "hex20": (8, [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)]),
    "wedge15": (6, [(0, 1), (1, 2), (2, 0), (3, 4), (4, 5), (5, 3), (0, 3), (1, 4), (2, 5)]),
    "tri6": (3, [(0, 1), (1, 2), (2, 0)]),
}
MESHIO_NAMES = {"line": "line2", "tetra": "tet4", "tetra10": "tet10", "hexahedron": "hex8", "hexahedron20": "hex20",
                "wedge": "wedge6", "pyramid": "pyramid5", "triangle": "tri3", "triangle6": "tri6", "quad": "quad4"}


def gmsh_decks(name, order, extruded=False):
    """One gmsh mesh written as small (BdfFieldFormat 1), large (2) and free (0) field."""
    gmsh.clear()
    if extruded:
        gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
        gmsh.model.occ.synchronize()
        gmsh.model.mesh.setRecombine(2, 1)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
        gmsh.model.occ.extrude([(2, 1)], 0, 0, 0.5, [2], recombine=True)
    else:
        gmsh.model.occ.addBox(0, 0, 0, 1, 2, 0.5)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 1)
    gmsh.model.mesh.generate(3)
    if order == 2:
        gmsh.model.mesh.setOrder(2)
    paths = []
    for field, fmt in (("small", 1), ("large", 2), ("free", 0)):
        paths.append(os.path.join(work, "%s_%s.bdf" % (name, field)))
        gmsh.option.setNumber("Mesh.BdfFieldFormat", fmt)
        gmsh.write(paths[-1])
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    return paths, xyz.reshape(-1, 3)[np.argsort(tags)]


def meshio_of(path):
    """meshio's reading of a deck (meshio wants BEGIN BULK: a copy with one)."""
    copy = path + ".meshio.bdf"
    with open(path) as f, open(copy, "w") as g:
        text = f.read()
        g.write(text if "BEGIN BULK" in text else "BEGIN BULK\n" + text)
    return meshio.read(copy)


def solids_positive(m, what):
    sj = cadmorph.quality(m, threads=1).per_cell
    dims = np.array([t in ("tet4", "tet10", "hex8", "hex20", "wedge6", "wedge15", "pyr5", "pyr13") for t in m.cell_types])
    check((sj[dims] > 0).all(), "%s: %d solids not of positive volume" % (what, int((sj[dims] <= 0).sum())))


def mid_nodes(m, what, tol):
    p = m.points
    for t, block in m.cells:
        if t not in VTK_EDGES:
            continue
        nc, edges = VTK_EDGES[t]
        block = np.asarray(block)
        for i, (a, b) in enumerate(edges):
            err = np.abs(p[block[:, nc + i]] - (p[block[:, a]] + p[block[:, b]]) / 2).max()
            check(err <= tol, "%s: %s mid-side node %d is %g from the middle of its VTK edge" % (what, t, i, err))


def same_cells(m, ref, what):
    """cadmorph's cells against meshio's (VTK order), block by block by type."""
    ours = {}
    for t, block in m.cells:
        ours.setdefault(t, []).append(np.asarray(block))
    theirs = {}
    for cb in ref.cells:
        theirs.setdefault(MESHIO_NAMES.get(cb.type, cb.type), []).append(cb.data)
    check(sorted(ours) == sorted(theirs), "%s: cell types %s vs meshio's %s" % (what, sorted(ours), sorted(theirs)))
    for t in ours:
        if t not in theirs:
            continue
        a, b = np.concatenate(ours[t]), np.concatenate(theirs[t])
        check(a.shape == b.shape and (a == b).all(), "%s: %s connectivity differs from meshio's" % (what, t))


# ---- 1. gmsh's decks ----
gmsh.initialize()
gmsh.option.setNumber("General.Verbosity", 2)
for name, order, extruded in [("tet", 1, False), ("tet10", 2, False), ("hex20", 2, True)]:
    paths, xyz = gmsh_decks(name, order, extruded)
    small = None
    for path in paths:
        what = os.path.basename(path)
        m = cadmorph.read_mesh(path)
        check(m.n_nodes == len(xyz), "%s: %d nodes, gmsh %d" % (what, m.n_nodes, len(xyz)))
        err = np.abs(m.points - xyz).max()
        # gmsh writes 8 columns in small and free field, 16 in large field
        check(err <= (5e-6 if "large" not in what else 1e-8), "%s: nodes %g from gmsh's" % (what, err))
        if small is None:
            # meshio reads gmsh's small-field element cards (not its large-field ones)
            same_cells(m, meshio_of(path), what)
            small = [(t, np.array(b)) for t, b in m.cells]
        else:
            cells = [(t, np.array(b)) for t, b in m.cells]
            check(len(cells) == len(small) and all(t == u and np.array_equal(b, c) for (t, b), (u, c) in zip(cells, small)),
                  "%s: cells differ from the small-field deck's" % what)
        solids_positive(m, what)
        mid_nodes(m, what, 2e-6)
        print("gmsh %-16s %6d nodes %6d cells: nodes within %.1e of gmsh's, cells as meshio's" % (what, m.n_nodes, m.n_cells, err))

# ---- 2. meshio's decks ----
pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1],
                [0.5, 0.5, 1.6], [2, 0, 0], [2, 1, 0], [2, 0, 1], [2, 1, 1], [0.3, 0.4, -0.7]], float) * 1.37 + 0.011
# every solid of positive volume in VTK's order (the reader mirrors the others)
cells = [("hexahedron", np.array([[0, 1, 2, 3, 4, 5, 6, 7]])), ("pyramid", np.array([[4, 5, 6, 7, 8]])),
         ("wedge", np.array([[1, 2, 9, 5, 6, 11], [2, 10, 9, 6, 12, 11]])), ("tetra", np.array([[0, 3, 1, 13]])),
         ("triangle", np.array([[0, 1, 13]])), ("quad", np.array([[9, 10, 12, 11]]))]
mesh = meshio.Mesh(pts, cells)
for fmt in ("fixed-large", "fixed-small", "free"):
    path = os.path.join(work, "meshio_%s.bdf" % fmt)
    meshio.write(path, mesh, file_format="nastran", point_format=fmt, cell_format="fixed-small")
    m = cadmorph.read_mesh(path)
    err = np.abs(m.points - pts).max()
    check(err <= (1e-6 if fmt == "fixed-small" else 1e-10), "meshio %s: nodes %g from meshio's" % (fmt, err))
    same_cells(m, mesh, "meshio " + fmt)
    solids_positive(m, "meshio " + fmt)
    print("meshio %-12s nodes within %.1e, cells as meshio's" % (fmt, err))

# ---- 3. an affine motion written back into gmsh's small-field deck ----
src = os.path.join(work, "tet10_small.bdf")
m = cadmorph.read_mesh(src)
A = np.array([[1.1, 0.2, 0.0], [-0.1, 0.9, 0.3], [0.05, 0.0, 1.2]])
t = np.array([0.123, -2.5, 10.0])
moved = m.points @ A.T + t
m.points = moved
out = os.path.join(work, "out")
os.makedirs(out)
dst = os.path.join(out, "tet10_small.bdf")
cadmorph.write_mesh(dst, m)
a, b = open(src).read().splitlines(), open(dst).read().splitlines()
large = sum(1 for line in b if line.startswith("GRID*"))
check(len(a) == len(b) + 0 - large or len(a) + large == len(b), "written deck: %d lines, source %d" % (len(b), len(a)))
other_a = [line for line in a if not line.startswith(("GRID", "*"))]
other_b = [line for line in b if not line.startswith(("GRID", "*"))]
check(other_a == other_b, "written deck: lines other than GRID cards differ")


def digits(text):
    mant = text.strip().lstrip("+-").replace(".", "")
    for i, ch in enumerate(mant):
        if not ch.isdigit():
            mant = mant[:i]
            break
    d = len(mant.lstrip("0"))
    return d if d else max(len(mant), 1)


# the precision of each coordinate field as read, by GRID id
prec = {}
for line in a:
    if line.startswith("GRID "):
        prec[int(line[8:16])] = [digits(line[24 + 8 * k:32 + 8 * k]) for k in range(3)]
gmsh.clear()
gmsh.open(dst)
tags, xyz, _ = gmsh.model.mesh.getNodes()
xyz = xyz.reshape(-1, 3)[np.argsort(tags)]
worst = 0.0
for i, gid in enumerate(sorted(prec)):
    for k in range(3):
        v = moved[i, k]
        tol = 10.0 ** (np.floor(np.log10(abs(v))) - prec[gid][k] + 1) * 0.5 * 1.0001 if v != 0 else 1e-300
        worst = max(worst, abs(xyz[i, k] - v) / tol)
check(worst <= 1.0, "affine motion: gmsh reads a node %.3g half-units of its field's last digit off" % worst)
check(len(xyz) == m.n_nodes, "affine motion: gmsh reads %d nodes of %d" % (len(xyz), m.n_nodes))
print("write-back: %d GRID cards became large field; gmsh reads the affine image within %.2f of the "
      "fields' half last digit" % (large, worst))

# ---- 4. a new deck from gmsh's .msh ----
gmsh.clear()
gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
gmsh.model.occ.synchronize()
gmsh.model.addPhysicalGroup(3, [1], 4)
gmsh.model.setPhysicalName(3, 4, "solid")
gmsh.model.addPhysicalGroup(2, [1, 2], 7)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
gmsh.model.mesh.generate(3)
gmsh.model.mesh.setOrder(2)
msh = os.path.join(work, "box.msh")
gmsh.write(msh)
m = cadmorph.read_mesh(msh)
new = os.path.join(work, "box_new.bdf")
cadmorph.write_mesh(new, m)
gmsh.clear()
gmsh.open(new)
tags, xyz, _ = gmsh.model.mesh.getNodes()
types = sorted(int(x) for x in gmsh.model.mesh.getElementTypes())
check(len(tags) == m.n_nodes and np.abs(xyz.reshape(-1, 3)[np.argsort(tags)] - m.points).max() < 1e-12,
      "new deck: gmsh's nodes differ")
check(types == [9, 11], "new deck: gmsh reads element types %s (want tri6 9, tet10 11)" % types)
r = meshio.read(new)
check(len(r.points) == m.n_nodes and sorted(c.type for c in r.cells) == ["tetra10", "triangle6"],
      "new deck: meshio reads %s" % r)
same_cells(m, r, "new deck")
print("new deck: gmsh and meshio read %d nodes, tet10 and tri6" % m.n_nodes)
gmsh.finalize()

if failures:
    print("%d failures" % len(failures))
    sys.exit(1)
print("ok")
