#!/usr/bin/python3
"""Figures 8-10 of [CMLS] on two gmsh-built parts (OpenCASCADE kernel, surface meshes):
- fandisk-like (Figure 8): a block whose profile (plateau, slanted face, lower step) is
  extruded, with a chamfered front edge; the bottom band (z < 0.35) fixed, a corner of the lower step (the
  handle) moved left and up; constraints: three sharp edges as feature lines, then also the
  plateau (upper left) as a planar area;
- joint-like (Figures 9, 10): a base plate, a post and on top a horizontal pipe; the base
  plate fixed, the back half of the pipe's top lifted and moved sideways; constraints: the rim of
  the pipe's front opening as a circle, then also the post's right face as a plane (Figure 9);
  Figure 10: the top cylinder region (the pipe's outer cylinder) is the handle and every other
  primitive `cadmorph detect` finds is a constraint (planes stay planar, cylinders cylinders).
Each run: `cadmorph deform --method mls --stretch 0 --bend 1` (gamma_c = 10, the paper's),
without and with the constraints (and with gamma_c = 100 and Anderson acceleration). Writes OUT/fig8_10.csv (per run and set: residual before,
after, relative to the diagonal, iterations, times), OUT/<run>.vtu (ParaView: displacement,
constraint_set) and OUT/fig8_10.svg (original, without, with; constrained nodes in red).
usage: fig8_10.py CADMORPH OUT [extra deform options...]"""
import csv, os, re, subprocess, sys
import numpy as np
import gmsh
import meshio
import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection  # noqa: E402

cad, out = sys.argv[1], os.path.abspath(sys.argv[2])
extra = sys.argv[3:]
os.makedirs(out, exist_ok=True)
os.chdir(out)


def surface_mesh(size):
    """the current gmsh model's triangles: points, tris, node index of each gmsh tag, and per
    curve / surface the 0-based node lists (with their boundary; curves in parameter order)"""
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", size / 3)
    gmsh.model.mesh.generate(2)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    index = {int(t): i for i, t in enumerate(tags)}
    pts = xyz.reshape(-1, 3)
    _, enodes = gmsh.model.mesh.getElementsByType(2)
    tris = np.array([index[int(t)] for t in enodes]).reshape(-1, 3)
    curves, surfaces = {}, {}
    for d, t in gmsh.model.getEntities(1):
        nt, _, par = gmsh.model.mesh.getNodes(1, t, includeBoundary=True)
        nodes = [index[int(v)] for v in nt]
        # boundary nodes come last with no parameter: order all by the curve parameter
        pr = gmsh.model.getParametrization(1, t, pts[nodes].ravel())
        curves[t] = [nodes[k] for k in np.argsort(pr)]
    for d, t in gmsh.model.getEntities(2):
        nt, _, _ = gmsh.model.mesh.getNodes(2, t, includeBoundary=True)
        surfaces[t] = sorted({index[int(v)] for v in nt})
    used = np.unique(tris)
    assert len(used) == len(pts), "every node is on a triangle"
    return pts, tris, curves, surfaces


def write_nodes(name, nodes):
    with open(name, "w") as f:
        f.write("node\n" + "".join("%d\n" % v for v in nodes))


def write_handles(name, nodes, d):
    """d: a displacement (3 numbers) or a function of the node index"""
    f_ = d if callable(d) else (lambda v: d)
    with open(name, "w") as f:
        f.write("node,dx,dy,dz\n" + "".join("%d,%.17g,%.17g,%.17g\n" % (v, *f_(v)) for v in nodes))


def unique(nodes):
    """first occurrences, in order (a closed curve lists its vertex twice)"""
    seen = set()
    return [v for v in nodes if not (v in seen or seen.add(v))]


def curve_ends(t):
    b = gmsh.model.getBoundary([(1, t)], oriented=False)
    return [np.array(gmsh.model.getValue(0, p[1], [])) for p in b]


# ---- fandisk-like part ----
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
occ = gmsh.model.occ
prof = [(0, 0), (4, 0), (4, 1.0), (3.2, 1.0), (2.6, 1.6), (0, 1.6)]
pt = [occ.addPoint(x, 0, z) for x, z in prof]
ln = [occ.addLine(pt[i], pt[(i + 1) % len(pt)]) for i in range(len(pt))]
face = occ.addPlaneSurface([occ.addCurveLoop(ln)])
vol = occ.extrude([(2, face)], 0, 2, 0)
vtag = [t for d, t in vol if d == 3][0]
occ.synchronize()
# chamfer the plateau's front edge (y = 0, z = 1.6)
front = [t for d, t in gmsh.model.getEntities(1)
         if all(abs(e[1]) < 1e-9 and abs(e[2] - 1.6) < 1e-9 for e in curve_ends(t))]
surf_at = [t for d, t in gmsh.model.getEntities(2)
           if abs(gmsh.model.getBoundingBox(2, t)[2] - 1.6) < 1e-6 and
           abs(gmsh.model.getBoundingBox(2, t)[5] - 1.6) < 1e-6]
occ.chamfer([vtag], front, surf_at, [0.35])
occ.synchronize()
fpts, ftris, fcurves, fsurfs = surface_mesh(0.09)
fdiag = np.linalg.norm(fpts.max(0) - fpts.min(0))


def is_line(t, p, q):
    e = curve_ends(t)
    return len(e) == 2 and ((np.allclose(e[0], p) and np.allclose(e[1], q)) or
                            (np.allclose(e[0], q) and np.allclose(e[1], p)))


# feature lines: the slanted face's two long edges and the chamfer's upper edge
features = []
for d, t in gmsh.model.getEntities(1):
    e = curve_ends(t)
    if len(e) != 2 or gmsh.model.getType(1, t) != "Line":
        continue
    along_y = abs(e[0][0] - e[1][0]) < 1e-9 and abs(e[0][2] - e[1][2]) < 1e-9
    along_x = abs(e[0][1] - e[1][1]) < 1e-9 and abs(e[0][2] - e[1][2]) < 1e-9
    if along_y and ((abs(e[0][0] - 2.6) < 1e-9 and abs(e[0][2] - 1.6) < 1e-9) or
                    (abs(e[0][0] - 3.2) < 1e-9 and abs(e[0][2] - 1.0) < 1e-9)):
        features.append(t)
    if along_x and abs(e[0][2] - 1.6) < 1e-9 and abs(e[0][1] - 0.35) < 1e-6:
        features.append(t)
assert len(features) == 3, features
# the plateau: the planar face at z = 1.6
plateau = [t for d, t in gmsh.model.getEntities(2)
           if abs(gmsh.model.getBoundingBox(2, t)[2] - 1.6) < 1e-6 and
           abs(gmsh.model.getBoundingBox(2, t)[5] - 1.6) < 1e-6]
assert len(plateau) == 1
gmsh.finalize()

meshio.write("fandisk.vtk", meshio.Mesh(fpts, [("triangle", ftris)]), binary=False)
# the bottom part fixed (a band, not just the bottom plane: with the plane alone, the one
# affine map d = z a fits the handle and the fixed nodes, and MLS reproduces affine maps, so
# no line would bend)
write_nodes("fandisk_F.csv", np.where(fpts[:, 2] < 0.35)[0])
fh = np.where((abs(fpts[:, 2] - 1.0) < 1e-9) & (fpts[:, 0] > 3.45) & (fpts[:, 1] > 1.2))[0]
write_handles("fandisk_H.csv", fh, (-0.5, 0, 0.25))
for k, t in enumerate(features):
    write_nodes("fandisk_line%d.csv" % k, unique(fcurves[t]))
# the plateau's nodes off the feature lines (those are constrained as lines already)
line_nodes = {v for t in features for v in fcurves[t]}
write_nodes("fandisk_plane.csv", [v for v in fsurfs[plateau[0]] if v not in line_nodes])

# ---- joint-like part ----
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
occ = gmsh.model.occ
base = occ.addBox(0, 0, 0, 4, 3, 0.5)
post = occ.addBox(1.4, 0.9, 0.5, 1.2, 1.2, 2.0)
tube = occ.addCylinder(2, 0, 3.0, 0, 3, 0, 0.8)
bore = occ.addCylinder(2, -0.1, 3.0, 0, 3.2, 0, 0.5)
solid, _ = occ.fuse([(3, base)], [(3, post), (3, tube)])
occ.cut(solid, [(3, bore)])
occ.synchronize()
jpts, jtris, jcurves, jsurfs = surface_mesh(0.11)
jdiag = np.linalg.norm(jpts.max(0) - jpts.min(0))
# the rim of the front opening: the circle of radius 0.5 at y = 0
rim = [t for d, t in gmsh.model.getEntities(1)
       if gmsh.model.getType(1, t) == "Circle" and
       np.allclose(gmsh.model.getBoundingBox(1, t), [1.5, 0, 2.5, 2.5, 0, 3.5], atol=1e-6)]
assert len(rim) == 1, rim
# the post's right face: the plane x = 2.6 between the base and the tube (the handle moves
# along +x, so a face of constant y or z could stay planar anyway)
postf = [t for d, t in gmsh.model.getEntities(2)
         if gmsh.model.getType(2, t) == "Plane" and
         abs(gmsh.model.getBoundingBox(2, t)[0] - 2.6) < 1e-6 and
         abs(gmsh.model.getBoundingBox(2, t)[3] - 2.6) < 1e-6]
assert len(postf) == 1, postf
outer = [t for d, t in gmsh.model.getEntities(2)
         if gmsh.model.getType(2, t) == "Cylinder" and
         gmsh.model.getBoundingBox(2, t)[5] > 3.7]
gmsh.finalize()

meshio.write("joint.vtk", meshio.Mesh(jpts, [("triangle", jtris)]), binary=False)
write_nodes("joint_F.csv", np.where(jpts[:, 2] < 0.5 + 1e-9)[0])  # the base plate
jh = np.where((jpts[:, 2] > 3.45) & (jpts[:, 1] > 2.0))[0]
write_handles("joint_H.csv", jh, (0.4, 0, 0.5))
write_nodes("joint_circle.csv", unique(jcurves[rim[0]]))
write_nodes("joint_plane.csv", jsurfs[postf[0]])
# Figure 10: handle = the outer cylinder's top region, lifted
jh10 = sorted({v for t in outer for v in jsurfs[t]} & set(np.where(jpts[:, 2] > 3.3)[0]))
write_handles("joint10_H.csv", jh10, lambda v: (0.3, 0, 0.4 + 0.3 * (jpts[v, 1] - 1.5) / 1.5))

# ---- detection (Figure 10) ----
p = subprocess.run([cad, "detect", "joint.vtk", "-o", "joint_prims.csv", "--faces-out",
                    "joint_prims.vtu", "--seed", "1"], capture_output=True, text=True)
if p.returncode:
    sys.exit("detect: " + p.stderr)
print(p.stdout, end="")
prims = list(csv.DictReader(open("joint_prims.csv")))
jm = meshio.read("joint_prims.vtu")
assert len(jm.points) == len(jpts) and np.allclose(jm.points, jpts), "detect keeps the nodes"
prim_of_cell = np.concatenate([np.asarray(c).ravel() for c in jm.cell_data["primitive"]]).astype(int)
tri_of = np.concatenate([c.data for c in jm.cells])
fixed = set(np.where(jpts[:, 2] < 0.5 + 1e-9)[0])
auto = []
for pr in prims:
    i = int(pr["id"])
    nodes = set(np.unique(tri_of[prim_of_cell == i]).tolist())
    # the handle's and the fixed bottom's primitives are driven already: no constraint on them
    if len(nodes & set(jh10)) > len(nodes) // 4 or nodes <= fixed:
        continue
    t = pr["type"]
    if t not in ("plane", "cylinder"):
        continue
    auto.append((t, "primitive=%d" % i, len(nodes)))

# ---- the deformations ----
runs = [
    ("fandisk_free", "fandisk.vtk", "fandisk", []),
    ("fandisk_lines", "fandisk.vtk", "fandisk",
     [("line", "fandisk_line%d.csv" % k) for k in range(3)]),
    ("fandisk_lines_plane", "fandisk.vtk", "fandisk",
     [("line", "fandisk_line%d.csv" % k) for k in range(3)] + [("plane", "fandisk_plane.csv")]),
    ("joint_free", "joint.vtk", "joint", []),
    ("joint_circle", "joint.vtk", "joint", [("circle", "joint_circle.csv")]),
    ("joint_circle_plane", "joint.vtk", "joint",
     [("circle", "joint_circle.csv"), ("plane", "joint_plane.csv")]),
    ("joint10_free", "joint_prims.vtu", "joint10", []),
    ("joint10_auto", "joint_prims.vtu", "joint10", [(t, s) for t, s, _ in auto]),
]
# stiffer constraints: gamma_c = 100, Anderson acceleration (m = 5); at gamma_c = 1000 the
# joint's circle + plane run drifts (the circle's radius is free) and stops at the cap
HARD = ["--constraint-weight", "100", "--constraint-iterations", "50000", "--constraint-anderson", "5"]
runs += [(n + "_gc100", m, p, c) for n, m, p, c in runs if n in
         ("fandisk_lines_plane", "joint_circle_plane", "joint10_auto")]


def measure(kind, pts, d, nodes):
    """the set's residual measured here (max distance to its least-squares shape), so that the
    unconstrained runs get the same number as the constrained ones"""
    y = (pts + d)[nodes]
    c = y.mean(0)
    if kind == "plane":
        n = np.linalg.svd(y - c)[2][2]
        return np.abs((y - c) @ n).max()
    if kind == "circle":
        n = np.linalg.svd(y - c)[2][2]
        q = (y - c) - np.outer((y - c) @ n, n)
        a = np.c_[2 * q, np.ones(len(q))]
        s = np.linalg.lstsq(a, (q * q).sum(1), rcond=None)[0]
        r = np.sqrt(s[3] + s[:3] @ s[:3])
        return max(np.abs(np.linalg.norm(q - s[:3], axis=1) - r).max(), np.abs((y - c) @ n).max())
    if kind == "line":  # distance to the similar copy of the initial polyline (Umeyama)
        x0 = pts[nodes]
        a, b = x0 - x0.mean(0), y - c
        u, sv, vt = np.linalg.svd(b.T @ a)
        dd = np.diag([1, 1, np.sign(np.linalg.det(u @ vt))])
        r = u @ dd @ vt
        s = (sv * np.diag(dd)).sum() / (a * a).sum()
        return np.linalg.norm(b - s * a @ r.T, axis=1).max()
    return float("nan")


rows = []
for name, mesh, part, cons in runs:
    cmd = [cad, "deform", "--mesh", mesh, "--handles", part + "_H.csv", "--fixed",
           ("joint" if part == "joint10" else part) + "_F.csv", "--method", "mls", "--stretch",
           "0", "--bend", "1", *extra]
    for t, s in cons:
        cmd += ["--constraint", "%s:%s" % (t, s)]
    if name.endswith("_gc100"):
        cmd += HARD
    cmd += ["-o", name + ".vtu"]
    pr = subprocess.run(["/usr/bin/time", "-f", "cpu %U %S"] + cmd, capture_output=True, text=True)
    if pr.returncode:
        sys.exit("%s: %s" % (" ".join(cmd), pr.stderr))
    cpu = re.search(r"cpu (\S+) (\S+)", pr.stderr)
    o = pr.stdout
    dep = re.search(r"deform: .*, (\d+) handle nodes, (\d+) fixed, (\d+) free, (\S+) s, residual (\S+)", o)
    it = re.search(r"shape-up: (\d+) iterations, (\S+) .* update (\S+) s, iterations (\S+) s", o)
    rows.append({"run": name, "mesh": mesh, "set": "(handles)", "nodes": dep.group(1),
                 "residual_before": "", "residual_after": dep.group(5), "after_rel_diag": "",
                 "iterations": it.group(1) if it else 0, "converged": it.group(2) if it else "",
                 "update_s": it.group(3) if it else "", "iterate_s": it.group(4) if it else "",
                 "deform_s": dep.group(4), "cpu_s": "%.2f" % (float(cpu.group(1)) + float(cpu.group(2)))})
    for m in re.finditer(r"constraint (\S+?):(\S+): (\d+) nodes, residual before (\S+) after (\S+) "
                         r"\((\S+) of the diagonal", o):
        rows.append({"run": name, "mesh": mesh, "set": m.group(1) + ":" + m.group(2),
                     "nodes": m.group(3), "residual_before": m.group(4),
                     "residual_after": m.group(5), "after_rel_diag": m.group(6)})
    print(" ".join(cmd[1:]))
    print("  ->", name, "cpu", rows[-1 - len(cons)]["cpu_s"], "s")

# the same measure on every run (the unconstrained ones too)
sets = {"fandisk": [("line", "fandisk_line%d.csv" % k) for k in range(3)] + [("plane", "fandisk_plane.csv")],
        "joint": [("circle", "joint_circle.csv"), ("plane", "joint_plane.csv")]}
meas = []
for name, mesh, part, cons in runs:
    if part == "joint10":
        continue
    pts = fpts if part == "fandisk" else jpts
    diag = fdiag if part == "fandisk" else jdiag
    d = meshio.read(name + ".vtu").point_data["displacement"]
    for kind, f in sets[part]:
        nodes = [int(v) for v in open(f).read().split()[1:]]
        meas.append({"run": name, "set": "%s:%s" % (kind, f), "nodes": len(nodes),
                     "max_dist_rel_diag": "%.3g" % (measure(kind, pts, d, nodes) / diag)})
with open("fig8_10_measured.csv", "w", newline="") as f:
    w = csv.DictWriter(f, fieldnames=list(meas[0]))
    w.writeheader()
    w.writerows(meas)
with open("fig8_10.csv", "w", newline="") as f:
    keys = ["run", "mesh", "set", "nodes", "residual_before", "residual_after", "after_rel_diag",
            "iterations", "converged", "update_s", "iterate_s", "deform_s", "cpu_s"]
    w = csv.DictWriter(f, fieldnames=keys, restval="")
    w.writeheader()
    w.writerows(rows)

# ---- the picture ----
panels = [("fandisk", fpts, ftris, ["fandisk_free", "fandisk_lines", "fandisk_lines_plane",
                                     "fandisk_lines_plane_gc100"],
           ["without constraints", "feature lines", "lines + plane", "lines + plane, gc 100"]),
          ("joint", jpts, jtris, ["joint_free", "joint_circle", "joint_circle_plane",
                                  "joint_circle_plane_gc100"],
           ["without constraints", "circle", "circle + plane", "circle + plane, gc 100"]),
          ("joint10", jpts, jtris, ["joint10_free", "joint10_auto", "joint10_auto_gc100"],
           ["without constraints", "detected primitives (%d)" % len(auto), "detected, gc 100"])]
fig = plt.figure(figsize=(20, 12))
for r, (part, pts, tris, names, titles) in enumerate(panels):
    edges = np.unique(np.sort(np.vstack([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), 1), axis=0)
    # the sharp edges (dihedral angle over 25 degrees on the original): drawn as vectors,
    # the wireframe rasterised so that the SVG stays small
    e_all = np.sort(np.vstack([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), 1)
    nrm = np.cross(pts[tris[:, 1]] - pts[tris[:, 0]], pts[tris[:, 2]] - pts[tris[:, 0]])
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    order = np.lexsort((e_all[:, 1], e_all[:, 0]))
    es, tf = e_all[order], np.tile(np.arange(len(tris)), 3)[order]
    same = np.all(es[1:] == es[:-1], axis=1)
    k = np.where(same)[0]
    sharp = es[k][np.einsum("ij,ij->i", nrm[tf[k]], nrm[tf[k + 1]]) < np.cos(np.radians(25))]
    cons = {n: c for n, _, _, c in runs}
    ds = [0 * pts] + [meshio.read(n + ".vtu").point_data["displacement"] for n in names]
    allp = np.vstack([pts + d for d in ds])
    lo, hi = allp.min(0), allp.max(0)
    for c, (title, d) in enumerate(zip(["original"] + titles, ds)):
        ax = fig.add_subplot(3, 5, 5 * r + c + 1, projection="3d")
        y = pts + d
        ax.add_collection3d(Line3DCollection(y[edges], colors="0.7", linewidths=0.12,
                                             rasterized=True))
        ax.add_collection3d(Line3DCollection(y[sharp], colors="black", linewidths=0.6))
        if c > 0:
            f = meshio.read(names[c - 1] + ".vtu").point_data.get("constraint_set")
            if f is not None:
                sel = np.where(np.asarray(f).ravel() >= 0)[0]
                ax.scatter(*y[sel].T, s=0.6, color="red", depthshade=False, rasterized=True)
        ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
        ax.set_box_aspect(hi - lo)
        ax.view_init(22, -62)
        ax.set_axis_off()
        ax.set_title("%s: %s" % (part, title), fontsize=9)
fig.tight_layout()
fig.savefig("fig8_10.svg", dpi=110)
print("wrote", os.path.join(out, "fig8_10.csv"), os.path.join(out, "fig8_10.svg"))
