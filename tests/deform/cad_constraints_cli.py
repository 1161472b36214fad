#!/usr/bin/python3
"""`cadmorph deform --constraints-from-cad G.step` on a tet mesh of a gmsh-built plate with a
bolt hole, stretched by 20 % along x: the CAD-derived cylinder set is exactly the bore's nodes
(every node on the bore face, its two circles and its seam); with --constraint-snap the hole
stays a cylinder to 1e-6 x the diagonal (unconstrained it becomes an ellipse), no cell
inverts; the filter by type and by id; the error paths.
usage: cad_constraints_cli.py CADMORPH DATA_DIR WORK_DIR"""
import os, re, subprocess, sys
import numpy as np
import gmsh
import meshio
from scipy.optimize import least_squares

from cli_case import CliCase

case = CliCase("cad_constraints_cli", "deform")
cad, work, check, run = case.cad, case.work, case.check, case.run


gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
box = gmsh.model.occ.addBox(0, 0, 0, 2, 1, 0.5)
hole = gmsh.model.occ.addCylinder(1, 0.5, -0.1, 0, 0, 0.7, 0.25)
gmsh.model.occ.cut([(3, box)], [(3, hole)])
gmsh.model.occ.synchronize()
gmsh.write("part.step")
gmsh.model.addPhysicalGroup(3, [1], 1)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.08)
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write("part.msh")
gmsh.finalize()

x = meshio.read("part.msh").points
diag = np.linalg.norm(x.max(0) - x.min(0))
left = np.where(abs(x[:, 0]) < 1e-9)[0]
right = np.where(abs(x[:, 0] - 2) < 1e-9)[0]
bore = set(np.where(abs(np.hypot(x[:, 0] - 1, x[:, 1] - 0.5) - 0.25) < 1e-6)[0])
open("F.csv", "w").write("node\n" + "".join("%d\n" % v for v in left))
open("H.csv", "w").write("node,dx,dy,dz\n" + "".join("%d,0.4,0,0\n" % v for v in right))
base = ["--mesh", "part.msh", "--handles", "H.csv", "--fixed", "F.csv", "--method", "mls"]


def cylinder_error(y):
    c = y.mean(0)

    def res(p):
        w = np.array([np.sin(p[0]) * np.cos(p[1]), np.sin(p[0]) * np.sin(p[1]), np.cos(p[0])])
        q = y - (c + p[2:5])
        return np.linalg.norm(q - np.outer(q @ w, w), axis=1) - p[5]

    s = least_squares(res, [0, 0, 0, 0, 0, 0.25], xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return np.abs(s.fun).max()


def quality(out):
    m = re.search(r"min_scaled_jacobian=(\S+) .* inverted=(\d+)", out)
    return (float(m.group(1)), int(m.group(2))) if m else (0, -1)


rc, out, err = run(*base, "-o", "free.vtu")
check(rc == 0, "unconstrained: %d %s" % (rc, err))
q0 = quality(out)
nodes = sorted(bore)
if rc == 0:
    y = x + meshio.read("free.vtu").point_data["displacement"]
    e0 = cylinder_error(y[nodes])
    check(e0 > 1e-2 * diag * 0.1, "unconstrained: the hole is no cylinder (%g)" % e0)

rc, out, err = run(*base, "--constraints-from-cad", "part.step", "--cad-constraints", "cylinder",
                   "--constraint-snap", "-o", "snap.vtu")
check(rc == 0, "from cad: %d %s" % (rc, err))
if rc == 0:
    m = re.search(r"constraint cylinder:cad-face-(\d+): (\d+) nodes", out)
    check(m and int(m.group(2)) == len(bore), "the bore's set: %s (%d bore nodes)" % (out, len(bore)))
    mesh = meshio.read("snap.vtu")
    sel = set(np.where(np.ravel(mesh.point_data["constraint_set"]) == 0)[0])
    check(sel == bore, "the set is exactly the bore's nodes (%d extra, %d missing)" %
          (len(sel - bore), len(bore - sel)))
    y = x + mesh.point_data["displacement"]
    e1 = cylinder_error(y[nodes])
    check(e1 < 1e-6 * diag, "snapped hole: cylinder error %g = %g x diagonal" % (e1, e1 / diag))
    q1 = quality(out)
    check(q1[1] == 0 and q1[0] > 0.8 * q0[0], "quality %s vs unconstrained %s" % (q1, q0))
    check(abs(np.median(mesh.point_data["displacement"][right, 0]) - 0.4) < 0.01, "stretched")
    face = m.group(1) if m else "0"
    # the same face by id
    rc, out2, err = run(*base, "--constraints-from-cad", "part.step", "--cad-constraints",
                        "face:" + face, "-o", "byid.vtu")
    check(rc == 0 and re.search(r"cylinder:cad-face-%s: %d nodes" % (face, len(bore)), out2),
          "by id: %d %s %s" % (rc, out2, err))

# all types: 6 planes, the cylinder, 2 circles; without snap the residuals drop
rc, out, err = run(*base, "--constraints-from-cad", "part.step", "-o", "all.vtu")
sets = re.findall(r"constraint (\w+):cad-(face|edge)-\d+: \d+ nodes, residual before (\S+) after (\S+) ", out)
check(rc == 0 and sorted(t for t, _, _, _ in sets) == ["circle"] * 2 + ["cylinder"] + ["plane"] * 6,
      "all types: %d %s %s" % (rc, out, err))
for t, _, r0, r1 in sets:
    if t != "plane":
        check(float(r1) < 0.3 * float(r0), "%s: %s -> %s" % (t, r0, r1))

# error paths
rc, out, err = run(*base, "--constraints-from-cad", "part.step", "--cad-constraints", "torus", "-o", "x.vtu")
check(rc == 1 and "none of plane" in err, "bad filter: %d %s" % (rc, err))
rc, out, err = run(*base, "--constraints-from-cad", "part.step", "--cad-constraints", "face:99", "-o", "x.vtu")
check(rc == 2 and "face 99" in err, "face id out of range: %d %s" % (rc, err))
rc, out, err = run(*base, "--constraints-from-cad", "missing.step", "-o", "x.vtu")
check(rc == 2, "missing STEP: %d %s" % (rc, err))
check(not os.path.exists("x.vtu"), "no output after failures")

case.finish()
