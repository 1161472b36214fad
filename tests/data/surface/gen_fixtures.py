#!/usr/bin/python3
"""Writes the STEP pairs of tests/surface through gmsh's OpenCASCADE kernel (run with Debian's
/usr/bin/python3 from this directory). Each pair is one construction with other dimensions,
so G and G' have the same topology in the same order (checked by the tests):
  hole_a/b      block with a through bore; b: larger radius, centre moved
  hole_rigid    hole_a translated and rotated (a rigid motion of G)
  holes2_a/b    plate whose top face has two holes; b: holes grown and moved, plate longer
  cyl_a/b       cylinder (periodic seam); b: longer, larger radius
  sphere_a/b    ball (poles, seam); b: larger radius, centre moved by half the radius
  cone_a/b      cone with its apex (a singular point); b: taller, wider
  torus_a/b     torus (periodic in u and v, two seams); b: both radii larger, centre moved
Meshes are made at test time by gmsh -3 (tests/surface/make_meshes.py).
"""
import math
import gmsh


def hole(occ, lx, ly, lz, cx, cy, r):
    box = occ.addBox(0, 0, 0, lx, ly, lz)
    cyl = occ.addCylinder(cx, cy, -1, 0, 0, lz + 2, r)
    occ.cut([(3, box)], [(3, cyl)])


def holes2(occ, lx, ly, lz, c1, r1, c2, r2):
    box = occ.addBox(0, 0, 0, lx, ly, lz)
    t1 = occ.addCylinder(c1[0], c1[1], -1, 0, 0, lz + 2, r1)
    t2 = occ.addCylinder(c2[0], c2[1], -1, 0, 0, lz + 2, r2)
    occ.cut([(3, box)], [(3, t1), (3, t2)])


def write(name, build, *args, rigid=False):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    occ = gmsh.model.occ
    build(occ, *args)
    if rigid:
        ents = occ.getEntities(3)
        occ.rotate(ents, 1, 2, 0, 0.3, 0.5, 1.0, 0.7)
        occ.translate(ents, 3.5, -2.0, 1.25)
    occ.synchronize()
    gmsh.write(name + ".step")
    gmsh.finalize()


def cyl(occ, h, r):
    occ.addCylinder(0, 0, 0, 0, 0, h, r)


def sphere(occ, cx, r):
    occ.addSphere(cx, 0, 0, r)


def cone(occ, h, r):
    occ.addCone(0, 0, 0, 0, 0, h, r, 0)


def torus(occ, cx, r1, r2):
    occ.addTorus(cx, 0, 0, r1, r2)


write("hole_a", hole, 10, 8, 4, 5, 4, 2)
write("hole_b", hole, 10, 8, 4, 5.6, 3.7, 2.6)
write("hole_rigid", hole, 10, 8, 4, 5, 4, 2, rigid=True)
write("holes2_a", holes2, 12, 6, 2, (3, 3), 1.2, (9, 3), 1.0)
write("holes2_b", holes2, 13, 6, 2, (3.2, 2.8), 1.5, (9.5, 3.2), 1.3)
write("cyl_a", cyl, 6, 2)
write("cyl_b", cyl, 8, 2.6)
write("sphere_a", sphere, 0, 3)
write("sphere_b", sphere, 1.5, 3.3)
write("cone_a", cone, 4, 2)
write("cone_b", cone, 5, 2.5)
write("torus_a", torus, 0, 4, 1.2)
write("torus_b", torus, 0.5, 4.5, 1.4)
