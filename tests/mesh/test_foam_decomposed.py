#!/usr/bin/python3
"""Decomposed OpenFOAM cases and whole-case output, against the real OpenFOAM v1912
(decomposePar, reconstructPar, checkMesh, simpleFoam), on blockMesh cases with zones
(tests/helpers/foam_cases.py):

  * decomposePar (simple: 2 pieces, binary; 2 pieces cutting a cyclic pair, ASCII;
    hierarchical: 4 pieces, ASCII at writePrecision 12)
    writes pieces with empty zones ("cellLabels 0;" in binary, "0()" in ASCII); cadmorph
    reads `CASE/processor*` and, with no constant/polyMesh, `CASE/` as one mesh that is the
    undecomposed mesh: the same .msh byte for byte (points, cells, patches, zones) and
    the same `quality --foam` report; written to a polyMesh directory, a reconstructed mesh
    that checkMesh passes;
  * `warp` of the pieces by a smooth displacement of every point, written to a new case and
    onto the source case in place: each processorN/constant/polyMesh/points replaced, every
    other file of the case byte-identical; reconstructPar of the written pieces gives the
    points of the undecomposed mesh warped the same way (binary: exactly; ASCII: to the
    written precision) and checkMesh passes on every piece;
  * `-o newcase/` of an undecomposed case is a runnable case (every file of the source copied,
    processor* left out, points replaced; 5 simpleFoam steps run) and a new case inside the
    source is refused;
  * ASCII points at the case's writePrecision: an unmoved point's line unchanged, a moved
    one at 12 significant digits (the case says 12; below 10 it gets 10, as blockMesh writes points).
Exit 77 (ctest SKIP) only when OpenFOAM's tools are not installed.
usage: test_foam_decomposed.py CADMORPH WORKDIR"""
import filecmp
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "helpers"))
import foam_cases as fc  # noqa: E402

if not fc.foam_available() or shutil.which("decomposePar") is None or shutil.which("reconstructPar") is None:
    print("SKIP: OpenFOAM (Debian package openfoam: blockMesh, decomposePar, reconstructPar) is not installed")
    sys.exit(77)

CADMORPH, WORK = sys.argv[1], os.path.join(sys.argv[2], "foam_decomposed")
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
failures = []


def check(ok, msg):
    if not ok:
        failures.append(msg)
        print("FAIL:", msg)


def cadmorph(*args):
    return subprocess.run([CADMORPH] + [str(a) for a in args], capture_output=True, text=True)


def files(case):
    """Relative paths of every regular file under case."""
    out = []
    for root, _, names in os.walk(case):
        out += [os.path.relpath(os.path.join(root, n), case) for n in names]
    return sorted(out)


def same_tree(a, b, changed, label):
    """Every file of a is in b byte for byte except the relative paths in changed (which
    must differ); b has no other file."""
    fa, fb = files(a), files(b)
    check(fa == fb, "%s: file lists differ: only in source %s, only in output %s"
          % (label, sorted(set(fa) - set(fb))[:5], sorted(set(fb) - set(fa))[:5]))
    for rel in fa:
        if rel not in fb:
            continue
        same = filecmp.cmp(os.path.join(a, rel), os.path.join(b, rel), shallow=False)
        check(same != (rel in changed), "%s: %s %s" % (label, rel, "unchanged" if rel in changed else "differs"))


def displacement_csv(case, path):
    """A smooth x displacement of every point (zero for x below the middle, so some points do
    not move; a function of x only, so planes x = const stay planes and 2-D stays 2-D)."""
    pts = fc.read_points(case)
    xs = [p[0] for p in pts]
    x0, length = 0.5 * (min(xs) + max(xs)), max(xs) - min(xs)
    with open(path, "w") as f:
        f.write("node,dx,dy,dz\n")
        for i, (x, _, _) in enumerate(pts):
            d = 0.05 * max(0.0, x - x0) ** 2 / length
            f.write("%d,%r,0,0\n" % (i, d))
    return length


def stale(case, polymesh, name):
    """A new case holding only a stale compressed twin in its polyMesh: writing the case must
    remove it (the file lists compared afterwards would differ otherwise)."""
    shutil.rmtree(case, ignore_errors=True)
    os.makedirs(os.path.join(case, polymesh))
    with open(os.path.join(case, polymesh, name), "wb") as f:
        f.write(b"stale")


def decompose(case, n, method, split=None):
    coeffs = "simpleCoeffs { n (%s); delta 0.001; }" % (split or "%d 1 1" % n) if method == "simple" else \
        "hierarchicalCoeffs { n (2 %d 1); delta 0.001; order xyz; }" % (n // 2)
    with open(os.path.join(case, "system", "decomposeParDict"), "w") as f:
        f.write(fc.HEADER % ("dictionary", "decomposeParDict") +
                "numberOfSubdomains %d;\nmethod %s;\n%s\n" % (n, method, coeffs))
    fc.run_foam("decomposePar", case)


def reconstructed_points(case, n):
    """reconstructPar of the pieces' constant points: each piece's points as time 1's
    polyMesh/points (how a moving mesh is stored), reconstructed into case/1/polyMesh."""
    for i in range(n):
        d = os.path.join(case, "processor%d" % i, "1", "polyMesh")
        os.makedirs(d)
        shutil.copy(os.path.join(case, "processor%d" % i, "constant", "polyMesh", "points"), d)
    fc.run_foam("reconstructPar", case, "-time", "1")
    pts = fc.read_points(case, "1/polyMesh")
    for i in range(n):
        shutil.rmtree(os.path.join(case, "processor%d" % i, "1"))
    shutil.rmtree(os.path.join(case, "1"))
    return pts


def decomposed_round_trip(kind, n, method, binary, precision, split=None):
    label = "%s %d pieces %s" % (kind, n, "binary" if binary else "ascii")
    src = fc.make_case(kind, os.path.join(WORK, kind + "_src"), zones=True, binary=binary,
                       scale=0.5, write_precision=precision)
    decompose(src, n, method, split)
    zones = "".join(open(os.path.join(src, "processor%d" % i, "constant", "polyMesh", "cellZones")).read()
                    if not binary else
                    open(os.path.join(src, "processor%d" % i, "constant", "polyMesh", "cellZones"), "rb")
                    .read().decode("latin-1") for i in range(n))
    empty = "cellLabels      0;" if binary else "cellLabels      0()"
    check(empty in zones, "%s: no piece has an empty zone written as '%s'" % (label, empty))

    # the pieces read as one mesh: the undecomposed mesh (the auto form without constant/polyMesh)
    only = os.path.join(WORK, kind + "_pieces_only")
    shutil.rmtree(only, ignore_errors=True)
    shutil.copytree(src, only)
    shutil.rmtree(os.path.join(only, "constant", "polyMesh"))
    zero = os.path.join(WORK, "zero.csv")
    with open(zero, "w") as f:
        f.write("node,dx,dy,dz\n0,0,0,0\n")
    msh = {}
    for name, path in (("undecomposed", src + "/"), ("pieces", src + "/processor*"), ("auto", only + "/")):
        msh[name] = os.path.join(WORK, "%s_%s.msh" % (kind, name))
        r = cadmorph("warp", "--mesh", path, "--displacements", zero, "-o", msh[name])
        check(r.returncode == 0, "%s: warp %s: %s" % (label, path, r.stderr))
    for name in ("pieces", "auto"):
        check(filecmp.cmp(msh["undecomposed"], msh[name], shallow=False),
              "%s: the %s mesh differs from the undecomposed one" % (label, name))
    qa = cadmorph("quality", src + "/", "--foam")
    qb = cadmorph("quality", src + "/processor*", "--foam")
    check(qa.returncode == 0 and qb.returncode == 0 and qa.stdout == qb.stdout,
          "%s: quality --foam differs:\n%s\n%s" % (label, qa.stdout[-600:], qb.stdout[-600:]))

    # the pieces written to a polyMesh directory: the reconstructed mesh (patch entries kept)
    rec = os.path.join(WORK, kind + "_reconstructed")
    shutil.rmtree(rec, ignore_errors=True)
    r = cadmorph("warp", "--mesh", src + "/processor*", "--displacements", zero, "-o", rec + "/constant/polyMesh")
    shutil.copytree(os.path.join(src, "system"), os.path.join(rec, "system"))
    cm = fc.checkmesh(rec)
    qr = cadmorph("quality", rec + "/", "--foam")
    check(r.returncode == 0 and cm["ok"] and qr.stdout == qa.stdout,
          "%s: the pieces as one polyMesh: %s; checkMesh %s; quality equal %s"
          % (label, r.stderr, cm["ok"], qr.stdout == qa.stdout))

    # warp the undecomposed mesh and the pieces by the same displacement of every point
    csv = os.path.join(WORK, kind + "_d.csv")
    displacement_csv(src, csv)
    und = os.path.join(WORK, kind + "_undecomposed_out")
    stale(und, "constant/polyMesh", "owner.gz")
    r = cadmorph("warp", "--mesh", src + "/", "--displacements", csv, "-o", und + "/")
    check(r.returncode == 0, "%s: warp undecomposed: %s" % (label, r.stderr))
    new = os.path.join(WORK, kind + "_pieces_out")
    stale(new, "processor1/constant/polyMesh", "faces.gz")
    r = cadmorph("warp", "--mesh", src + "/processor*", "--displacements", csv, "-o", new + "/")
    check(r.returncode == 0, "%s: warp pieces -> new case: %s" % (label, r.stderr))
    pts = ["processor%d/constant/polyMesh/points" % i for i in range(n)]
    same_tree(src, new, pts, label + " new case")
    # in place: a copy of the source case written onto itself
    inplace = os.path.join(WORK, kind + "_in_place")
    shutil.rmtree(inplace, ignore_errors=True)
    shutil.copytree(src, inplace)
    r = cadmorph("warp", "--mesh", inplace + "/processor*", "--displacements", csv, "-o", inplace + "/")
    check(r.returncode == 0, "%s: warp pieces in place: %s" % (label, r.stderr))
    same_tree(src, inplace, pts, label + " in place")
    for rel in pts:
        check(filecmp.cmp(os.path.join(new, rel), os.path.join(inplace, rel), shallow=False),
              "%s: %s in place differs from the new case's" % (label, rel))

    # reconstructPar of the written pieces = the undecomposed mesh warped the same way
    want = fc.read_points(und)
    got = reconstructed_points(new, n)
    # reconstructPar writes ASCII points at the case's writePrecision P (default 6)
    big = max(abs(v) for q in want for v in q)
    tol = 0.0 if binary else 10.0 ** (1 - (precision or 6)) * big
    err = max(max(abs(a - b) for a, b in zip(p, q)) for p, q in zip(want, got)) if len(want) == len(got) else None
    check(err is not None and err <= tol, "%s: reconstructPar of the pieces differs from the warped "
          "undecomposed mesh by %s (tolerance %g)" % (label, err, tol))
    for i in range(n):
        cm = fc.checkmesh(os.path.join(new, "processor%d" % i))
        check(cm["ok"], "%s: checkMesh fails on processor%d:\n%s" % (label, i, cm["text"][-1500:]))
    print("%s: read as one mesh, written back piece by piece (new case and in place), "
          "reconstructPar agrees (max %g), checkMesh OK" % (label, err if err is not None else -1))
    return src, und


# 1. binary, 2 pieces (simple); 2. the cyclic pair cut by the decomposition (processorCyclic
# patches); 3. ASCII at writePrecision 12, 4 pieces (hierarchical)
decomposed_round_trip("channel2d", 2, "simple", True, None)
decomposed_round_trip("cyclic", 2, "simple", False, None, "1 1 2")
with open(os.path.join(WORK, "cyclic_src", "processor0", "constant", "polyMesh", "boundary")) as f:
    check("processorCyclic" in f.read(), "cyclic: the decomposition has no processorCyclic patch")
src, und = decomposed_round_trip("symmetry3d", 4, "hierarchical", False, 12)

# 3. -o newcase/ of an undecomposed case: the whole case (processor* left out)
changed = ["constant/polyMesh/points"]
src_files = [f for f in files(src) if not f.startswith("processor")]
check(files(und) == src_files, "new case: files %s, expected the source's %s"
      % (sorted(set(files(und)) ^ set(src_files))[:6], len(src_files)))
for rel in src_files:
    if rel in changed or not os.path.exists(os.path.join(und, rel)):
        continue
    check(filecmp.cmp(os.path.join(src, rel), os.path.join(und, rel), shallow=False), "new case: %s differs" % rel)
cm = fc.checkmesh(und)
check(cm["ok"], "new case: checkMesh fails:\n%s" % cm["text"][-1500:])
p = fc.solver_steps(und, 5, check=False)
check(p.returncode == 0, "new case: 5 simpleFoam steps fail:\n%s" % (p.stdout[-1500:] + p.stderr[-800:]))
r = cadmorph("warp", "--mesh", src + "/", "--displacements", os.path.join(WORK, "zero.csv"), "-o", src + "/inner/")
check(r.returncode != 0 and "one inside the other" in r.stderr and not os.path.exists(src + "/inner"),
      "new case inside the source: exit %d, %s" % (r.returncode, r.stderr))

# 4. ASCII points at writePrecision 12: unmoved lines unchanged, moved ones at 12 digits
a = open(os.path.join(src, "constant", "polyMesh", "points")).read().splitlines()
b = open(os.path.join(und, "constant", "polyMesh", "points")).read().splitlines()
pa, pb = fc.read_points(src), fc.read_points(und)
line = re.compile(r"^\(([^ ]+) ([^ ]+) ([^ ]+)\)$")
unmoved = moved = 0
ok = len(a) == len(b)
for la, lb in zip(a, b) if ok else []:
    m = line.match(lb)
    if la == lb:
        unmoved += m is not None
        continue
    moved += 1
    digits = max(len(re.sub(r"e.*|^-|\.", "", v).lstrip("0")) for v in m.groups()) if m else 99
    ok &= m is not None and digits <= 12
unmoved_pts = sum(1 for p, q in zip(pa, pb) if p == q)
check(ok and moved > 0 and unmoved == unmoved_pts > 0,
      "writePrecision 12: %d moved lines, %d unchanged lines for %d unmoved points; all moved at <= 12 "
      "digits: %s" % (moved, unmoved, unmoved_pts, ok))
print("new case: every file copied, checkMesh OK, 5 simpleFoam steps; points: %d moved lines at 12 "
      "digits, %d unchanged" % (moved, unmoved))

# the case named as input and output (`--mesh case/ -o case/`): its points replaced in place, as
# moveMesh does, every other file unchanged (another format's same-file output stays refused:
# tests/cli/warp.cmake)
whole = os.path.join(WORK, "whole_in_place")
shutil.rmtree(whole, ignore_errors=True)
shutil.copytree(src, whole)
with open(os.path.join(WORK, "one_node.csv"), "w") as f:
    f.write("node,dx,dy,dz\n0,0,0,0.001\n")
r = cadmorph("warp", "--mesh", whole + "/", "--displacements", os.path.join(WORK, "one_node.csv"),
             "-o", whole + "/")
check(r.returncode == 0, "case/ onto itself: exit %d, %s" % (r.returncode, r.stderr))
same_tree(src, whole, ["constant/polyMesh/points"], "case/ onto itself")

if failures:
    print("%d failures" % len(failures))
    sys.exit(1)
print("all decomposed-case checks passed")
