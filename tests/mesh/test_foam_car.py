#!/usr/bin/python3
"""The polyhedral morph test at ctest size: benchmarks/foam/make_case.py builds the
car-like body in a wind tunnel (snappyHexMesh with layers, --base 10: ~52k cells); one RBF warp
of the three roof handles (morph_table.py's handles, the tunnel and the rest of the body fixed)
and the CAD-driven morph onto the body's STEP with the roof 5% higher (`morph --off-cad fixed
--cad-tol 0.5 --keep-offset`, as cad_morph.py) are written as OpenFOAM cases; the real checkMesh
passes on both ("Mesh OK") and every value it prints equals `cadmorph quality --foam`
(foam_compare.py, shared with test_foam_crosscheck.py). The morphs must move the mesh: the
handle nodes by their lift, the roof by the CAD edit.
Exit 77 (ctest SKIP) only when OpenFOAM's tools are not installed.
usage: test_foam_car.py CADMORPH WORKDIR"""
import os
import re
import shutil
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from foam_compare import FoamCompare  # noqa: E402

CADMORPH, WORK = sys.argv[1], os.path.join(sys.argv[2], "foam_car")
if any(shutil.which(t) is None for t in ("blockMesh", "snappyHexMesh", "checkMesh")):
    print("SKIP: OpenFOAM (Debian package openfoam) is not installed")
    sys.exit(77)
ENV = dict(os.environ)
ENV.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")
BENCH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "benchmarks", "foam")
FC = FoamCompare(CADMORPH, ENV)
check = FC.check
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
case = os.path.join(WORK, "car50")

# the case: gmsh STEP/STL, blockMesh, snappyHexMesh (their time counts as OpenFOAM's)
t = time.time()
p = FC.run([sys.executable, os.path.join(BENCH, "make_case.py"), case, "--base", "10", "--level", "2"])
FC.foam_seconds += time.time() - t
if p.returncode != 0:
    print(p.stdout[-2000:], p.stderr[-2000:])
    sys.exit("make_case.py failed")
ref, _ = FC.compare("car50", case)
cells = int(ref["cells"])
check(40000 <= cells <= 70000, "car50: %d cells, not about 50k" % cells)
check(ref["mesh OK"], "car50: checkMesh does not say Mesh OK")

# the roof handles and the fixed tunnel nodes, as morph_table.py chooses them
runs = os.path.join(WORK, "runs")
p = FC.run([sys.executable, os.path.join(BENCH, "morph_table.py"), CADMORPH, case, runs, "--handles-only"])
check(p.returncode == 0, "morph_table.py --handles-only: " + p.stderr[-500:])
H = os.path.join(runs, "handles.csv")
handles = {int(l.split(",")[0]): float(l.split(",")[3]) for l in open(H).read().splitlines()[1:]}
check(len(handles) > 10, "only %d roof handle nodes" % len(handles))


def points(c):
    txt = open(os.path.join(c, "constant", "polyMesh", "points")).read()
    return [tuple(map(float, l[1:-1].split())) for l in txt[txt.find("\n(\n") + 3:].splitlines() if l.startswith("(")]


def new_case(name):
    out = os.path.join(WORK, name)
    os.makedirs(out)
    shutil.copytree(os.path.join(case, "system"), os.path.join(out, "system"))
    return out


p0 = points(case)

# 1. RBF warp of the roof handles (every other boundary node fixed)
rbf = new_case("rbf")
w = FC.run([CADMORPH, "warp", "--method", "rbf", "--mesh", case, "--displacements", H, "-o", rbf])
check(w.returncode == 0, "rbf warp: exit %d %s" % (w.returncode, w.stderr[-500:]))
r, _ = FC.compare("rbf", rbf)
check(r["mesh OK"], "rbf: checkMesh does not say Mesh OK")
p1 = points(rbf)
worst = max(abs(p1[i][2] - p0[i][2] - d) for i, d in handles.items())
check(worst < 1e-9, "rbf: handle nodes off their lift by %g" % worst)
moved = sum(1 for a, b in zip(p0, p1) if a != b)
check(moved > len(handles), "rbf: only %d nodes moved" % moved)
print("rbf: %d handles on their lift (worst %.2g), %d nodes moved" % (len(handles), worst, moved))

# 2. the CAD-driven morph: the body's STEP with the roof 5% higher
g1 = os.path.join(WORK, "body_h.step")
p = FC.run([sys.executable, os.path.join(BENCH, "make_case.py"), "x", "--height", "0.336", "--step-only", g1])
check(p.returncode == 0, "edited STEP: " + p.stderr[-500:])
cad = new_case("cad")
m = FC.run([CADMORPH, "morph", "--from", os.path.join(case, "constant", "body.step"), "--to", g1, "--mesh", case,
            "-o", cad, "--off-cad", "fixed", "--cad-tol", "0.5", "--keep-offset"])
check(m.returncode == 0, "cad morph: exit %d %s" % (m.returncode, m.stderr[-500:]))
c, _ = FC.compare("cad", cad)
check(c["mesh OK"], "cad: checkMesh does not say Mesh OK")
p2 = points(cad)
# the highest body node rises by the edit (0.016), the tunnel's top (z = 1.5) stays
roof0 = max(p0[i][2] for i in handles)
roof2 = max(p2[i][2] for i in handles)
check(abs(roof2 - roof0 - 0.016) < 0.004, "cad: roof %.4f -> %.4f, expected +0.016" % (roof0, roof2))
check(max(q[2] for q in p2) == max(q[2] for q in p0), "cad: the tunnel top moved")
print("cad: roof %.4f -> %.4f" % (roof0, roof2))

print("OpenFOAM (make_case.py with snappyHexMesh, checkMesh) ran %.1f s in total" % FC.foam_seconds)
check(FC.foam_seconds < 55, "OpenFOAM runs took %.1f s (budget: 60 s for all foam tests)" % FC.foam_seconds)
if FC.failures:
    print("%d failures" % len(FC.failures))
    sys.exit(1)
print("car50 polyhedral morph test passed")
