#!/usr/bin/python3
"""Test-time meshes for tests/surface: gmsh -3 on the STEP fixtures of tests/data/surface
(kept small: a few thousand nodes), plus the bad-input variants.
  make_meshes.py DATA_DIR WORK_DIR
writes WORK_DIR/surface/<model>.msh for hole_a holes2_a cyl_a sphere_a cone_a torus_a,
hole_a_metres.msh (the hole_a mesh in metres: the CAD is in millimetres) and cyl_a_o2.msh
(second order: tet10 with mid-edge nodes on the curved boundary), bore_a.msh (of
tests/data/cad/bore_a.step)."""
import os
import subprocess
import sys

SIZES = {"hole_a": 1.0, "holes2_a": 0.9, "cyl_a": 0.9, "sphere_a": 1.0, "cone_a": 0.8,
         "torus_a": 0.8}


def gmsh(args):
    r = subprocess.run(["gmsh", "-v", "1"] + args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("gmsh %s failed: %s%s" % (" ".join(args), r.stdout, r.stderr))


def main(data, work):
    out = os.path.join(work, "surface")
    os.makedirs(out, exist_ok=True)
    for name, h in SIZES.items():
        step = os.path.join(data, "surface", name + ".step")
        gmsh(["-3", step, "-clmax", str(h), "-format", "msh41", "-o",
              os.path.join(out, name + ".msh")])
    gmsh(["-3", os.path.join(data, "surface", "hole_a.step"), "-clmax", "1.0",
          "-setnumber", "Mesh.ScalingFactor", "0.001", "-format", "msh41",
          "-o", os.path.join(out, "hole_a_metres.msh")])
    # the bore of tests/data/cad (sphere-capped boss: sphere, seams, a bore)
    gmsh(["-3", os.path.join(data, "cad", "bore_a.step"), "-clmax", "0.8", "-format", "msh41",
          "-o", os.path.join(out, "bore_a.msh")])
    gmsh(["-3", "-order", "2", os.path.join(data, "surface", "cyl_a.step"), "-clmax", "1.2",
          "-format", "msh41", "-o", os.path.join(out, "cyl_a_o2.msh")])


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
