#!/usr/bin/env python3
"""`cadmorph quality|warp|morph|deform|optimize` on an SU2 mesh that gmsh wrote: the bore of
tests/data/cad meshed by `cadmorph mesh --mesher gmsh` (its CAD faces are the physical groups
face_0 .. face_8), converted to .su2 by gmsh's own writer (the groups become markers).

Every .su2 written is the input with only the coordinate numbers of point lines changed
(every other line, and each point's index column, byte for byte); meshio reads it. Further:
quality of the .su2 is that of the .msh it came from; warp moves the listed nodes by exactly
their displacement; morph into .su2 and into .vtu write the same coordinates; deform resolves
marker names (a plane constraint on one marker keeps its nodes on a plane; an unknown name is
refused, naming the markers); optimize leaves every boundary point line untouched.

usage: su2_cli.py CADMORPH DATA WORK
"""
import contextlib
import csv
import os
import re
import subprocess
import sys

import numpy as np

import gmsh
import meshio

CLI, DATA = sys.argv[1], sys.argv[2]
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from su2_files import check, finish, markers  # noqa: E402
WORK = os.path.join(sys.argv[3], "su2_cli")
os.makedirs(WORK, exist_ok=True)
CAD = os.path.join(DATA, "cad")
SUMMARY = re.compile(r"min_scaled_jacobian=(\S+) mean_scaled_jacobian=(\S+) inverted=(\d+) cells=(\d+)\s*$")


def w(name):
    return os.path.join(WORK, name)


def run(*args, code=0):
    p = subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True)
    check(p.returncode == code, "cadmorph %s: exit %d (want %d)%s" % (
        args[0], p.returncode, code, "" if p.returncode == code else ": " + p.stderr.strip()))
    return p


def lines_of(path):
    return open(path, "rb").read().split(b"\n")


def point_lines(lines):
    """{line index: point index} of the NPOIN= block."""
    out = {}
    for i, s in enumerate(lines):
        if s.startswith(b"NPOIN"):
            n = int(s.split(b"=")[1].split()[0])
            for k in range(n):
                out[i + 1 + k] = k
            break
    return out


def only_coordinates(src, dst, what):
    """dst is src with only coordinate numbers of point lines changed; the changed points."""
    a, b = lines_of(src), lines_of(dst)
    pts = point_lines(a)
    ok = len(a) == len(b)
    moved = set()
    for i in range(min(len(a), len(b))):
        if i in pts:
            ok &= a[i].split()[3:] == b[i].split()[3:]
            if a[i] != b[i]:
                moved.add(pts[i])
        else:
            ok &= a[i] == b[i]
    check(ok, "%s: only coordinate numbers changed (%d points)" % (what, len(moved)))
    return moved


def meshio_points(path):
    """meshio's reading of path (its notes that marker names are not integers are dropped)."""
    with open(os.devnull, "w") as null, contextlib.redirect_stderr(null):
        return meshio.read(path).points


def planarity(x):
    c = x - x.mean(axis=0)
    s = np.linalg.svd(c, compute_uv=False)
    return s[2] / s[0]


def main():
    # the mesh: cadmorph mesh (gmsh), then gmsh's .su2 writer
    run("mesh", os.path.join(CAD, "bore_a.step"), "-o", w("bore_a.msh"), "--size", "0.6", "--mesher", "gmsh")
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(w("bore_a.msh"))
    gmsh.option.setNumber("Mesh.SaveAll", 1)
    gmsh.write(w("bore_a.su2"))
    gmsh.finalize()
    su2 = w("bore_a.su2")
    x0 = meshio_points(su2)
    mk = markers(su2)[0]
    check(len(mk) >= 6, "gmsh wrote %d markers: %s" % (len(mk), sorted(mk)))

    # quality: the same as of the .msh it came from
    q_su2 = run("quality", su2).stdout.strip().splitlines()[-1]
    q_msh = run("quality", w("bore_a.msh")).stdout.strip().splitlines()[-1]
    check(SUMMARY.match(q_su2) is not None and q_su2 == q_msh, "quality: %s" % q_su2)

    # warp: the nodes of one marker moved by a fixed vector, written back into .su2
    name = sorted(mk)[0]
    d = np.array([0.01, -0.02, 0.015])
    with open(w("d.csv"), "w", newline="") as f:
        out = csv.writer(f)
        out.writerow(["node", "dx", "dy", "dz"])
        for n in sorted(mk[name]):
            out.writerow([n, repr(d[0]), repr(d[1]), repr(d[2])])
    p = run("warp", "--mesh", su2, "--displacements", w("d.csv"), "-o", w("warped.su2"))
    check(SUMMARY.search(p.stdout) is not None, "warp: summary line")
    only_coordinates(su2, w("warped.su2"), "warp")
    x1 = meshio_points(w("warped.su2"))
    nodes = np.array(sorted(mk[name]))
    check(np.array_equal(x1[nodes], x0[nodes] + d), "warp: marker %s moved by exactly d" % name)

    # morph onto bore_b: into .su2 and into .vtu, the same coordinates
    for out in ("bore_b.su2", "bore_b.vtu"):
        p = run("morph", "--from", os.path.join(CAD, "bore_a.step"), "--to", os.path.join(CAD, "bore_b.step"),
                "--mesh", su2, "-o", w(out), "--threads", "1")
        check(SUMMARY.search(p.stdout) is not None and " inverted=0 " in p.stdout, "morph -> %s: no inverted cell" % out)
    moved = only_coordinates(su2, w("bore_b.su2"), "morph")
    xb = meshio_points(w("bore_b.su2"))
    check(len(moved) > 0 and np.array_equal(xb, meshio.read(w("bore_b.vtu")).points),
          "morph: .su2 and .vtu outputs have the same coordinates")

    # deform: handles on one marker, another fixed, a plane constraint on a third by its name
    flat = [m for m in sorted(mk) if planarity(x0[sorted(mk[m])]) < 1e-12]
    check(len(flat) >= 3, "planar markers: %s" % flat)
    if len(flat) >= 3:
        hand, fixed, plane = flat[0], flat[1], flat[2]
        plane_nodes = mk[plane] - mk[hand] - mk[fixed]
        with open(w("h.csv"), "w", newline="") as f:
            out = csv.writer(f)
            out.writerow(["node", "dx", "dy", "dz"])
            for n in sorted(mk[hand]):
                out.writerow([n, 0.02, 0.01, -0.01])
        with open(w("f.csv"), "w") as f:
            f.write("node\n" + "".join("%d\n" % n for n in sorted(mk[fixed] - mk[hand])))
        # the constraint is a weighted term of MLS (Shape-Up): the marker ends much flatter
        # with it than without
        flatness = []
        for out, extra in (("deformed.su2", ["--constraint", "plane:" + plane, "--constraint-weight", "10000"]), ("free.su2", [])):
            run("deform", "--mesh", su2, "--handles", w("h.csv"), "--fixed", w("f.csv"), "--method", "mls",
                "-o", w(out), "--threads", "1", *extra)
            if os.path.exists(w(out)):
                only_coordinates(su2, w(out), "deform")
                flatness.append(planarity(meshio_points(w(out))[sorted(plane_nodes)]))
        check(len(flatness) == 2 and flatness[0] < 0.1 * flatness[1],
              "deform: a plane constraint on marker %s by name (flatness %s)" % (plane, flatness))
        p = run("deform", "--mesh", su2, "--handles", w("h.csv"), "--fixed", w("f.csv"), "--method", "mls",
                "--constraint", "plane:no_such_marker", "-o", w("bad.su2"), code=2)
        check(name in p.stderr and not os.path.exists(w("bad.su2")), "deform: an unknown marker is refused naming the markers")

    # optimize: boundary point lines untouched
    run("optimize", su2, "-o", w("optimized.su2"), "--target-sj", "0.5")
    moved = only_coordinates(su2, w("optimized.su2"), "optimize")
    boundary = set().union(*mk.values())
    check(len(moved) > 0 and not (moved & boundary), "optimize: %d interior points moved, no boundary point" % len(moved))

    return finish()


if __name__ == "__main__":
    sys.exit(main())
