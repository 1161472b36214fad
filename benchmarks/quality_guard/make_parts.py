#!/usr/bin/python3
"""Two parts written by gmsh's OpenCASCADE kernel (another CAD tool than ours) for the mesher
figures: a flange (disc with a hub, a bore and six bolt holes) and an L bracket with a fillet
and two holes. usage: make_parts.py OUT_DIR"""
import math
import os
import sys

import gmsh


def flange(path):
    occ = gmsh.model.occ
    disc = occ.addCylinder(0, 0, 0, 0, 0, 0.4, 3.0)
    hub = occ.addCylinder(0, 0, 0.4, 0, 0, 1.0, 1.4)
    body = occ.fuse([(3, disc)], [(3, hub)])[0]
    holes = [(3, occ.addCylinder(0, 0, -1, 0, 0, 3, 0.8))]
    for k in range(6):
        a = 2 * math.pi * k / 6
        holes.append((3, occ.addCylinder(2.2 * math.cos(a), 2.2 * math.sin(a), -1, 0, 0, 3, 0.25)))
    occ.cut(body, holes)


def bracket(path):
    occ = gmsh.model.occ
    base = occ.addBox(0, 0, 0, 4, 2, 0.4)
    wall = occ.addBox(0, 0, 0, 0.4, 2, 3)
    body = occ.fuse([(3, base)], [(3, wall)])[0]
    occ.synchronize()
    # the inner edge of the L, along y at x = z = 0.4
    inner = [e for (d, e) in gmsh.model.getEntities(1)
             if abs(gmsh.model.occ.getCenterOfMass(1, e)[0] - 0.4) < 1e-6
             and abs(gmsh.model.occ.getCenterOfMass(1, e)[2] - 0.4) < 1e-6]
    body = occ.fillet([v for (d, v) in body], inner, [0.3])
    holes = [(3, occ.addCylinder(2.8, 1.0, -1, 0, 0, 3, 0.35)),
             (3, occ.addCylinder(-1, 1.0, 2.0, 3, 0, 0, 0.35))]
    occ.cut(body, holes)


def main(out):
    for name, build in (("gmsh_flange", flange), ("gmsh_bracket", bracket)):
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add(name)
        build(name)
        gmsh.model.occ.synchronize()
        gmsh.write(os.path.join(out, name + ".step"))
        gmsh.finalize()


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
