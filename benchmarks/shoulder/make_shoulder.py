#!/usr/bin/python3
"""The compressed-shoulder case (benchmarks/RESULTS.md, "A compressed shoulder"):
a block 5 x 5 x 3 with a counterbore (radius 1.5, from z = 1.5) over a through bore of radius
r2, written as STEP through gmsh's OpenCASCADE kernel. shoulder_a has r2 = 0.6 (annulus 0.9
wide); shoulder_rR has r2 = R (the annulus compressed (1.5 - 0.6) / (1.5 - R) times).
  make_shoulder.py OUT_DIR [R ...]      (default R: 1.15 1.2 1.25 1.35)"""
import os
import sys

import gmsh


def write(path, r2):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("shoulder")
    occ = gmsh.model.occ
    box = occ.addBox(-2.5, -2.5, 0, 5, 5, 3)
    counterbore = occ.addCylinder(0, 0, 1.5, 0, 0, 2, 1.5)
    bore = occ.addCylinder(0, 0, -1, 0, 0, 5, r2)
    occ.cut([(3, box)], [(3, counterbore), (3, bore)])
    occ.synchronize()
    gmsh.write(path)
    gmsh.finalize()


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    write(os.path.join(out, "shoulder_a.step"), 0.6)
    for r in sys.argv[2:] or ["1.15", "1.2", "1.25", "1.35"]:
        write(os.path.join(out, "shoulder_r%s.step" % r), float(r))


if __name__ == "__main__":
    main()
