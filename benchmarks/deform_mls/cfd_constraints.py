#!/usr/bin/python3
"""The MLS's handle and fixed constraints on CFD meshes (benchmarks/RESULTS.md, "MLS
constraints on CFD meshes"): a body in a channel rotated about its centre (in the x-y plane),
the outer patches (inlet, outlet, walls) fixed, `cadmorph deform` with
--approximate-constraints (the paper's weighted fit), the default (exact, the miss blended over
--blend 1.5), --blend 0 (exact, the miss in the first cell layer) and --method rbf. Prints per
run: the body's miss and the fixed nodes' motion (both relative to the largest body motion),
cadmorph's inverted cells, checkMesh's negative-volume cells and wrongly oriented faces, and
for 2-D meshes how differently the front and back planes moved (largest |d_front - d_back|
in x-y of a point pair, relative to the body motion). Cases: tests/helpers/foam_cases.py's
channel2d and symmetry3d, and "airfoil2d", channel2d's blocks stretched into a 40 x 30 domain
around a 1 x 0.2 body, graded 50:1 towards it (a small body in a large domain, as OpenFOAM's
airFoil2D). Also the no-free-node rbf run (every node of the 2-D mesh on a patch).
usage: cfd_constraints.py CADMORPH WORK_DIR [DEGREES ...]   (default 10 30)"""
import os, re, shutil, subprocess, sys, time
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests",
                                "helpers"))
import foam_cases as fc  # noqa: E402

cad, work = sys.argv[1], sys.argv[2]
degrees = [float(a) for a in sys.argv[3:]] or [10.0, 30.0]
os.makedirs(work, exist_ok=True)


def points(case):
    text = open(os.path.join(case, "constant", "polyMesh", "points")).read()
    body = text[text.index("}", text.index("FoamFile")) + 1:]
    return np.array([[float(a) for a in m.groups()] for m in
                     re.finditer(r"\(([-+0-9.eE]+) ([-+0-9.eE]+) ([-+0-9.eE]+)\)", body)])


def airfoil2d(case):
    """channel2d's 3 x 3 blocks (the middle one the body) moved to X, Y and graded."""
    fc.make_case("channel2d", case)
    p = os.path.join(case, "system", "blockMeshDict")
    s = open(p).read()
    X, Y, g = [-15, 0, 1, 25], [-15, -0.1, 0.1, 15], 0.02
    vs = ["(%g %g %g)" % (x, y, z) for z in (0, 0.1) for y in Y for x in X]
    s = re.sub(r"vertices\n\(.*?\n\);", "vertices\n(\n" + "\n".join(vs) + "\n);", s, flags=re.S)
    nx, ny, gr = [40, 20, 50], [40, 6, 40], [g, 1, 1 / g]
    blocks = []
    for j in range(3):
        for i in range(3):
            if i == 1 and j == 1:
                continue
            a = j * 4 + i
            h = (a, a + 1, a + 5, a + 4)
            blocks.append("hex (%s %s) (%d %d 1) simpleGrading (%g %g 1)" % (
                " ".join(map(str, h)), " ".join(str(v + 16) for v in h), nx[i], ny[j], gr[i], gr[j]))
    s = re.sub(r"blocks\n\(.*?\n\);", "blocks\n(\n" + "\n".join(blocks) + "\n);", s, flags=re.S)
    open(p, "w").write(s)
    shutil.rmtree(os.path.join(case, "constant", "polyMesh"), ignore_errors=True)
    fc.run_foam("blockMesh", case)
    return case


def pairs(x):
    """Front/back point pairs of a one-cell-thick mesh (same x, y)."""
    lo = np.flatnonzero(x[:, 2] == x[:, 2].min())
    hi = np.flatnonzero(x[:, 2] == x[:, 2].max())
    key = {tuple(np.round(x[i, :2], 9)): i for i in lo}
    return np.array([(key[tuple(np.round(x[j, :2], 9))], j) for j in hi
                     if tuple(np.round(x[j, :2], 9)) in key])


cases = [("channel2d", fc.make_case("channel2d", os.path.join(work, "channel2d"))),
         ("airfoil2d", airfoil2d(os.path.join(work, "airfoil2d"))),
         ("symmetry3d", fc.make_case("symmetry3d", os.path.join(work, "symmetry3d")))]
runs = [("approximate", ["--approximate-constraints"]), ("exact (default)", []),
        ("exact --blend 0", ["--blend", "0"]), ("rbf", ["--method", "rbf"])]
print("| case | rotation | run | body miss | fixed moved | inverted | neg. cells | wrong faces "
      "| front/back |")
print("|---|---|---|---|---|---|---|---|---|")
for name, case in cases:
    x = points(case)
    body = fc.patch_points(case, "body")
    outer = sorted(set().union(*[fc.patch_points(case, p) for p in ("inlet", "outlet", "walls")])
                   - set(body))
    two_d = name.endswith("2d")
    pr = pairs(x) if two_d else None
    c0 = x[body].mean(0)
    c0[2] = 0
    for deg in degrees:
        a = np.radians(deg)
        R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
        D = (x[body] - c0) @ R.T + c0 - x[body]
        big = np.linalg.norm(D, axis=1).max()
        h, f = os.path.join(work, "H.csv"), os.path.join(work, "F.csv")
        with open(h, "w") as o:
            o.write("node,dx,dy,dz\n" + "".join("%d,%r,%r,%r\n" % (i, *v) for i, v in zip(body, D)))
        with open(f, "w") as o:
            o.write("node\n" + "".join("%d\n" % i for i in outer))
        for label, extra in runs:
            out = os.path.join(work, "out")
            shutil.rmtree(out, ignore_errors=True)
            shutil.copytree(case, out, ignore=shutil.ignore_patterns("polyMesh"))
            p = subprocess.run([cad, "deform", "--mesh", case, "--handles", h, "--fixed", f,
                                "-o", out, *extra], capture_output=True, text=True)
            if p.returncode != 0:
                print("| %s | %g° | %s | failed: %s |" % (name, deg, label, p.stderr.strip()[-200:]))
                continue
            y = points(out)
            d = y - x
            inv = re.search(r"inverted=(\d+)", p.stdout).group(1)
            cm = fc.checkmesh(out)
            fb = "–"
            if two_d:
                fb = "%.3g" % (np.linalg.norm(d[pr[:, 0], :2] - d[pr[:, 1], :2], axis=1).max() / big)
            print("| %s | %g° | %s | %.3g | %.3g | %s | %d | %d | %s |" % (
                name, deg, label, np.linalg.norm(d[body] - D, axis=1).max() / big,
                np.linalg.norm(d[outer], axis=1).max() / big, inv, cm["negative_cells"],
                cm["wrong_pyramids"], fb))
# no free node: every point of the 2-D mesh lies on a patch
case = cases[1][1]
x = points(case)
with open(os.path.join(work, "H.csv"), "w") as o:
    o.write("node,dx,dy,dz\n" + "".join("%d,0,0.05,0\n" % i for i in fc.patch_points(case, "body")))
out = os.path.join(work, "out")
shutil.rmtree(out, ignore_errors=True)
shutil.copytree(case, out, ignore=shutil.ignore_patterns("polyMesh"))
t0 = time.time()
p = subprocess.run([cad, "deform", "--mesh", case, "--handles", os.path.join(work, "H.csv"),
                    "--fix-unlisted-boundary", "--method", "rbf", "-o", out], capture_output=True,
                   text=True)
print("\nno free node (airfoil2d, rbf, --fix-unlisted-boundary): exit %d, %.2f s wall\n%s"
      % (p.returncode, time.time() - t0, "\n".join(p.stdout.splitlines()[:2])))
