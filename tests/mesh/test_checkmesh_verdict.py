#!/usr/bin/python3
"""checkMesh's whole verdict: `cadmorph quality --foam` against the real checkMesh of OpenFOAM
v1912 on blockMesh cases (tests/helpers/foam_cases.py: channel2d, wedge, symmetry3d, cyclic)
and on broken copies of them - a point moved through its neighbours (negative volumes, wrong
face pyramids), a point of an empty plane moved off it (2-D edge alignment), a point of a
wedge moved off its plane, an unused point, two internal faces swapped (upper-triangular
order). For each: the same verdict ("Mesh OK." or "Failed N mesh checks." with the same N),
the same failed checks, the same cell-type table and directions, and every number to
checkMesh's printed precision. Then the inverted-cell count of `cadmorph quality` is
checkMesh's negative-volume-or-wrong-pyramid cells (docs/DESIGN.md, "What counts as an
inverted cell"). Exit 77 (ctest SKIP) only when OpenFOAM's tools are not installed.
usage: test_checkmesh_verdict.py CADMORPH WORKDIR [blockmesh|snappy] (default: both)"""
import os
import re
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "helpers"))
import foam_cases  # noqa: E402

CADMORPH, WORK = sys.argv[1], os.path.join(sys.argv[2], "checkmesh_verdict")
PARTS = sys.argv[3:] or ["blockmesh", "snappy"]
if not foam_cases.foam_available():
    print("SKIP: OpenFOAM (blockMesh, checkMesh) is not installed")
    sys.exit(77)

failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL:", msg)


def same(a, b):
    """Equal to the printed precision of the coarser of the two (6 significant digits);
    round-off noise (both below 1e-10 in magnitude) only to 1e-12."""
    if abs(a) < 1e-10 and abs(b) < 1e-10:
        return abs(a - b) < 1e-12
    return abs(a - b) <= 1e-5 * max(abs(a), abs(b))


def category(line):
    """What a failed check is about, from its "***" line (numbers and names dropped)."""
    return re.sub(r"\(?[-+]?\d[-+0-9.eE]*\)?", "#", line.split(":")[0].split(". ")[0]).strip()


NUMBERS = ["max_aspect", "max_non_orth", "avg_non_orth", "max_skewness", "max_cell_openness",
           "min_volume", "max_volume", "total_volume"]
COUNTS = ["points", "faces", "internal_faces", "cells", "hexahedra", "prisms", "wedges", "pyramids",
          "tetWedges", "tetrahedra", "polyhedra", "directions", "solution_directions",
          "wrong_pyramids", "negative_cells"]


def compare(name, case, expect_ok=None, expect_error=None):
    """checkMesh and `cadmorph quality --foam` on case: the same verdict and numbers."""
    ref = foam_cases.checkmesh(case)
    check(ref["returncode"] == 0 and ref["fatal"] is None, "%s: checkMesh failed: %s" % (name, ref["fatal"]))
    q = subprocess.run([CADMORPH, "quality", "--foam", case], capture_output=True, text=True)
    check(q.returncode == 0, "%s: cadmorph quality --foam exit %d: %s" % (name, q.returncode, q.stderr))
    ours = foam_cases.parse_checkmesh(q.stdout)
    check(ref["ok"] == ours["ok"] and ref["failed"] == ours["failed"],
          "%s: checkMesh says %s, cadmorph %s" % (name, "OK" if ref["ok"] else "Failed %d" % ref["failed"],
                                                 "OK" if ours["ok"] else "Failed %d" % ours["failed"]))
    if expect_ok is not None:
        check(ref["ok"] == expect_ok, "%s: the case is meant to be %s by checkMesh" % (name, "OK" if expect_ok
                                                                                      else "failed"))
    for k in COUNTS:
        check(ref.get(k) == ours.get(k), "%s: %s: checkMesh %s, cadmorph %s" % (name, k, ref.get(k), ours.get(k)))
    for k in NUMBERS:
        if k in ref or k in ours:
            check(k in ref and k in ours and same(ref[k], ours[k]),
                  "%s: %s: checkMesh %s, cadmorph %s" % (name, k, ref.get(k), ours.get(k)))
    # the failed checks, one "***" line each (checkMesh's "Wedge patch X not planar" names the
    # patch: compared by what the line is about)
    a = sorted(category(x) for x in ref["errors"])
    b = sorted(category(x) for x in ours["errors"])
    check(a == b, "%s: failed checks differ:\n  checkMesh %s\n  cadmorph  %s" % (name, a, b))
    if expect_error:
        check(any(expect_error in x for x in ref["errors"]),
              "%s: checkMesh does not report '%s': %s" % (name, expect_error, ref["errors"]))
    print("%-28s %-16s %s" % (name, "Mesh OK" if ref["ok"] else "Failed %d" % ref["failed"],
                              "; ".join(a) if a else ""))
    return ref, ours, q.stdout


# ---- editing a polyMesh (ASCII) -------------------------------------------------------

def list_span(text):
    """(start, end) of the entries of the first top-level list `N\\n(\\n ... \\n)`."""
    m = re.search(r"^(\d+)\s*\n\(\n", text, re.M)
    end = text.index("\n)", m.end())
    return m.start(), m.end(), end, int(m.group(1))


def read_list(path):
    text = open(path).read()
    s, b, e, n = list_span(text)
    items = text[b:e].split("\n")
    assert len(items) == n, (path, len(items), n)
    return text, s, e, items


def write_list(path, text, s, e, items):
    with open(path, "w") as f:
        f.write(text[:s] + "%d\n(\n" % len(items) + "\n".join(items) + text[e:])


def move_point(case, i, dx):
    path = os.path.join(case, "constant", "polyMesh", "points")
    text, s, e, items = read_list(path)
    x = [float(v) for v in items[i].strip("()").split()]
    items[i] = "(%.17g %.17g %.17g)" % (x[0] + dx[0], x[1] + dx[1], x[2] + dx[2])
    write_list(path, text, s, e, items)


def add_point(case, p):
    path = os.path.join(case, "constant", "polyMesh", "points")
    text, s, e, items = read_list(path)
    write_list(path, text, s, e, items + ["(%r %r %r)" % p])


def swap_internal_faces(case, i, j):
    d = os.path.join(case, "constant", "polyMesh")
    for name in ("faces", "owner", "neighbour"):
        text, s, e, items = read_list(os.path.join(d, name))
        items[i], items[j] = items[j], items[i]
        write_list(os.path.join(d, name), text, s, e, items)


def fresh(kind, name):
    src = os.path.join(WORK, "src_" + kind)
    if not os.path.isdir(src):
        foam_cases.make_case(kind, src)
    dst = os.path.join(WORK, name)
    shutil.rmtree(dst, ignore_errors=True)
    shutil.copytree(src, dst)
    return dst


def points_of(case):
    return foam_cases.read_points(case)


def interior_point(case, patch_kinds_to_avoid=()):
    """A point of no patch but those named, far from the bounding box's sides: (label, xyz)."""
    pts = points_of(case)
    on = set()
    for name, info in foam_cases.read_boundary(case).items():
        if name not in patch_kinds_to_avoid:
            on.update(foam_cases.patch_points(case, name))
    lo = [min(p[k] for p in pts) for k in range(3)]
    hi = [max(p[k] for p in pts) for k in range(3)]
    mid = [(a + b) / 2 for a, b in zip(lo, hi)]
    best = None
    for i, p in enumerate(pts):
        if i in on:
            continue
        d = sum((p[k] - mid[k]) ** 2 for k in range(2))
        if best is None or d < best[0]:
            best = (d, i)
    return best[1], pts[best[1]]


def spacing(case, p=None):
    """The distance from p (default: the middle interior point) to its nearest point."""
    pts = points_of(case)
    if p is None:
        p = interior_point(case)[1]
    return min(sum((a - b) ** 2 for a, b in zip(p, q)) ** 0.5 for q in pts if q != p)


os.makedirs(WORK, exist_ok=True)


def label_set(path):
    if not os.path.exists(path):
        return set()
    text = re.sub(r"//[^\n]*", "", open(path).read())
    m = re.search(r"^(\d+)\s*\(([^)]*)\)", text[text.index("}") + 1:], re.M)
    got = set(int(x) for x in m.group(2).split())
    assert len(got) == int(m.group(1)), path
    return got


def inverted_of(case):
    q = subprocess.run([CADMORPH, "quality", case], capture_output=True, text=True)
    m = re.search(r"inverted=(\d+)", q.stdout)
    return int(m.group(1)) if m else -1, q


def solver_view(case):
    """(cells of zero or negative volume, those plus the cells of wrongly oriented faces)."""
    sets = os.path.join(case, "constant", "polyMesh", "sets")
    shutil.rmtree(sets, ignore_errors=True)
    foam_cases.run_foam("checkMesh", case, check=False)
    neg = label_set(os.path.join(sets, "zeroVolumeCells"))
    faces = label_set(os.path.join(sets, "wrongOrientedFaces"))
    shutil.rmtree(sets, ignore_errors=True)
    d = os.path.join(case, "constant", "polyMesh")
    own = [int(x) for x in read_list(os.path.join(d, "owner"))[3]]
    nei = [int(x) for x in read_list(os.path.join(d, "neighbour"))[3]]
    near = set(neg)
    for f in faces:
        near.add(own[f])
        if f < len(nei):
            near.add(nei[f])
    return neg, near



if "blockmesh" in PARTS:
    # 1. the cases as blockMesh makes them: "Mesh OK." on both sides
    for kind in foam_cases.KINDS:
        ref, ours, text = compare(kind, fresh(kind, kind), expect_ok=True)
        if kind == "wedge":
            check(ref.get("directions") == 2, "wedge: checkMesh reports %s geometric directions" % ref.get("directions"))

    # blocks with collapsed edges: checkMesh's wedge (a hex with one edge collapsed) and tet
    # wedge cells, besides prisms and hexahedra (two blocks that share no face: 2 regions)
    c = fresh("symmetry3d", "collapsed_blocks")
    foam_cases.write_dict(c, "system/blockMeshDict", """
    vertices ( (0 0 0) (1 0 0) (1 1 0) (0 1 0) (0 0 1) (1 0 1) (1 1 1) (0 1 1)
               (2 0 0) (3 0 0) (3 1 0) (2 1 0) (2 0 1) (3 0 1) (3 1 1) (2 1 1) );
    blocks ( hex (0 1 2 3 4 5 6 6) (2 3 2) simpleGrading (1 1 1)
             hex (8 9 10 10 12 12 14 14) (3 3 3) simpleGrading (1 1 1) );
    defaultPatch { type wall; name walls; }
    boundary ( );
    """)
    foam_cases.run_foam("blockMesh", c)
    ref, ours, text = compare("collapsed_blocks", c)
    check(ref.get("wedges", 0) > 0 and ref.get("tetWedges", 0) > 0,
          "collapsed_blocks: no wedge or tet wedge cells: %s" % {k: ref.get(k) for k in COUNTS})

    # 2. broken copies
    # a point inside the 2-D channel moved in-plane across its neighbours, on both planes: every
    # cell around it inverts, the mesh stays 2-D
    c = fresh("channel2d", "channel2d_inverted")
    pts = points_of(c)
    front = set(foam_cases.patch_points(c, "frontAndBack"))
    i, p = interior_point(c, ("frontAndBack",))
    h = spacing(c, p)
    for j, q in enumerate(pts):
        if abs(q[0] - p[0]) < 1e-12 and abs(q[1] - p[1]) < 1e-12:
            move_point(c, j, (3 * h, 2 * h, 0))
    compare("channel2d_inverted", c, expect_ok=False, expect_error="negative")

    # a point of the front plane off the plane: edges no longer aligned with the 2-D directions
    c = fresh("channel2d", "channel2d_off_plane")
    i, p = interior_point(c, ("frontAndBack",))
    move_point(c, i, (0, 0, 0.05 * h))
    compare("channel2d_off_plane", c, expect_ok=False, expect_error="edges not aligned")

    # a point of a wedge plane moved off it (along the plane's normal direction z)
    c = fresh("wedge", "wedge_off_plane")
    wf = set(foam_cases.patch_points(c, "front"))
    k = sorted(wf)[len(wf) // 2]
    move_point(c, k, (0, 0, 1e-3 * spacing(c, points_of(c)[k])))
    compare("wedge_off_plane", c, expect_ok=False, expect_error="not planar")

    # a wedge point moved within its plane but across its neighbours: negative volumes
    c = fresh("wedge", "wedge_inverted")
    pts = points_of(c)
    wb = set(foam_cases.patch_points(c, "back"))
    i, p = interior_point(c, ("front", "back", "axis"))
    h = spacing(c, p)
    for j, q in enumerate(pts):
        if abs(q[0] - p[0]) < 1e-12 and abs((q[1] ** 2 + q[2] ** 2) - (p[1] ** 2 + p[2] ** 2)) < 1e-12:
            move_point(c, j, (4 * h, 0, 0))
    compare("wedge_inverted", c, expect_ok=False)

    # a 3-D point moved through its neighbours
    c = fresh("symmetry3d", "symmetry3d_inverted")
    i, p = interior_point(c)
    move_point(c, i, (10 * spacing(c, p), 0, 0))
    ref, ours, text = compare("symmetry3d_inverted", c, expect_ok=False)

    # an unused point
    c = fresh("symmetry3d", "symmetry3d_unused_point")
    add_point(c, (0.0, 0.0, 0.0))
    compare("symmetry3d_unused_point", c, expect_ok=False, expect_error="Unused points")

    # two internal faces swapped: no longer upper-triangular
    c = fresh("cyclic", "cyclic_unordered")
    nint = foam_cases.checkmesh(c)["internal_faces"]
    swap_internal_faces(c, 0, nint - 1)
    compare("cyclic_unordered", c, expect_ok=False, expect_error="upper triangular")

    # 3. inverted cells as the solver sees them: what `cadmorph quality` counts as inverted lies
    # between checkMesh's zero-volume cells and those plus the cells of its wrongly oriented faces
    # (the face sets it writes; a face's set does not say which side's pyramid failed)

    for name in ("channel2d_inverted", "wedge_inverted", "symmetry3d_inverted", "symmetry3d"):
        c = os.path.join(WORK, name)
        n, q = inverted_of(c)
        neg, near = solver_view(c)
        check(len(neg) <= n <= len(near) and (n > 0) == (len(near) > 0),
              "%s: cadmorph counts %d inverted cells, checkMesh %d of negative volume, %d with those of "
              "wrong face pyramids" % (name, n, len(neg), len(near)))
        print("%-28s inverted=%d (checkMesh: %d negative volumes, %d with wrong pyramids)"
              % (name, n, len(neg), len(near)))


if "snappy" in PARTS:
    # 4. snappyHexMesh around a rounded box: polyhedra whose tet decomposition folds (a scaled
    # Jacobian <= 0) while checkMesh finds every volume and face pyramid fine: not inverted
    snappy = foam_cases.make_snappy_case(os.path.join(WORK, "snappy"), body="rounded_box")
    ref, ours, text = compare("snappy", snappy, expect_ok=True)
    check(ref.get("polyhedra", 0) > 0 and ref.get("prisms", 0) + ref.get("wedges", 0) + ref.get("pyramids", 0) > 0,
          "snappy: expected polyhedra and other shapes: %s" % {k: ref.get(k) for k in COUNTS})
    n, q = inverted_of(snappy)
    sj = subprocess.run([CADMORPH, "quality", snappy, "--csv", os.path.join(WORK, "snappy_sj.csv")],
                        capture_output=True, text=True)
    rows = open(os.path.join(WORK, "snappy_sj.csv")).read().splitlines()[1:]
    sj_folded = sum(1 for r in rows if float(r.split(",")[2]) <= 0 or r.split(",")[2] == "nan")
    # the scaled Jacobian of our tet decomposition folds on some valid cells of this mesh:
    # the case would not tell the two notions apart otherwise
    check(sj_folded > 0, "snappy: no cell with a scaled Jacobian <= 0: the case tests nothing")
    check(n == 0, "snappy: checkMesh finds no negative volume or wrong pyramid, cadmorph counts %d inverted" % n)
    print("snappy: %d cells with a scaled Jacobian <= 0 (a quality measure), %d inverted" % (sj_folded, n))
    # a harmless warp (one interior point nudged) warns about no inverted cell; one that pushes
    # it through its neighbours warns with checkMesh's rule named
    i, p = interior_point(snappy)
    h = spacing(snappy, p)
    for name, d, want in (("nudged", 0.01 * h, 0), ("through", 10 * h, 1)):
        csv = os.path.join(WORK, "snappy_%s.csv" % name)
        with open(csv, "w") as f:
            f.write("node,dx,dy,dz\n%d,%r,0,0\n" % (i, d))
        w = subprocess.run([CADMORPH, "warp", "--mesh", snappy, "--displacements", csv, "-o",
                            os.path.join(WORK, "snappy_%s.vtu" % name)], capture_output=True, text=True)
        check(w.returncode == 0, "snappy warp %s: exit %d: %s" % (name, w.returncode, w.stderr))
        warned = re.search(r"warning: (\d+) inverted cells? \(a negative volume or a wrongly oriented face, "
                           r"as checkMesh finds them\).*cells a solver rejects", w.stderr)
        check(bool(warned) == bool(want) and ("inverted" in w.stderr) == bool(want),
              "snappy warp %s: %s" % (name, w.stderr.strip() or "no warning"))


if failures:
    print("%d failures" % len(failures))
    sys.exit(1)
print("all verdicts agree")
