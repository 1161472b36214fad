"""The CLI on CGNS meshes: the bore model's hex mesh written as a new CGNS file (`cadmorph
model --hex-mesh`), then quality, morph, warp, optimize on it and deform with a constraint on
a BC family of a two-zone file (test_cgns's zones.cgns). Every mesh written from a CGNS input
is that file with other coordinates (cgnsdiff: nothing else differs; cgnscheck: no error); a
warp whose D.csv lists every node with an affine motion writes the affine image.

usage: test_cgns_cli.py CADMORPH WORKDIR   (WORKDIR holds test_cgns's cgns/zones.cgns)
"""
import os
import subprocess
import sys

import h5py
import numpy as np

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def run(*args):
    r = subprocess.run(list(args), capture_output=True, text=True)
    check(r.returncode == 0, " ".join(args[1:3]) + f": exit {r.returncode}: {r.stderr.strip()[-300:]}")
    return r


def coords(path, zone="Base/Zone1"):
    g = h5py.File(path, "r")[zone + "/GridCoordinates"]
    return np.column_stack([g[c][" data"][()] for c in ("CoordinateX", "CoordinateY", "CoordinateZ")])


def only_coordinates_differ(a, b):
    out = subprocess.run(["cgnsdiff", "-d", a, b], capture_output=True, text=True).stdout
    lines = [l for l in out.splitlines() if l.strip()]
    check(lines and all("/GridCoordinates/Coordinate" in l for l in lines), f"cgnsdiff {b}: {lines[:3]}")
    chk = subprocess.run(["cgnscheck", b], capture_output=True, text=True)
    check(chk.returncode == 0 and "ERROR" not in chk.stdout, f"cgnscheck {b}")


def main():
    cli, work = sys.argv[1], sys.argv[2]
    d = os.path.join(work, "cgns_cli")
    os.makedirs(d, exist_ok=True)
    p = lambda n: os.path.join(d, n)
    run(cli, "model", "bore", "0", p("G0.step"), "--hex-mesh", p("M0.cgns"))
    run(cli, "model", "bore", "1", p("G1.step"))
    r = run(cli, "quality", p("M0.cgns"))
    check("cells=30720" in r.stdout, "quality: 30720 hexahedra")
    run(cli, "morph", "--from", p("G0.step"), "--to", p("G1.step"), "--mesh", p("M0.cgns"), "-o", p("M1.cgns"))
    only_coordinates_differ(p("M0.cgns"), p("M1.cgns"))
    # an affine motion of every node
    x = coords(p("M0.cgns"))
    A = np.array([[1.1, 0.2, -0.1], [-0.05, 0.9, 0.1], [0.02, 0.0, 1.2]])
    b = np.array([0.3, -1.0, 2.5])
    want = x @ A.T + b
    with open(p("D.csv"), "w") as f:
        f.write("node,dx,dy,dz\n")
        for i, row in enumerate(want - x):
            f.write("%d,%.17g,%.17g,%.17g\n" % (i, *row))
    run(cli, "warp", "--mesh", p("M0.cgns"), "--displacements", p("D.csv"), "-o", p("W.cgns"))
    only_coordinates_differ(p("M0.cgns"), p("W.cgns"))
    got = coords(p("W.cgns"))
    err = np.abs(got - want).max() / np.abs(want).max()
    check(err < 1e-14, f"warp: the affine image (relative error {err:.3g})")
    run(cli, "optimize", p("M1.cgns"), "-o", p("O.cgns"))
    chk = subprocess.run(["cgnsdiff", "-d", p("M1.cgns"), p("O.cgns")], capture_output=True, text=True).stdout
    check(all("/GridCoordinates/Coordinate" in l for l in chk.splitlines() if l.strip()), "optimize: coordinates only")
    # deform: a BC family ('wall', the floor z = 0 of both zones) kept planar by name
    zones = os.path.join(work, "cgns", "zones.cgns")
    with open(p("H.csv"), "w") as f:
        f.write("node,dx,dy,dz\n26,0,0,0.3\n")
    run(cli, "deform", "--mesh", zones, "--handles", p("H.csv"), "--method", "mls",
        "--constraint", "plane:wall", "-o", p("Z.cgns"))
    only_coordinates_differ(zones, p("Z.cgns"))
    # the floor is bilinear in the file: the (soft) plane constraint flattens it
    def off_plane(path):
        floor = np.concatenate([coords(path, "Base/" + z)[:9] for z in ("left", "right")])
        return np.linalg.svd(floor - floor.mean(axis=0), compute_uv=False)[-1]
    before, after = off_plane(zones), off_plane(p("Z.cgns"))
    check(after < before / 3, f"deform: the wall family flattened ({before:.3g} -> {after:.3g})")
    bad = subprocess.run([cli, "deform", "--mesh", zones, "--handles", p("H.csv"), "--method", "mls",
                          "--constraint", "plane:nosuch", "-o", p("Z2.cgns")], capture_output=True, text=True)
    check(bad.returncode != 0 and "left, wall, inlet, right" in bad.stderr, "deform: the groups listed")
    print(f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
