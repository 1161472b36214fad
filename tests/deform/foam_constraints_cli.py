#!/usr/bin/python3
"""`cadmorph deform --constraint TYPE:SET` with SET an OpenFOAM patch or cellZone: a blockMesh
case (three 4 x 4 x 4 hex blocks along x, the middle one the cellZone 'core'; patches inlet
x = 0, outlet x = 3, top z = 1, defaultFaces), inlet fixed, outlet turned and lifted (MLS):
rigid:core takes the nodes of the zone's cells (125), plane:top the nodes of the patch's faces
(65); with the constraints the core keeps its distances and the top stays planar far better
than without; an unknown name lists the patches and zones. Exit 77 without blockMesh.
usage: foam_constraints_cli.py CADMORPH WORK_DIR"""
import os, re, shutil, subprocess, sys
import numpy as np
import meshio

cad, work = sys.argv[1], os.path.join(sys.argv[2], "foam_constraints_cli")
if shutil.which("blockMesh") is None:
    print("SKIP: OpenFOAM's blockMesh (Debian package openfoam) is not installed")
    sys.exit(77)
shutil.rmtree(work, ignore_errors=True)
case = os.path.join(work, "case")
os.makedirs(os.path.join(case, "system"))
os.makedirs(os.path.join(case, "constant"))
os.chdir(work)
fails = 0


def check(cond, what):
    global fails
    if not cond:
        fails += 1
        print("FAILED:", what)


H = "FoamFile { version 2.0; format ascii; class dictionary; object %s; }\n"
files = {
    "controlDict": "application blockMesh; startFrom startTime; startTime 0; stopAt endTime; "
                   "endTime 1;\ndeltaT 1; writeControl timeStep; writeInterval 1; writeFormat ascii; "
                   "writePrecision 12;\nwriteCompression off; timeFormat general; timePrecision 6;\n",
    "fvSchemes": "ddtSchemes { default steadyState; } gradSchemes { default Gauss linear; }\n"
                 "divSchemes { default none; } laplacianSchemes { default Gauss linear corrected; }\n"
                 "interpolationSchemes { default linear; } snGradSchemes { default corrected; }\n",
    "fvSolution": ""}
for name, text in files.items():
    with open(os.path.join(case, "system", name), "w") as f:
        f.write(H % name + text)


def v(i, j, k):
    return k * 8 + j * 4 + i


def hexa(i):
    return "(%s)" % " ".join(str(x) for x in (v(i, 0, 0), v(i + 1, 0, 0), v(i + 1, 1, 0), v(i, 1, 0),
                                              v(i, 0, 1), v(i + 1, 0, 1), v(i + 1, 1, 1), v(i, 1, 1)))


verts = " ".join("(%d %d %d)" % (i, j, k) for k in range(2) for j in range(2) for i in range(4))
blocks = ("hex %s (4 4 4) simpleGrading (1 1 1)\nhex %s core (4 4 4) simpleGrading (1 1 1)\n"
          "hex %s (4 4 4) simpleGrading (1 1 1)" % (hexa(0), hexa(1), hexa(2)))
top = " ".join("(%d %d %d %d)" % (v(i, 0, 1), v(i + 1, 0, 1), v(i + 1, 1, 1), v(i, 1, 1)) for i in range(3))
with open(os.path.join(case, "system", "blockMeshDict"), "w") as f:
    f.write(H % "blockMeshDict" + """scale 1;
vertices (%s);
blocks (%s);
boundary (
  inlet { type patch; faces ((%d %d %d %d)); }
  outlet { type patch; faces ((%d %d %d %d)); }
  top { type wall; faces (%s); }
);
""" % (verts, blocks, v(0, 0, 0), v(0, 0, 1), v(0, 1, 1), v(0, 1, 0), v(3, 0, 0), v(3, 1, 0),
       v(3, 1, 1), v(3, 0, 1), top))
env = dict(os.environ)
env.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")
p = subprocess.run(["blockMesh", "-case", case], env=env, capture_output=True, text=True)
if p.returncode != 0:
    sys.exit("blockMesh failed: " + p.stdout[-1000:] + p.stderr[-1000:])

# the points in file order (the mesh's node order): ASCII vectorField
text = open(os.path.join(case, "constant", "polyMesh", "points")).read()
body = text[text.index("}", text.index("FoamFile")) + 1:]  # after the header dictionary
x = np.array([[float(a) for a in m.groups()] for m in
              re.finditer(r"\(([-+0-9.eE]+) ([-+0-9.eE]+) ([-+0-9.eE]+)\)", body)])
check(len(x) == 13 * 5 * 5, "%d points" % len(x))
inlet = np.where(abs(x[:, 0]) < 1e-9)[0]
outlet = np.where(abs(x[:, 0] - 3) < 1e-9)[0]
core = np.where((x[:, 0] > 1 - 1e-9) & (x[:, 0] < 2 + 1e-9))[0]
topn = np.where(abs(x[:, 2] - 1) < 1e-9)[0]
a = np.radians(20)
with open("H.csv", "w") as f:
    f.write("node,dx,dy,dz\n")
    for i in outlet:
        px, pz = x[i, 0] - 3, x[i, 2] - 0.5
        f.write("%d,%.17g,0,%.17g\n" % (i, np.cos(a) * px + np.sin(a) * pz - px,
                                          -np.sin(a) * px + np.cos(a) * pz - pz + 0.4))
with open("F.csv", "w") as f:
    f.write("node\n" + "".join("%d\n" % i for i in inlet))
base = ["deform", "--mesh", case, "--handles", "H.csv", "--fixed", "F.csv", "--method", "mls",
        "--stretch", "0"]


def run(*args):
    return subprocess.run([cad, *base, *args], capture_output=True, text=True)


def rigid_error(d):
    """largest change of a distance between core nodes"""
    y = x[core] + d[core]
    d0 = np.linalg.norm(x[core][:, None] - x[core][None], axis=2)
    d1 = np.linalg.norm(y[:, None] - y[None], axis=2)
    return np.abs(d1 - d0).max()


def plane_error(d):
    y = x[topn] + d[topn]
    y = y - y.mean(0)
    return np.abs(y @ np.linalg.svd(y)[2][-1]).max()


r0 = run("-o", "free.vtu")
check(r0.returncode == 0, "unconstrained: %d %s" % (r0.returncode, r0.stderr))
r1 = run("--constraint", "rigid:core", "--constraint", "plane:top", "--constraint-weight", "100",
         "--constraint-anderson", "5", "-o", "con.vtu")
check(r1.returncode == 0, "constrained: %d %s" % (r1.returncode, r1.stderr))
check("constraint rigid:core: %d nodes" % len(core) in r1.stdout and len(core) == 125,
      "the cellZone's nodes: " + r1.stdout)
check("constraint plane:top: %d nodes" % len(topn) in r1.stdout and len(topn) == 65,
      "the patch's nodes: " + r1.stdout)
if r0.returncode == 0 and r1.returncode == 0:
    d0 = meshio.read("free.vtu").point_data["displacement"]
    d1 = meshio.read("con.vtu").point_data["displacement"]
    e0, e1 = rigid_error(d0), rigid_error(d1)
    p0, p1 = plane_error(d0), plane_error(d1)
    print("core: distance change %.3g -> %.3g; top: plane error %.3g -> %.3g" % (e0, e1, p0, p1))
    check(e0 > 1e-2 and e1 < 0.2 * e0, "core rigid: %g -> %g" % (e0, e1))
    check(p0 > 1e-3 and p1 < 0.2 * p0, "top planar: %g -> %g" % (p0, p1))
# a name that is neither: the message lists the case's patches and zones
r2 = run("--constraint", "plane:nothing", "-o", "x.vtu")
check(r2.returncode == 2 and all(n in r2.stderr for n in ("inlet", "outlet", "top", "core")),
      "unknown set: %d %s" % (r2.returncode, r2.stderr))
check(not os.path.exists("x.vtu"), "no output after a failure")
print("%d passed, %d failed" % (1 if fails == 0 else 0, fails))
sys.exit(1 if fails else 0)
