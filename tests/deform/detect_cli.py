#!/usr/bin/python3
"""`cadmorph detect` end to end on gmsh-built parts whose faces' surface types gmsh
(OpenCASCADE) knows: a block with a bore and a boss (7 planes, 2 cylinders) and a sphere
beside a truncated cone (1 sphere, 1 cone, 2 planes). At the default seed every CAD face is
found (its triangles' majority primitive covers >= 95 % of them, of the right type: 100 %
recall) and no primitive is false (one per CAD face, >= 95 % of its triangles on that face).
Also the CSV's parameters (bore radius and axis), the per-face field of --faces-out, a volume
mesh (its boundary faces), determinism for a seed, and the error paths.
usage: detect_cli.py CADMORPH DATA_DIR WORK_DIR"""
import csv, os, subprocess, sys
import numpy as np
import gmsh
import meshio

from cli_case import CliCase

case = CliCase("detect_cli", "detect")
cad, work, check, run = case.cad, case.work, case.check, case.run


def build(name, make, size, dim=2):
    """make() adds OCC solids; every surface becomes a physical group tagged by its entity.
    Returns {entity tag: gmsh surface type}."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    make()
    gmsh.model.occ.synchronize()
    types = {}
    for d, t in gmsh.model.getEntities(2):
        gmsh.model.addPhysicalGroup(2, [t], t)
        types[t] = gmsh.model.getType(d, t).lower()
    if dim == 3:
        gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)], 100)
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.model.mesh.generate(dim)
    gmsh.write(name + ".msh")
    gmsh.finalize()
    return types


def block():
    box = gmsh.model.occ.addBox(0, 0, 0, 2, 1, 1)
    hole = gmsh.model.occ.addCylinder(0.6, 0.5, -0.1, 0, 0, 1.2, 0.25)
    boss = gmsh.model.occ.addCylinder(1.5, 0.5, 1, 0, 0, 0.4, 0.2)
    out, _ = gmsh.model.occ.cut([(3, box)], [(3, hole)])
    gmsh.model.occ.fuse(out, [(3, boss)])


def sphere_cone():
    gmsh.model.occ.addSphere(0, 0, 0, 0.5)
    gmsh.model.occ.addCone(2, 0, -0.4, 0, 0, 0.8, 0.5, 0.15)


def compare(name, types, faces_file, csv_file):
    truth = np.concatenate([np.ravel(d) for c, d in zip(meshio.read(name + ".msh").cells,
                                                          meshio.read(name + ".msh").cell_data["gmsh:physical"])
                            if c.type == "triangle"])
    got = np.ravel(meshio.read(faces_file).cell_data["primitive"][0]).astype(int)
    check(len(got) == len(truth), "%s: %d faces vs %d triangles" % (name, len(got), len(truth)))
    prims = list(csv.DictReader(open(csv_file)))
    used = {}
    for tag, t in types.items():
        sel = got[truth == tag]
        ids, cnt = np.unique(sel, return_counts=True)
        k = ids[np.argmax(cnt)]
        share = cnt.max() / len(sel)
        ok = k >= 0 and share >= 0.95 and prims[k]["type"] == t
        check(ok, "%s: CAD face %d (%s, %d triangles): primitive %d (%s) covers %.3f" %
              (name, tag, t, len(sel), k, prims[k]["type"] if k >= 0 else "-", share))
        used.setdefault(k, []).append(tag)
    check(len(prims) == len(types), "%s: %d primitives for %d CAD faces" % (name, len(prims), len(types)))
    for i in range(len(prims)):
        sel = truth[got == i]
        tags, cnt = np.unique(sel, return_counts=True)
        check(cnt.max() >= 0.95 * len(sel) and used.get(i) == [tags[np.argmax(cnt)]],
              "%s: primitive %d (%s) is no single CAD face: %s" % (name, i, prims[i]["type"], dict(zip(tags, cnt))))
    return prims


types = build("block", block, 0.06)
rc, out, err = run("block.msh", "-o", "block.csv", "--faces-out", "block_faces.vtu")
check(rc == 0 and "primitives (7 planes, 2 cylinders, 0 spheres, 0 cones)" in out, "block: %d %s %s" % (rc, out, err))
if rc == 0:
    prims = compare("block", types, "block_faces.vtu", "block.csv")
    bore = [p for p in prims if p["type"] == "cylinder" and abs(float(p["p0"]) - 0.6) < 0.01]
    check(len(bore) == 1, "the bore in the CSV")
    if bore:
        b = bore[0]
        # barycentres of chords lie inside the circle: the radius a little under 0.25
        check(abs(float(b["p6"]) - 0.25) < 0.005, "bore radius %s" % b["p6"])
        check(abs(abs(float(b["p5"])) - 1) < 1e-6, "bore axis %s" % b["p5"])
    # the same seed, the same result; the CSV is identical
    rc2, out2, _ = run("block.msh", "-o", "block2.csv")
    check(rc2 == 0 and open("block.csv").read() == open("block2.csv").read(), "deterministic for a seed")

types2 = build("sphere_cone", sphere_cone, 0.05)
rc, out, err = run("sphere_cone.msh", "-o", "sc.csv", "--faces-out", "sc_faces.vtu")
check(rc == 0 and "(2 planes, 0 cylinders, 1 spheres, 1 cones)" in out, "sphere/cone: %d %s %s" % (rc, out, err))
if rc == 0:
    prims = compare("sphere_cone", types2, "sc_faces.vtu", "sc.csv")
    sph = [p for p in prims if p["type"] == "sphere"]
    check(sph and abs(float(sph[0]["p3"]) - 0.5) < 0.005, "sphere radius")
    # the cone (refitted by Levenberg-Marquardt): radius 0.5 -> 0.15 over 0.8, so half-angle
    # atan(0.35 / 0.8) and apex at z = -0.4 + 0.8 * 0.5 / 0.35 on the axis x = 2, y = 0
    cone = [p for p in prims if p["type"] == "cone"]
    if cone:
        c = cone[0]
        apex = np.array([float(c["p0"]), float(c["p1"]), float(c["p2"])])
        check(abs(float(c["p6"]) - np.arctan(0.35 / 0.8)) < 0.003, "cone half-angle %s" % c["p6"])
        check(np.linalg.norm(apex - [2, 0, -0.4 + 0.8 * 0.5 / 0.35]) < 0.01, "cone apex %s" % apex)
        check(float(c["rms"]) < 1e-3, "cone rms %s" % c["rms"])

# a volume mesh: its boundary faces
build("block_tet", block, 0.12, dim=3)
rc, out, err = run("block_tet.msh", "-o", "tet.csv", "--faces-out", "tet_faces.vtu")
check(rc == 0 and "(7 planes, 2 cylinders" in out, "volume mesh: %d %s %s" % (rc, out, err))

# only planes (the facets of the cylinders then come out as narrow planes too)
rc, out, err = run("block.msh", "-o", "planes.csv", "--types", "plane")
check(rc == 0 and " planes, 0 cylinders, 0 spheres, 0 cones)" in out, "--types plane: %s" % out)
# error paths
rc, out, err = run("block.msh")
check(rc == 1 and "-o is required" in err, "no -o: %d %s" % (rc, err))
rc, out, err = run("block.msh", "-o", "x.csv", "--types", "torus")
check(rc == 1 and "unknown primitive" in err, "torus: %d %s" % (rc, err))
rc, out, err = run("missing.msh", "-o", "x.csv")
check(rc == 2 and not os.path.exists("x.csv"), "missing mesh: %d %s" % (rc, err))
rc, out, err = run("--help")
check(rc == 0 and "Schnabel" in out, "help")

case.finish()
