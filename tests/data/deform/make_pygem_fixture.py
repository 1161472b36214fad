#!/usr/bin/python3
"""Makes the PyGeM cross-check fixture of tests/deform/test_ffd_pygem.c (not run by ctest).

PyGeM (mathLab/PyGeM, MIT, read and run at commit b482f27, version 2.0.0) is run from a
checkout on PYTHONPATH with Debian's numpy/scipy (and python3-matplotlib, which pygem/__init__
imports); none of its code is in this repository:

    PYTHONPATH=/path/to/PyGeM /usr/bin/python3 make_pygem_fixture.py tests/data/deform

For each case it writes <case>.prm with FFD.write_parameters (so the fixture also tests our
.prm reader on PyGeM's own output) and <case>.csv: x,y,z then PyGeM's deformed x',y',z' for
points inside the box (away from its faces: PyGeM's strict inside test drops points at
s = 1 + 4e-16, its bug #272) and some outside (unchanged). Values are written with repr, so
the stored numbers are PyGeM's doubles exactly.
"""
import os
import sys

import numpy as np
from pygem import FFD

CASES = [
    # name, control points, origin, lengths, angles (deg), mu scale
    ("bern444_rot", [4, 4, 4], [0.3, -0.2, 0.5], [2.0, 1.5, 1.0], [10.0, 20.0, 30.0], 0.1),
    ("bern333_rot", [3, 3, 3], [-1.0, 0.5, 0.25], [1.0, 2.0, 0.5], [-35.0, 5.0, 60.0], 0.15),
    ("bern222", [2, 2, 2], [0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [0.0, 0.0, 0.0], 0.2),
    ("bern534_rot", [5, 3, 4], [2.0, -1.0, 0.0], [3.0, 1.0, 2.0], [0.0, 45.0, 0.0], 0.05),
]


def make(outdir, name, n, origin, length, angle, scale, rng):
    ffd = FFD(n)
    ffd.box_origin = np.array(origin)
    ffd.box_length = np.array(length)
    ffd.rot_angle = np.array(angle)
    ffd.array_mu_x = scale * rng.standard_normal(n)
    ffd.array_mu_y = scale * rng.standard_normal(n)
    ffd.array_mu_z = scale * rng.standard_normal(n)
    # a few exact zeros, so that the file has omitted-looking lines too
    ffd.array_mu_x[0, 0, 0] = 0.0
    prm = os.path.join(outdir, name + ".prm")
    ffd.write_parameters(prm)
    # re-read what PyGeM wrote (write_parameters rounds nothing, but be sure the fixture is
    # the file's parameters, not the in-memory ones)
    ffd2 = FFD()
    ffd2.read_parameters(prm)
    # points: 150 inside (local s in [0.02, 0.98]^3), 30 outside (some coordinate beyond)
    s_in = rng.uniform(0.02, 0.98, size=(150, 3))
    s_out = rng.uniform(-0.5, 1.5, size=(60, 3))
    s_out = s_out[np.any((s_out < -0.05) | (s_out > 1.05), axis=1)][:30]
    s = np.vstack([s_in, s_out])
    a = ffd2.rotation_matrix.dot(np.diag(ffd2.box_length))
    x = ffd2.box_origin + s.dot(a.T)
    y = ffd2(x)
    with open(os.path.join(outdir, name + ".csv"), "w") as f:
        f.write("x,y,z,xd,yd,zd\n")
        for p, q in zip(x, y):
            f.write(",".join(repr(float(v)) for v in list(p) + list(q)) + "\n")
    moved = np.abs(y - x).max()
    print("%s: %d points, max |d| %.3g" % (name, len(x), moved))


def main():
    outdir = sys.argv[1] if len(sys.argv) > 1 else "."
    rng = np.random.default_rng(20261201)
    for c in CASES:
        make(outdir, *c, rng)


if __name__ == "__main__":
    main()
