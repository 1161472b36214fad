#!/usr/bin/python3
"""`cadmorph ffd` end to end (ctest, label cli;deform): usage: ffd_cli.py CADMORPH DATA WORK.

1. PyGeM's numbers through the CLI: the points of tests/data/deform/bern444_rot.csv as a
   vertex-cell .vtu, deformed by PyGeM's own .prm, match PyGeM's stored output to 1e-13.
2. PyGeM #272 through the CLI: a .prm box equal to the mesh's bounding box and every weight
   t/L: every node (also those on the box faces) moves by t.
3. --displacements (physical units) and --basis bspline.
4. Error paths: missing .prm (exit 2, nothing written there), unknown basis (exit 1),
   a B-spline lattice with 3 points per axis (exit 2), a bad CSV row (exit 2 with file:line).
5. `cadmorph warp --method dmffd --lattice 5 --clamp 1e-2`: a valid mesh, the residual in the
   debug line, constrained nodes at their motion; the default clamping gives a worse mesh;
   --lattice 3 is a usage error.
"""
import os
import subprocess
import sys

import meshio
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "helpers"))
from pygem_prm import write_prm  # noqa: E402

CM, DATA, WORK = sys.argv[1], sys.argv[2], os.path.join(sys.argv[3], "ffd_cli")
os.makedirs(WORK, exist_ok=True)
failures = 0


def check(cond, what):
    global failures
    print(("ok   " if cond else "FAIL ") + what)
    failures += 0 if cond else 1


def run(*args):
    p = subprocess.run([CM, "ffd", *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


# 1. PyGeM's numbers
rows = np.loadtxt(os.path.join(DATA, "deform", "bern444_rot.csv"), delimiter=",", skiprows=1)
pts = meshio.Mesh(rows[:, :3], [("vertex", np.arange(len(rows)).reshape(-1, 1))])
src = os.path.join(WORK, "pygem_points.vtu")
meshio.write(src, pts)
out = os.path.join(WORK, "pygem_points_ffd.vtu")
rc, so, se = run("--mesh", src, "--lattice", os.path.join(DATA, "deform", "bern444_rot.prm"),
                 "-o", out)
check(rc == 0, "pygem case runs (%s)" % se.strip())
if rc == 0:
    got = meshio.read(out).points
    err = np.abs(got - rows[:, 3:]).max()
    check(err <= 1e-13, "CLI matches PyGeM to %.3g" % err)
    check("150 inside" in so, "counts: " + so.splitlines()[0])

# 2. #272: box = bounding box, all weights t / L
mesh_path = os.path.join(DATA, "msh", "box_hole_41.msh")
m = meshio.read(mesh_path)
lo, hi = m.points.min(axis=0), m.points.max(axis=0)
L = hi - lo
t = np.array([0.25, -0.5, 0.125])
n = [3, 2, 4]
mu = [np.full(n, t[a] / L[a]) for a in range(3)]
prm = os.path.join(WORK, "bbox.prm")
write_prm(prm, n, list(lo), list(L), [0.0, 0.0, 0.0], mu)
out = os.path.join(WORK, "bbox_ffd.vtu")
rc, so, se = run("--mesh", mesh_path, "--lattice", prm, "-o", out)
check(rc == 0, "bbox case runs (%s)" % se.strip())
if rc == 0:
    d = meshio.read(out).points - m.points
    on_face = np.any((np.abs(m.points - lo) < 1e-12) | (np.abs(m.points - hi) < 1e-12), axis=1)
    err = np.abs(d - t).max()
    check(err <= 1e-12, "every node moves by t (%d on the faces), max error %.3g"
          % (on_face.sum(), err))
    check(so.splitlines()[-1].startswith("min_scaled_jacobian="), "summary line last")

# 3. --displacements with physical units, B-spline basis on a 4^3 lattice
n4 = [4, 4, 4]
write_prm(prm, n4, list(lo), list(L), [0.0, 0.0, 0.0], [np.zeros(n4)] * 3)
csv = os.path.join(WORK, "ctrl.csv")
with open(csv, "w") as f:
    f.write("i,j,k,dx,dy,dz\n")
    for i in range(4):
        for j in range(4):
            for k in range(4):
                f.write("%d,%d,%d,%r,%r,%r\n" % (i, j, k, *t))
out = os.path.join(WORK, "csv_ffd.vtu")
rc, so, se = run("--mesh", mesh_path, "--lattice", prm, "--displacements", csv,
                 "--basis", "bspline", "-o", out)
check(rc == 0, "csv + bspline runs (%s)" % se.strip())
if rc == 0:
    err = np.abs(meshio.read(out).points - m.points - t).max()
    check(err <= 1e-12, "csv displacements are physical: max error %.3g" % err)

# 4. error paths
missing = os.path.join(WORK, "missing.prm")
if os.path.exists(missing):
    os.remove(missing)
rc, so, se = run("--mesh", mesh_path, "--lattice", missing, "-o", out)
check(rc == 2 and not os.path.exists(missing), "missing .prm: exit %d, %s" % (rc, se.strip()))
rc, so, se = run("--mesh", mesh_path, "--lattice", prm, "--basis", "nurbs", "-o", out)
check(rc == 1, "unknown basis: exit %d" % rc)
write_prm(prm, [3, 3, 3], list(lo), list(L), [0.0, 0.0, 0.0], [np.zeros([3, 3, 3])] * 3)
rc, so, se = run("--mesh", mesh_path, "--lattice", prm, "--basis", "bspline", "-o", out)
check(rc == 2 and "at least 4" in se, "bspline n=3: exit %d, %s" % (rc, se.strip()))
with open(csv, "a") as f:
    f.write("1,1,x,0,0,0\n")
write_prm(prm, n4, list(lo), list(L), [0.0, 0.0, 0.0], [np.zeros(n4)] * 3)
rc, so, se = run("--mesh", mesh_path, "--lattice", prm, "--displacements", csv, "-o", out)
check(rc == 2 and "ctrl.csv:66:" in se and len(se.strip().splitlines()) == 1,
      "bad csv row: exit %d, %s" % (rc, se.strip()))

# 5. the DM-FFD interior warp through `cadmorph warp --method dmffd --lattice N`
dcsv = os.path.join(WORK, "warp_disp.csv")
face = np.where(np.abs(m.points[:, 0] - hi[0]) < 1e-9)[0]
with open(dcsv, "w") as f:
    f.write("node,dx,dy,dz\n")
    for v in face:
        f.write("%d,%r,0,0\n" % (v, 0.02 * L[0]))
out = os.path.join(WORK, "warp_dmffd.vtu")
def min_sj(text):
    last = text.strip().splitlines()[-1]
    return float(last.split()[0].split("=")[1]), int(last.split()[2].split("=")[1])


# clamping 1e-2 keeps the coarse lattice's least-squares map tame (no inverted cell here);
# the default 1e-10 keeps tiny singular values and does worse: the paper's Fig. 8 in a mesh
p = subprocess.run([CM, "warp", "--mesh", mesh_path, "--displacements", dcsv, "-o", out,
                    "--method", "dmffd", "--lattice", "5", "--clamp", "1e-2", "--verbose"],
                   capture_output=True, text=True)
check(p.returncode == 0 and min_sj(p.stdout)[1] == 0,
      "warp --method dmffd --clamp 1e-2: exit %d, %s" % (p.returncode,
                                                        p.stdout.strip().splitlines()[-1:]))
check("residual at the constrained nodes" in p.stderr, "the residual is reported (--verbose)")
if p.returncode == 0:
    got = meshio.read(out).points
    err = np.abs(got[face, 0] - m.points[face, 0] - 0.02 * L[0]).max()
    check(err <= 1e-12, "constrained nodes keep their prescribed motion (%.3g)" % err)
    q = subprocess.run([CM, "warp", "--mesh", mesh_path, "--displacements", dcsv, "-o", out,
                        "--method", "dmffd", "--lattice", "5"], capture_output=True, text=True)
    check(q.returncode == 0 and min_sj(q.stdout)[0] < min_sj(p.stdout)[0],
          "default clamping 1e-10: min SJ %s < %s" % (min_sj(q.stdout)[0], min_sj(p.stdout)[0]))
p = subprocess.run([CM, "warp", "--mesh", mesh_path, "--displacements", dcsv, "-o", out,
                    "--method", "dmffd", "--lattice", "3"], capture_output=True, text=True)
check(p.returncode == 1, "--lattice 3: exit %d" % p.returncode)
sys.exit(1 if failures else 0)
