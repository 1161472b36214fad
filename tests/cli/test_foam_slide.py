#!/usr/bin/python3
"""Boundary motion by patch kind through the CLI on real OpenFOAM cases (docs/DESIGN.md,
"Boundary motion by patch kind"): the body of each shared blockMesh case (2-D channel,
axisymmetric wedge, symmetry plane, cyclic pair) is moved by `cadmorph warp --displacements`
and `cadmorph deform --handles ... --fix-unlisted-boundary`, and the result checked:
the normal motion of every node of a sliding plane is 0, the 2-D pairs stay identical in
plane, the wedge planes stay planar with each pair at one (r, z), fixed patches do not move,
the body reaches its target, the real checkMesh says "Mesh OK" (with its 2-D and wedge
checks) and the case's solver runs 5 steps on the 2-D and wedge results.

  test_foam_slide.py CADMORPH WORKDIR
Exit 77 (ctest SKIP) only when OpenFOAM's tools are not installed.
"""
import math
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "helpers"))
import foam_cases as fc  # noqa: E402

if not fc.foam_available():
    print("SKIP: blockMesh/checkMesh not installed")
    sys.exit(77)

CLI, WORK = sys.argv[1], os.path.join(sys.argv[2], "foam_slide")
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
FAILS = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILS.append(what)


def run(*args, expect=0):
    r = subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True)
    if r.returncode != expect:
        print(r.stdout[-2000:], r.stderr[-2000:])
    check(r.returncode == expect, "%s %s exits %d (got %d)" % (args[0], args[1:3], expect,
                                                                   r.returncode))
    return r


def body_motion(kind, pts, body, how):
    """{node: (dx, dy, dz)} of the body's points."""
    cx = sum(pts[i][0] for i in body) / len(body)
    cy = sum(pts[i][1] for i in body) / len(body)
    out = {}
    for i in body:
        x, y, z = pts[i]
        if how == "translate":
            d = (0.02, 0.01, 0.0)
        elif how == "rotate":  # 5 degrees about the body's centre, in the x-y plane
            a, dx, dy = math.radians(5), x - cx, y - cy
            d = (math.cos(a) * dx - math.sin(a) * dy - dx,
                 math.sin(a) * dx + math.cos(a) * dy - dy, 0.0)
        elif how == "radial-axial":  # the wedge's axis is x: r x 1.1 and 0.01 along the axis
            d = (0.01, 0.1 * y, 0.1 * z)
        else:  # parallel to the plane y = 0 (symmetry3d) or along the channel (cyclic)
            d = (0.02, 0.0, 0.01) if kind == "symmetry3d" else (0.02, 0.01, 0.0)
        out[i] = d
    return out


def write_csv(path, motion, handles=False):
    with open(path, "w") as f:
        f.write("node,dx,dy,dz\n")
        for i, d in sorted(motion.items()):
            f.write("%d,%.17g,%.17g,%.17g\n" % ((i,) + tuple(d)))


def runnable(src, out):
    """The written case with the source's system/, 0/ and constant/ files (a morph writes
    only the polyMesh)."""
    for d in ("system", "0"):
        if not os.path.exists(os.path.join(out, d)):
            shutil.copytree(os.path.join(src, d), os.path.join(out, d))
    for x in os.listdir(os.path.join(src, "constant")):
        p = os.path.join(src, "constant", x)
        if os.path.isfile(p) and not os.path.exists(os.path.join(out, "constant", x)):
            shutil.copy(p, os.path.join(out, "constant"))


def verify(kind, src, out, motion, label, solve):
    runnable(src, out)
    p0, p1 = fc.read_points(src), fc.read_points(out)
    bnd = fc.read_boundary(src)
    types = {k: v["type"] for k, v in bnd.items()}
    scale = max(max(abs(c) for c in p) for p in p0)
    tol = 1e-12 * scale
    # prescribed nodes at their target
    miss = max(math.dist(p1[i], tuple(a + b for a, b in zip(p0[i], d))) for i, d in motion.items())
    check(miss <= tol, "%s: body at its target (miss %.3g)" % (label, miss))
    # fixed patches unmoved, bit for bit
    for name, t in types.items():
        if t in ("patch", "wall") and name != "body":
            moved = [i for i in fc.patch_points(src, name) if i not in motion and p0[i] != p1[i]]
            check(not moved, "%s: fixed patch %s unmoved (%d moved)" % (label, name, len(moved)))
    interior_moved = sum(p0[i] != p1[i] for i in range(len(p0)))
    check(interior_moved > 2 * len(motion), "%s: the mesh follows the body (%d nodes moved)" %
          (label, interior_moved))
    if kind == "channel2d":
        zs = sorted(set(p[2] for p in p0))
        check(all(a[2] == b[2] for a, b in zip(p0, p1)), "%s: z of every node unchanged" % label)
        front = {(p[0], p[1]): i for i, p in enumerate(p0) if p[2] == zs[-1]}
        pairs = [(i, front[(p[0], p[1])]) for i, p in enumerate(p0) if p[2] == zs[0]]
        check(len(pairs) == len(p0) // 2, "%s: every node has its partner" % label)
        bad = sum(p1[i][:2] != p1[j][:2] for i, j in pairs)
        check(bad == 0, "%s: 2-D pairs identical in plane (%d differ)" % (label, bad))
    if kind == "wedge":
        fr, bk = set(fc.patch_points(src, "front")), set(fc.patch_points(src, "back"))
        worst = 0.0
        for side in (fr, bk):
            for i in side:  # the angle about the x axis of every point off the axis
                r0, r1 = math.hypot(p0[i][1], p0[i][2]), math.hypot(p1[i][1], p1[i][2])
                if r0 > 1e-9 * scale:
                    worst = max(worst, abs(math.atan2(p1[i][2], p1[i][1]) -
                                           math.atan2(p0[i][2], p0[i][1])) * r1)
        check(worst <= 1e-12 * scale, "%s: wedge planes planar (off by %.3g)" % (label, worst))
        back = {}
        for i in bk:
            back[(round(p0[i][0], 9), round(math.hypot(p0[i][1], p0[i][2]), 9))] = i
        diff, n = 0.0, 0
        for i in fr:
            j = back.get((round(p0[i][0], 9), round(math.hypot(p0[i][1], p0[i][2]), 9)))
            if j is None or j == i:
                continue
            n += 1
            diff = max(diff, abs(p1[i][0] - p1[j][0]),
                       abs(math.hypot(p1[i][1], p1[i][2]) - math.hypot(p1[j][1], p1[j][2])))
        check(n > 100 and diff <= 1e-12 * scale,
              "%s: %d wedge pairs at one (r, z) (off by %.3g)" % (label, n, diff))
    if kind == "symmetry3d":
        sym = fc.patch_points(src, "symmetry")
        check(all(p1[i][1] == p0[i][1] for i in sym), "%s: symmetry nodes keep y" % label)
        check(any(p1[i] != p0[i] for i in sym), "%s: symmetry nodes slide" % label)
    if kind == "cyclic":
        for side in ("front", "back"):
            pts = fc.patch_points(src, side)
            check(all(p1[i][2] == p0[i][2] for i in pts), "%s: cyclic %s keeps z" % (label, side))
        back = {p0[i][:2]: i for i in fc.patch_points(src, "back")}
        pairs = [(i, back.get(p0[i][:2])) for i in fc.patch_points(src, "front")]
        check(all(j is not None for _, j in pairs) and
              all(p1[i][:2] == p1[j][:2] for i, j in pairs) and
              any(p1[i] != p0[i] for i, _ in pairs),
              "%s: the cyclic sides slide with one motion per pair" % label)
    cm = fc.checkmesh(out)
    check(cm["ok"], "%s: checkMesh Mesh OK%s" % (label, "" if cm["ok"] else
                                                 ":\n" + cm["text"][-1500:]))
    if kind in ("channel2d", "wedge"):
        check(cm.get("directions") == 2, "%s: checkMesh sees 2 directions" % label)
    if solve:
        r = fc.solver_steps(out, 5, check=False)
        check(r.returncode == 0, "%s: 5 solver steps run (exit %d)" % (label, r.returncode))


CASES = [("channel2d", "translate"), ("channel2d", "rotate"), ("wedge", "radial-axial"),
         ("symmetry3d", "parallel"), ("cyclic", "parallel")]
made = {}
for kind, how in CASES:
    src = made.get(kind)
    if src is None:
        src = made[kind] = fc.make_case(kind, os.path.join(WORK, kind))
        # blockMesh wrote the points at 10 digits (pairs exactly equal); cadmorph writes the
        # moved ones at 17, so the checks below are of the motion to round-off, not of the
        # case's rounding
        ctl = os.path.join(src, "system", "controlDict")
        text = open(ctl).read()
        open(ctl, "w").write(re.sub(r"writePrecision\s+\d+;", "writePrecision 17;", text))
    pts = fc.read_points(src)
    motion = body_motion(kind, pts, fc.patch_points(src, "body"), how)
    csv = os.path.join(WORK, "%s_%s.csv" % (kind, how))
    write_csv(csv, motion)
    for cmd in ("warp", "deform") + (("deform-mls",) if how in ("rotate", "radial-axial") else ()):
        out = os.path.join(WORK, "%s_%s_%s" % (kind, how, cmd))
        label = "%s %s %s" % (cmd, kind, how)
        if cmd == "warp":
            run("warp", "--mesh", src, "--displacements", csv, "-o", out + "/")
        else:  # rbf, and the default method (MLS: the correction makes it exact)
            run("deform", "--mesh", src, "--handles", csv, "--fix-unlisted-boundary",
                *(("--method", "rbf") if cmd == "deform" else ()), "-o", out + "/")
        if os.path.isdir(out):
            verify(kind, src, out, motion, label, solve=how != "translate" and cmd == "warp"
                   or (kind == "wedge" and cmd == "deform-mls"))

# the user's choice: a patch name the mesh does not have is a usage error naming its patches
src = made["channel2d"]
r = run("warp", "--mesh", src, "--displacements", os.path.join(WORK, "channel2d_rotate.csv"),
        "-o", os.path.join(WORK, "bad") + "/", "--slide", "nosuch", expect=1)
check("nosuch" in r.stderr and "frontAndBack" in r.stderr, "unknown patch names the mesh's")
# --fixed-patches frontAndBack: the old motion (the planes fixed): the interior cannot move
out = os.path.join(WORK, "fixedplanes")
run("warp", "--mesh", src, "--displacements", os.path.join(WORK, "channel2d_rotate.csv"),
    "-o", out + "/", "--fixed-patches", "frontAndBack")
p0, p1 = fc.read_points(src), fc.read_points(out)
check(sum(a != b for a, b in zip(p0, p1)) == 80, "--fixed-patches: only the body moves")
# --slide walls: the channel walls (flat, y = const) slide along x
out = os.path.join(WORK, "slidewalls")
run("warp", "--mesh", src, "--displacements", os.path.join(WORK, "channel2d_translate.csv"),
    "-o", out + "/", "--slide", "walls")
p1 = fc.read_points(out)
walls = fc.patch_points(src, "walls")
check(all(p1[i][1] == p0[i][1] and p1[i][2] == p0[i][2] for i in walls) and
      any(p1[i][0] != p0[i][0] for i in walls), "--slide walls: the walls slide along x only")

if FAILS:
    print("%d FAILED" % len(FAILS))
    sys.exit(1)
print("all passed")
