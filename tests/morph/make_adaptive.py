#!/usr/bin/python3
"""STEP models and gmsh meshes for the adaptive-step tests, written by gmsh's OpenCASCADE kernel
into <work>/adaptive:

  hole_0.step, hole_0.msh   a 4 x 4 x 2 block with a bore of radius 0.5 on the z axis (h 0.2)
  hole_moved.step           the bore moved to x = 1.2: 0.3 from the wall, where one step of
                            the warp inverts cells and smaller steps do not
  tilt_0.step, tilt_0.msh   the same block, coarse (h 0.35)
  tilt_15.step              the bore tilted by 15 degrees: the coarse mesh has a cell with every
                            node on the boundary that the boundary motion itself flattens

usage: make_adaptive.py <work dir>
"""
import math
import os
import sys

import gmsh


def block(path, cx=0.0, tilt=0.0, mesh=None, size=0.2):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("block")
    occ = gmsh.model.occ
    box = occ.addBox(-2, -2, -1, 4, 4, 2)
    a = math.radians(tilt)
    d = (0.0, -4 * math.sin(a), 4 * math.cos(a))
    cyl = occ.addCylinder(cx - d[0] / 2, -d[1] / 2, -d[2] / 2, d[0], d[1], d[2], 0.5)
    occ.cut([(3, box)], [(3, cyl)])
    occ.synchronize()
    gmsh.write(path)
    if mesh:
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        gmsh.model.mesh.generate(3)
        gmsh.write(mesh)
    gmsh.finalize()


def main(work):
    out = os.path.join(work, "adaptive")
    os.makedirs(out, exist_ok=True)
    p = lambda name: os.path.join(out, name)
    block(p("hole_0.step"), mesh=p("hole_0.msh"), size=0.2)
    block(p("hole_moved.step"), cx=1.2)
    block(p("tilt_0.step"), mesh=p("tilt_0.msh"), size=0.35)
    block(p("tilt_15.step"), tilt=15.0)


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
