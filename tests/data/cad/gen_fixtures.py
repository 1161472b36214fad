#!/usr/bin/python3
"""Writes the STEP fixtures of tests/cad through gmsh's OpenCASCADE kernel (run with Debian's
/usr/bin/python3 from this directory):
  bore_a.step       block 10 x 8 x 4 mm with a bore of radius 2 and a sphere-capped boss
  bore_b.step       the same model with other dimensions (same topology, same order)
  bore_2holes.step  bore_a with one extra hole (topology differs)
  broken.step       bore_a with its closed shell replaced by a point: parses, cannot transfer
"""
import re
import gmsh


def bore(lx, ly, lz, r, extra_hole=False):
    gmsh.model.add("bore")
    occ = gmsh.model.occ
    block = occ.addBox(0, 0, 0, lx, ly, lz)
    tools = [(3, occ.addCylinder(lx / 2, ly / 2, -1, 0, 0, lz + 2, r))]
    # a sphere-capped boss on top: a sphere face and a cylinder with a seam
    boss = occ.addCylinder(lx * 0.8, ly * 0.75, lz, 0, 0, 1.5, 0.8)
    cap = occ.addSphere(lx * 0.8, ly * 0.75, lz + 1.5, 0.8)
    if extra_hole:
        tools.append((3, occ.addCylinder(lx * 0.2, ly * 0.2, -1, 0, 0, lz + 2, 0.5)))
    out, _ = occ.cut([(3, block)], tools)
    out, _ = occ.fuse(out, [(3, boss), (3, cap)])
    occ.synchronize()


def write(name, *args, **kw):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    bore(*args, **kw)
    gmsh.write(name)
    gmsh.finalize()


write("bore_a.step", 10, 8, 4, 2)
write("bore_b.step", 12, 8.5, 5, 2.6)
write("bore_2holes.step", 10, 8, 4, 2, extra_hole=True)

# Replace the closed shell entity by a cartesian point: the file still parses, but the solid
# refers to an entity of the wrong type and the transfer yields nothing.
text = open("bore_a.step").read()
m = re.search(r"^(#\d+)\s*=\s*CLOSED_SHELL\(.*?\);", text, re.M | re.S)
text = text[:m.start()] + m.group(1) + " = CARTESIAN_POINT('',(0.,0.,0.));" + text[m.end():]
open("broken.step", "w").write(text)
