#!/usr/bin/python3
"""`cadmorph deform --constraint TYPE:SET` end to end: a gmsh-built block with a bore (surface
mesh, physical groups), bent by lifting one end: the bore stays a cylinder and the top face a
plane far better than without; a band of a sheared cone stays a cone; SET as a physical group, a node-list file and a VTK field;
the error paths (exit 1 for usage, 2 for a set that is not there).
usage: constraints_cli.py CADMORPH DATA_DIR WORK_DIR"""
import os, re, subprocess, sys
import numpy as np
import gmsh
import meshio

from cli_case import CliCase

case = CliCase("constraints_cli", "deform")
cad, work, check, run = case.cad, case.work, case.check, case.run


# the block [0,2]x[0,1]x[0,1] with a bore of radius 0.25 along z at (1, 0.5)
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("block")
box = gmsh.model.occ.addBox(0, 0, 0, 2, 1, 1)
hole = gmsh.model.occ.addCylinder(1, 0.5, -0.1, 0, 0, 1.2, 0.25)
gmsh.model.occ.cut([(3, box)], [(3, hole)])
gmsh.model.occ.synchronize()
groups = {"bore": [], "left": [], "right": [], "top": []}
for dim, tag in gmsh.model.getEntities(2):
    t = gmsh.model.getType(dim, tag)
    c = gmsh.model.occ.getCenterOfMass(dim, tag)
    if "Cylinder" in t:
        groups["bore"].append(tag)
    elif abs(c[0]) < 1e-9:
        groups["left"].append(tag)
    elif abs(c[0] - 2) < 1e-9:
        groups["right"].append(tag)
    elif abs(c[2] - 1) < 1e-9:
        groups["top"].append(tag)
for name, tags in groups.items():
    assert tags, name
    gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
others = [t for _, t in gmsh.model.getEntities(2) if not any(t in v for v in groups.values())]
gmsh.model.addPhysicalGroup(2, others)
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.08)
gmsh.model.mesh.generate(2)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write("block.msh")
gmsh.finalize()

m = meshio.read("block.msh")
x = m.points
tri = np.vstack([c.data for c in m.cells if c.type == "triangle"])
used = np.unique(tri)
left = [v for v in used if abs(x[v, 0]) < 1e-9]
right = [v for v in used if abs(x[v, 0] - 2) < 1e-9]
bore = [v for v in used if abs(np.hypot(x[v, 0] - 1, x[v, 1] - 0.5) - 0.25) < 1e-6]
top = [v for v in used if abs(x[v, 2] - 1) < 1e-9]
# the right end turned by 25 degrees about its mid line (y axis through (2, ., 0.5)) and
# lifted: a bend, whose field is not affine
a = np.radians(25)
with open("H.csv", "w") as f:
    f.write("node,dx,dy,dz\n")
    for v in right:
        px, pz = x[v, 0] - 2, x[v, 2] - 0.5
        dx = np.cos(a) * px + np.sin(a) * pz - px
        dz = -np.sin(a) * px + np.cos(a) * pz - pz + 0.3
        f.write("%d,%.17g,0,%.17g\n" % (v, dx, dz))
with open("F.csv", "w") as f:
    f.write("node\n" + "".join("%d\n" % v for v in left))
with open("bore_nodes.csv", "w") as f:
    f.write("node\n" + "".join("%d\n" % v for v in bore))

base = ["--mesh", "block.msh", "--handles", "H.csv", "--fixed", "F.csv", "--samples", "300",
        "--stretch", "0"]


def cylinder_error(d, nodes):
    """largest distance from the least-squares cylinder of the moved nodes (scipy fit)"""
    from scipy.optimize import least_squares
    y = x[nodes] + d[nodes]
    c = y.mean(0)

    def res(p):
        w = np.array([np.sin(p[0]) * np.cos(p[1]), np.sin(p[0]) * np.sin(p[1]), np.cos(p[0])])
        q = y - (c + p[2:5])
        r = q - np.outer(q @ w, w)
        return np.linalg.norm(r, axis=1) - p[5]

    best = None
    for th in np.linspace(0, 0.6, 3):
        for ph in np.linspace(0, np.pi, 4, endpoint=False):
            s = least_squares(res, [th, ph, 0, 0, 0, 0.25])
            if best is None or s.cost < best.cost:
                best = s
    return np.abs(best.fun).max()


def plane_error(d, nodes):
    y = x[nodes] + d[nodes]
    y = y - y.mean(0)
    n = np.linalg.svd(y)[2][-1]
    return np.abs(y @ n).max()


rc, out, err = run(*base, "-o", "free.vtu")
check(rc == 0, "unconstrained: exit %d %s" % (rc, err))
d0 = meshio.read("free.vtu").point_data["displacement"] if rc == 0 else None

rc, out, err = run(*base, "--constraint", "cylinder:bore", "--constraint", "plane:top",
                   "--constraint-weight", "100", "--constraint-anderson", "5", "-o", "con.vtu")
check(rc == 0, "constrained: exit %d %s" % (rc, err))
if rc == 0 and d0 is not None:
    d1 = meshio.read("con.vtu").point_data["displacement"]
    lines = dict(re.findall(r"constraint (\S+): .* after (\S+) ", out))
    check(set(lines) == {"cylinder:bore", "plane:top"}, "report lines: " + out)
    check(re.search(r"shape-up: \d+ iterations, converged", out), "converged: " + out)
    e0, e1 = cylinder_error(d0, bore), cylinder_error(d1, bore)
    p0, p1 = plane_error(d0, top), plane_error(d1, top)
    check(e1 < 0.2 * e0, "bore: cylinder error %g -> %g" % (e0, e1))
    check(p1 < 0.2 * p0, "top: plane error %g -> %g" % (p0, p1))
    # the report's residual is the distance to our own fit: the same order as scipy's
    check(abs(float(lines["cylinder:bore"]) - e1) < 0.5 * e1 + 1e-6,
          "bore residual %s vs scipy %g" % (lines.get("cylinder:bore"), e1))
    # the handle still goes up
    check(abs(np.median(d1[right, 2]) - 0.3) < 0.05, "handle %g" % np.median(d1[right, 2]))

# the same set as a node-list file, and the dense formulation: the same bore, converging
rc, out, err = run(*base, "--constraint", "cylinder:bore_nodes.csv", "--dense-constraints",
                   "--constraint-weight", "100", "--constraint-anderson", "5", "-o", "con_file.vtu")
check(rc == 0 and "mean-centred" in out, "node file, dense: exit %d %s %s" % (rc, out, err))
if rc == 0 and d0 is not None:
    d2 = meshio.read("con_file.vtu").point_data["displacement"]
    check(cylinder_error(d2, bore) < 0.2 * cylinder_error(d0, bore), "node file: bore kept")

# a VTK node field as the set: 'flat' = 1 on the top face, written into the mesh
mv = meshio.Mesh(x, [("triangle", tri)], point_data={"flat": np.isin(np.arange(len(x)), top).astype(float)})
meshio.write("block_field.vtu", mv)
rc, out, err = run("--mesh", "block_field.vtu", *base[2:], "--constraint", "plane:flat=1",
                   "--constraint", "rigid:bore_nodes.csv", "-o", "con_field.vtu")
check(rc == 0 and "plane:flat=1: %d nodes" % len(top) in out, "field set: %d %s %s" % (rc, out, err))

# a cone: a quad mesh of a truncated cone (half-angle 0.35, distance 1..2.5 from the apex along
# the generator), the bottom rows fixed, the top rows moved sideways; the middle band as a
# cone set: scipy's least-squares cone of the band fits far better with the constraint
A, na, nt = 0.35, 48, 30
ang, tt = np.meshgrid(np.linspace(0, 2 * np.pi, na, endpoint=False), np.linspace(1, 2.5, nt + 1))
cx = np.c_[(tt * np.sin(A) * np.cos(ang)).ravel(), (tt * np.sin(A) * np.sin(ang)).ravel(),
           (tt * np.cos(A)).ravel()]
quads = np.array([[j * na + i, j * na + (i + 1) % na, (j + 1) * na + (i + 1) % na, (j + 1) * na + i]
                  for j in range(nt) for i in range(na)])
meshio.write("cone.vtk", meshio.Mesh(cx, [("quad", quads)]), binary=False)
h = cx[:, 2]
with open("cone_F.csv", "w") as f:
    f.write("node\n" + "".join("%d\n" % v for v in np.where(h < 1.1 * np.cos(A))[0]))
with open("cone_H.csv", "w") as f:
    f.write("node,dx,dy,dz\n" + "".join("%d,0.4,0,0.1\n" % v for v in np.where(h > 2.4 * np.cos(A))[0]))
band = np.where((h > 1.5 * np.cos(A)) & (h < 2.0 * np.cos(A)))[0]
with open("cone_band.csv", "w") as f:
    f.write("node\n" + "".join("%d\n" % v for v in band))


def cone_error(d):
    from scipy.optimize import least_squares
    y = cx[band] + d[band]

    def res(p):
        w = np.array([np.sin(p[0]) * np.cos(p[1]), np.sin(p[0]) * np.sin(p[1]), np.cos(p[0])])
        q = y - p[2:5]
        hh = q @ w
        r = np.linalg.norm(q - np.outer(hh, w), axis=1)
        return r * np.cos(p[5]) - hh * np.sin(p[5])

    best = None
    for th in (0.0, 0.2):
        for ph in np.linspace(0, np.pi, 3, endpoint=False):
            s = least_squares(res, [th, ph, 0, 0, 0, A], xtol=1e-14, ftol=1e-14)
            if best is None or s.cost < best.cost:
                best = s
    return np.abs(best.fun).max()


cbase = ["--mesh", "cone.vtk", "--handles", "cone_H.csv", "--fixed", "cone_F.csv", "--method", "mls",
         "--stretch", "0"]
rc, out, err = run(*cbase, "-o", "cone_free.vtu")
check(rc == 0, "cone unconstrained: %d %s" % (rc, err))
rc2, out2, err2 = run(*cbase, "--constraint", "cone:cone_band.csv", "--constraint-weight", "100",
                      "--constraint-anderson", "5", "-o", "cone_con.vtu")
check(rc2 == 0 and "constraint cone:cone_band.csv: %d nodes" % len(band) in out2,
      "cone constrained: %d %s %s" % (rc2, out2, err2))
if rc == 0 and rc2 == 0:
    c0 = cone_error(meshio.read("cone_free.vtu").point_data["displacement"])
    c1 = cone_error(meshio.read("cone_con.vtu").point_data["displacement"])
    check(c0 > 1e-3 and c1 < 0.2 * c0, "cone band: scipy cone error %g -> %g" % (c0, c1))
    m = re.search(r"constraint cone:\S+: \d+ nodes, residual before (\S+) after (\S+) ", out2)
    check(m and abs(float(m.group(2)) - c1) < 0.5 * c1 + 1e-6,
          "cone residual %s vs scipy %g" % (m.group(2) if m else None, c1))

# error paths
rc, out, err = run(*base, "--constraint", "sphere:bore", "-o", "x.vtu")
check(rc == 1 and "unknown type 'sphere'" in err, "unknown type: %d %s" % (rc, err))
rc, out, err = run(*base, "--constraint", "plane", "-o", "x.vtu")
check(rc == 1 and "TYPE:SET" in err, "no set: %d %s" % (rc, err))
rc, out, err = run(*base, "--constraint", "plane:nothing", "-o", "x.vtu")
check(rc == 2 and "no such file, physical group or field" in err and "bore" in err,
      "unknown set: %d %s" % (rc, err))
rc, out, err = run(*base, "--method", "rbf", "--constraint", "plane:top", "-o", "x.vtu")
check(rc == 1 and "--method mls" in err, "rbf: %d %s" % (rc, err))
check(not os.path.exists("x.vtu"), "no output after a failure")
rc, out, err = run(*base, "--constraint", "plane:top", "--constraint-anderson", "0", "-o", "x.vtu")
check(rc == 1 and "1..64" in err, "anderson 0: %d %s" % (rc, err))
rc, out, err = run("--help")
check(rc == 0 and "--constraint TYPE:SET" in out, "help")

case.finish()
