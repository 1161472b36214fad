#!/usr/bin/python3
"""`cadmorph deform` on CFD meshes (blockMesh cases of tests/helpers/foam_cases.py): the MLS
(deform's default method) gives handle and fixed nodes exactly their prescribed motion by
default (--approximate-constraints: the field's values, which miss them; --exact-constraints:
accepted, the default), checkMesh finds no negative volume and no wrongly oriented face;
every node a handle or fixed (a 2-D mesh with --fix-unlisted-boundary) builds no RBF and
says so; --constraint plane:frontAndBack splits the patch into its two planes, and with
--constraint-snap the wedge's planes hold to the input's own planarity. The 2-D and wedge
alignment of the planes' points is not judged here (sliding patches do that).
Exit 77 without OpenFOAM.
usage: cfd_deform_cli.py CADMORPH WORK_DIR"""
import os, re, shutil, subprocess, sys
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "helpers"))
import foam_cases as fc  # noqa: E402

cad, work = sys.argv[1], os.path.join(sys.argv[2], "cfd_deform_cli")
if not fc.foam_available():
    print("SKIP: OpenFOAM's blockMesh/checkMesh are not installed")
    sys.exit(77)
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
os.chdir(work)
fails = 0


def check(cond, what):
    global fails
    if not cond:
        fails += 1
        print("FAILED:", what)


def points(case):
    """The points of case's ASCII polyMesh, in file order (the mesh's node order)."""
    text = open(os.path.join(case, "constant", "polyMesh", "points")).read()
    body = text[text.index("}", text.index("FoamFile")) + 1:]
    return np.array([[float(a) for a in m.groups()] for m in
                     re.finditer(r"\(([-+0-9.eE]+) ([-+0-9.eE]+) ([-+0-9.eE]+)\)", body)])


def off_plane(p):
    """The largest distance of points p from their least-squares plane."""
    c = p.mean(0)
    return np.abs((p - c) @ np.linalg.svd(p - c)[2][2]).max()


def write_inputs(x, handles, D, fixed, tag):
    with open(tag + "_H.csv", "w") as f:
        f.write("node,dx,dy,dz\n" + "".join("%d,%r,%r,%r\n" % (i, *d) for i, d in zip(handles, D)))
    with open(tag + "_F.csv", "w") as f:
        f.write("node\n" + "".join("%d\n" % i for i in fixed))


def deform(case, tag, *args):
    """Runs deform into a copy of case (its polyMesh replaced); returns (process, new points)."""
    out = os.path.join(work, tag)
    shutil.rmtree(out, ignore_errors=True)
    shutil.copytree(case, out, ignore=shutil.ignore_patterns("polyMesh"))
    p = subprocess.run([cad, "deform", "--mesh", case, "-o", out, *args], capture_output=True,
                       text=True)
    check(p.returncode == 0, "%s: exit %d %s" % (tag, p.returncode, p.stderr[-800:]))
    return p, (points(out) if p.returncode == 0 else None), out


def solver_ready(out, tag):
    """checkMesh: no negative volume, no wrongly oriented face, no failed check but the 2-D /
    wedge alignment (the sliding patches' matter)."""
    cm = fc.checkmesh(out)
    errs = [e for e in cm["errors"] if "not aligned" not in e]
    check(not cm["negative_volume"] and cm["wrong_pyramids"] == 0 and not errs,
          "%s: checkMesh %s" % (tag, cm["errors"]))


# ---- the 2-D channel: the body translated, the outer patches fixed, MLS by default ----
case = fc.make_case("channel2d", os.path.join(work, "channel2d"))
x = points(case)
body = fc.patch_points(case, "body")
outer = sorted(set().union(*[fc.patch_points(case, p) for p in ("inlet", "outlet", "walls")]))
move = np.array([0.05, 0.1, 0.0])
write_inputs(x, body, np.tile(move, (len(body), 1)), outer, "ch")
size = np.abs(x).max()
p, y, out = deform(case, "ch_exact", "--handles", "ch_H.csv", "--fixed", "ch_F.csv")
if y is not None:
    d = y - x
    check(np.abs(d[body] - move).max() <= 1e-12 * size, "ch: handles exact by default: miss %g"
          % np.abs(d[body] - move).max())
    check(np.array_equal(y[outer], x[outer]), "ch: fixed nodes stay, bit for bit: moved %g"
          % np.abs(d[outer]).max())
    free = np.setdiff1d(np.arange(len(x)), np.union1d(body, outer))
    check(np.abs(d[free]).max() > 0.05, "ch: free nodes follow")
    res = float(re.search(r"residual (\S+)", p.stdout).group(1))
    check(res > 1e-5, "ch: the field's own miss is reported: residual %g" % res)
    solver_ready(out, "ch exact")
# the old flag: the default, same result
p2, y2, _ = deform(case, "ch_exactflag", "--handles", "ch_H.csv", "--fixed", "ch_F.csv",
                   "--exact-constraints")
check(y is not None and y2 is not None and np.array_equal(y, y2), "ch: --exact-constraints is the default")
# the paper's weighted fit: handles and fixed nodes get the field's values, which miss
p3, y3, _ = deform(case, "ch_approx", "--handles", "ch_H.csv", "--fixed", "ch_F.csv",
                   "--approximate-constraints")
if y3 is not None:
    d = y3 - x
    mb, mf = np.linalg.norm(d[body] - move, axis=1).max(), np.linalg.norm(d[outer], axis=1).max()
    check(mb > 1e-4 * np.linalg.norm(move) and mf > 1e-4 * np.linalg.norm(move),
          "ch approximate: misses the body by %g, moves fixed nodes by %g" % (mb, mf))
r = subprocess.run([cad, "deform", "--mesh", case, "--handles", "ch_H.csv", "-o", "x.vtu",
                    "--exact-constraints", "--approximate-constraints"], capture_output=True, text=True)
check(r.returncode == 1 and "exclude each other" in r.stderr, "both flags: %s" % r.stderr)
check("--approximate-constraints" in subprocess.run([cad, "deform", "--help"], capture_output=True,
                                                    text=True).stdout, "--help names the flag")

# ---- no free node: every node of the 2-D mesh lies on a patch, and --no-slide fixes the
# empty planes' (by default they slide: docs/DESIGN.md, "Boundary motion by patch kind") ----
p, y, out = deform(case, "ch_nofree", "--handles", "ch_H.csv", "--fix-unlisted-boundary",
                   "--no-slide", "--method", "rbf", "--verbose")
check("0 free" in p.stdout and "no free node" in p.stdout and "no RBF built" in p.stdout,
      "no free node: said on stdout: %s" % p.stdout)
check("nothing to build or solve" in p.stderr, "no free node: --verbose says nothing is built")
check(not re.search(r"rbf: .*(dense|iterative)", p.stderr), "no free node: no RBF solve logged")
if y is not None:
    rest = np.setdiff1d(np.arange(len(x)), body)
    check(np.abs(y[body] - x[body] - move).max() <= 1e-12 * size and np.array_equal(y[rest], x[rest]),
          "no free node: the prescribed motion")
for method in ("dmffd", "mls"):
    p, _, _ = deform(case, "ch_nofree_" + method, "--handles", "ch_H.csv", "--fix-unlisted-boundary",
                     "--no-slide", "--method", method)
    check("no free node" in p.stdout, "no free node, %s: %s" % (method, p.stdout))

# ---- plane:frontAndBack: both planes of the 2-D mesh in one patch, split into two ----
p, y, out = deform(case, "ch_planes", "--handles", "ch_H.csv", "--fixed", "ch_F.csv",
                   "--constraint", "plane:frontAndBack", "--constraint-snap")
check("frontAndBack: 2 separate planes" in p.stdout, "frontAndBack split: %s" % p.stdout)
if y is not None:
    for z in (x[:, 2].min(), x[:, 2].max()):
        side = np.flatnonzero(x[:, 2] == z)
        check(off_plane(y[side]) <= 1e-13 * size and np.abs(y[side, 2] - z).max() <= 1e-13 * size,
              "frontAndBack z=%g: off its plane by %g" % (z, off_plane(y[side])))
    check(np.abs(y[body] - x[body] - move).max() <= 1e-12 * size, "planes: handles exact")
    solver_ready(out, "ch planes")

# ---- the wedge: the body grows radially within each wedge plane; plane snaps hold ----
# written at 17 digits: the checks below are of the deformation, not of the case's rounding
case = fc.make_case("wedge", os.path.join(work, "wedge"), write_precision=17)
x = points(case)
body = fc.patch_points(case, "body")
outer = sorted(set().union(*[fc.patch_points(case, p) for p in ("inlet", "outlet", "wall")])
               - set(body))
r = np.hypot(x[body, 1], x[body, 2])
D = np.zeros((len(body), 3))
D[r > 0, 1:] = 0.05 * x[body][r > 0, 1:] / r[r > 0, None]
write_inputs(x, body, D, outer, "we")
p, y, out = deform(case, "we_planes", "--handles", "we_H.csv", "--fixed", "we_F.csv",
                   "--constraint", "plane:front", "--constraint", "plane:back", "--constraint-snap")
if y is not None:
    check(np.abs(y[body] - x[body] - D).max() <= 1e-12 * size, "wedge: handles exact")
    check(np.array_equal(y[outer], x[outer]), "wedge: fixed nodes stay")
    for side in ("front", "back"):
        ids = fc.patch_points(case, side)
        before, after = off_plane(x[ids]), off_plane(y[ids])
        # the fixed nodes keep the input's coordinates: the plane can be no flatter than theirs
        check(after <= 2 * before + 1e-14 * size, "wedge %s: off its plane by %g (input %g)"
              % (side, after, before))
    solver_ready(out, "wedge planes")
# without the snap's anchoring the planes are lost by the field: the check above can fail
p, y, _ = deform(case, "we_free", "--handles", "we_H.csv", "--fixed", "we_F.csv")
if y is not None:
    ids = fc.patch_points(case, "front")
    check(off_plane(y[ids]) > 1e-6, "wedge without constraints: off its plane by %g" % off_plane(y[ids]))

print("%d failures" % fails)
sys.exit(1 if fails else 0)
