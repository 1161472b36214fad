#!/usr/bin/python3
"""Cross-checks cadmorph's gmsh .msh I/O against code nobody here wrote.

usage: test_msh_crosscheck.py <tests/data> <work dir> <mesh/io/msh_common.c>

1. The gmsh -> VTK node permutations in msh_common.c equal the ones derived from gmsh's own
   reference elements (gmsh.model.mesh.getElementProperties) and VTK's
   (vtkCell.GetParametricCoords), by matching each higher-order node to the corners it is the
   centroid of.
2. What test_msh read from each fixture (msh_dump_*.txt) equals what the gmsh API reads from
   the same file (node tags, coordinates bit for bit, element tags, corner order, node sets,
   entities and physical groups) and, where meshio supports the type, meshio's VTK-ordered
   connectivity.
3. Every file test_msh wrote (msh_rt_*.msh) opens in gmsh and meshio, with the same nodes as
   the source and the fields as views / point and cell data.
"""
import glob
import itertools
import os
import re
import sys

import gmsh
import meshio
import numpy as np
import vtk

data_dir, work_dir, common_c = sys.argv[1:4]
failures = []


def fail(msg):
    failures.append(msg)
    print("FAIL:", msg)


# ---- 1. permutations ----
GMSH_TYPES = {  # cadmorph name: (gmsh id, vtk class, corners)
    "tet10": (11, vtk.vtkQuadraticTetra, 4),
    "hex20": (17, vtk.vtkQuadraticHexahedron, 8),
    "hex27": (12, vtk.vtkTriQuadraticHexahedron, 8),
    "wedge6": (6, vtk.vtkWedge, 6),
    "wedge15": (18, vtk.vtkQuadraticWedge, 6),
    "wedge18": (13, vtk.vtkBiQuadraticQuadraticWedge, 6),
}


def corner_sets(points, corners):
    """For each node, the tuple of corners it is the centroid of."""
    points = np.asarray(points)
    out = []
    for i, p in enumerate(points):
        if i < corners:
            out.append((i,))
            continue
        found = None
        for r in (2, 4, 8):
            for s in itertools.combinations(range(corners), r):
                if np.allclose(points[list(s)].mean(0), p, atol=1e-9):
                    found = s
                    break
            if found:
                break
        out.append(found)
    return out


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
source = open(common_c).read()
tables = {m.group(1): [int(x) for x in m.group(2).replace("\n", " ").split(",")]
          for m in re.finditer(r"perm_(\w+)\[\d+\]\s*=\s*\{([^}]*)\}", source)}
for name, (gid, cls, corners) in GMSH_TYPES.items():
    _, dim, _, nn, loc, _ = gmsh.model.mesh.getElementProperties(gid)
    cell = cls()
    pc = cell.GetParametricCoords()
    pc = np.array([pc[i] for i in range(3 * cell.GetNumberOfPoints())]).reshape(-1, 3)[:, :dim]
    if name.startswith("wedge"):
        # VTK winds the wedge's (0,1,2) away from (3,4,5), gmsh towards it (vtkWedge docs,
        # meshio, gmsh's own VTK export), although vtkWedge's parametric coordinates follow
        # gmsh: the same element is gmsh's reference mirrored u <-> v (w in [-1,1] -> [0,1]).
        ref = np.array(loc).reshape(nn, dim)
        mirrored = np.column_stack([ref[:, 1], ref[:, 0], (ref[:, 2] + 1) / 2])
        perm = [int(np.argmin(np.linalg.norm(mirrored - p, axis=1))) for p in pc]
        if max(np.linalg.norm(mirrored[perm[i]] - pc[i]) for i in range(len(pc))) > 1e-12:
            fail(f"permutation {name}: no node-by-node match after mirroring")
    else:
        g = corner_sets(np.array(loc).reshape(nn, dim), corners)
        v = corner_sets(pc, corners)
        perm = [g.index(s) for s in v]
    if tables.get(name) != perm:
        fail(f"permutation {name}: msh_common.c has {tables.get(name)}, gmsh/VTK give {perm}")
# VTK's pyramids collapse a hex in parametric space, so match their edges by topology
vtk_pyr = [(0,), (1,), (2,), (3,), (4,), (0, 1), (1, 2), (2, 3), (0, 3), (0, 4), (1, 4), (2, 4), (3, 4)]
_, dim, _, nn, loc, _ = gmsh.model.mesh.getElementProperties(14)  # pyramid14
g = corner_sets(np.array(loc).reshape(nn, dim), 5)
g[13] = (0, 1, 2, 3)  # base centre (also the centroid of 0-2; VTK calls it the base face centre)
for name, n in (("pyr13", 13), ("pyr14", 14)):
    perm = [g.index(s) for s in (vtk_pyr + [(0, 1, 2, 3)])[:n]]
    if tables.get(name) != perm:
        fail(f"permutation {name}: msh_common.c has {tables.get(name)}, gmsh/VTK give {perm}")
print("permutations checked:", sorted(tables))

# ---- 2. dumps vs the gmsh API and meshio ----
CM_NAMES = {15: "point", 1: "line2", 8: "line3", 2: "tri3", 9: "tri6", 3: "quad4", 16: "quad8",
            10: "quad9", 4: "tet4", 11: "tet10", 5: "hex8", 17: "hex20", 12: "hex27", 6: "wedge6",
            18: "wedge15", 13: "wedge18", 7: "pyramid5", 19: "pyramid13", 14: "pyramid14"}
MESHIO_NAMES = {"vertex": "point", "line": "line2", "line3": "line3", "triangle": "tri3",
                "triangle6": "tri6", "quad": "quad4", "quad8": "quad8", "quad9": "quad9",
                "tetra": "tet4", "tetra10": "tet10", "hexahedron": "hex8", "hexahedron20": "hex20",
                "hexahedron27": "hex27", "wedge": "wedge6", "wedge15": "wedge15",
                "pyramid": "pyramid5", "pyramid13": "pyramid13"}


def read_dump(path):
    with open(path) as f:
        lines = f.read().split("\n")
    n = int(lines[0].split()[1])
    nodes = {}
    for line in lines[1:1 + n]:
        t, x, y, z = line.split()
        nodes[int(t)] = (float(x), float(y), float(z))
    nc = int(lines[1 + n].split()[1])
    cells = []
    for line in lines[2 + n:2 + n + nc]:
        w = line.split()
        cells.append((int(w[0]), w[1], int(w[2]), int(w[3]), [int(x) for x in w[4:]]))
    return nodes, cells


def gmsh_model():
    """Nodes and elements of the open model: {tag: xyz}, {tag: (name, phys, entity, nodes)}."""
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    nodes = {int(t): tuple(xyz[3 * i:3 * i + 3]) for i, t in enumerate(tags)}
    elems = {}
    for dim, etag in gmsh.model.getEntities():
        phys = gmsh.model.getPhysicalGroupsForEntity(dim, etag)
        p = int(phys[0]) if len(phys) else 0
        types, etags, enodes = gmsh.model.mesh.getElements(dim, etag)
        for t, tt, nn in zip(types, etags, enodes):
            k = len(nn) // len(tt)
            for i, e in enumerate(tt):
                elems[int(e)] = (CM_NAMES.get(int(t), str(t)), p, etag, [int(x) for x in nn[k * i:k * (i + 1)]])
    return nodes, elems


for dump in sorted(glob.glob(os.path.join(work_dir, "msh_dump_*.txt"))):
    name = os.path.basename(dump)[len("msh_dump_"):-4]
    fixture = os.path.join(data_dir, "msh", name + ".msh")
    nodes, cells = read_dump(dump)
    gmsh.clear()
    gmsh.open(fixture)
    gnodes, gelems = gmsh_model()
    if gnodes != nodes:
        fail(f"{name}: nodes differ from gmsh's ({len(nodes)} vs {len(gnodes)})")
    if len(gelems) != len(cells):
        fail(f"{name}: {len(cells)} cells, gmsh has {len(gelems)}")
    bad = 0
    for tag, typ, phys, ent, conn in cells:
        g = gelems.get(tag)
        perm = tables.get(typ.replace("pyramid", "pyr"))
        expected = [g[3][perm[i]] for i in range(len(perm))] if g and perm else (g[3] if g else None)
        if g is None or g[0] != typ or g[1] != phys or g[2] != ent or expected != conn:
            bad += 1
            if bad < 4:
                print(f"{name}: element {tag}: ours {typ} phys {phys} ent {ent} {conn}, gmsh {g}")
    if bad:
        fail(f"{name}: {bad} elements differ from gmsh's")
    # meshio: VTK-ordered connectivity (it has no wedge18/pyramid14 reordering; its 2.2
    # reader fails on wedge15)
    try:
        m = meshio.read(fixture)
    except KeyError as e:
        print(f"{name}: meshio cannot read it ({e!r}); gmsh check only")
        continue
    index_tag = np.array(sorted(nodes))  # meshio keeps file order; map via coordinates instead
    ours = {}
    for tag, typ, phys, ent, conn in cells:
        ours.setdefault(typ, []).append(conn)
    # meshio renumbers nodes 0..n-1 in file order, which is the tag order of our dump
    order = list(nodes.keys())
    if not np.array_equal(np.array([nodes[t] for t in order]), m.points):
        fail(f"{name}: meshio points differ")
    for block in m.cells:
        typ = MESHIO_NAMES.get(block.type)
        if typ is None:
            continue
        got = [[order[i] for i in row] for row in block.data.tolist()]
        # meshio splits types by entity; compare the multiset of cells
        want = ours.get(typ, [])
        missing = [c for c in got if c not in want]
        if missing:
            fail(f"{name}: {len(missing)} meshio {block.type} cells not in ours, e.g. {missing[0]}")
    print(f"{name}: {len(nodes)} nodes, {len(cells)} cells agree with gmsh and meshio")

# ---- 3. files cadmorph wrote ----
written = sorted(glob.glob(os.path.join(work_dir, "msh_rt_*.msh")))
if len(written) < 16:
    fail(f"expected 16 round-trip files in {work_dir}, found {len(written)}")
sources = {"box_hole": "box_hole_41b", "box_hole_from22": "box_hole_22", "hybrid_o2": "hybrid_o2_41",
           "hybrid_o2i": "hybrid_o2i_22b"}
for path in written:
    base = os.path.basename(path)[len("msh_rt_"):-4]
    src = sources[base.rsplit("_", 1)[0]]
    nodes, cells = read_dump(os.path.join(work_dir, f"msh_dump_{src}.txt"))
    gmsh.clear()
    gmsh.logger.start()
    try:
        gmsh.open(path)
    except Exception as e:
        fail(f"{base}: gmsh cannot open it: {e}")
        gmsh.logger.stop()
        continue
    log = gmsh.logger.get()
    gmsh.logger.stop()
    errors = [l for l in log if l.startswith("Error")]
    if errors:
        fail(f"{base}: gmsh reports {errors[:2]}")
    gnodes, gelems = gmsh_model()
    if gnodes != nodes:
        fail(f"{base}: gmsh reads other nodes than the source ({len(gnodes)} vs {len(nodes)})")
    if len(gelems) != len(cells):
        fail(f"{base}: gmsh reads {len(gelems)} elements, the source has {len(cells)}")
    # the fields test_msh wrote: displacement[i] = 1e-3 cos(3i + k) + 1/7, sj[c] = sin(c) / 3
    views = gmsh.view.getTags()
    if len(views) != 2:
        fail(f"{base}: gmsh made {len(views)} views of the 2 fields")
    order = list(nodes)
    for v in views:
        kind, tags, data, _, comps = gmsh.view.getModelData(v, 0)
        data = np.array(data)
        if kind == "NodeData":
            want = np.array([[1e-3 * np.cos(3 * order.index(t) + k) + 1 / 7 for k in range(3)] for t in tags])
        else:
            want = np.array([[np.sin(i) / 3] for i in range(len(tags))])
        if data.shape != want.shape or np.abs(data - want).max() > 1e-15:
            fail(f"{base}: gmsh view {kind} values differ from what test_msh wrote")
        gmsh.view.remove(v)
    try:
        m = meshio.read(path)
        note = ""
    except Exception as e:
        # meshio 5.3 reads binary 4.1 data tags as int (gmsh writes size_t, as we do) and
        # splits 2.2 $ElementData wrongly; check the rest of the file without the data
        raw = open(path, "rb").read()
        for sec in (b"NodeData", b"ElementData"):
            while (a := raw.find(b"$" + sec + b"\n")) >= 0:
                z = raw.find(b"$End" + sec + b"\n", a)
                raw = raw[:a] + raw[z + len(sec) + 5:]
        stripped = os.path.join(work_dir, "nodata_" + os.path.basename(path))
        open(stripped, "wb").write(raw)
        try:
            m = meshio.read(stripped)
        except KeyError as e2:
            print(f"{base}: meshio cannot read it ({e2!r})")
            continue
        note = f" (meshio: {type(e).__name__} on the data sections, read without them)"
        m.point_data["displacement"] = np.zeros((len(m.points), 3))
        m.cell_data["scaled_jacobian"] = [0]
    if len(m.points) != len(nodes) or not np.array_equal(m.points, np.array([nodes[t] for t in order])) or \
            np.asarray(m.point_data.get("displacement", [])).shape != (len(nodes), 3) or \
            "scaled_jacobian" not in m.cell_data:
        fail(f"{base}: meshio reads {len(m.points)} points, point data {list(m.point_data)}, "
             f"cell data {list(m.cell_data)}")
    else:
        print(f"{base}: gmsh and meshio read it{note}")

# the hand-made binary file of tests/data/msh/bad (generate_bad.py) is one gmsh reads
gmsh.clear()
gmsh.open(os.path.join(data_dir, "msh", "bad", "ok_binary.msh"))
gn, ge = gmsh_model()
if len(gn) != 4 or len(ge) != 1:
    fail(f"bad/ok_binary.msh: gmsh reads {len(gn)} nodes, {len(ge)} elements")

gmsh.finalize()
print(f"{len(failures)} failures")
sys.exit(1 if failures else 0)
