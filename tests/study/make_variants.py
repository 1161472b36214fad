#!/usr/bin/python3
"""Writes the variants of the study tests through gmsh's OpenCASCADE kernel (a STEP writer
nobody here wrote), and a gmsh tet mesh of G0. usage: make_variants.py DIR

  DIR/G0.step             block [0,4] x [0,4] x [0,2] minus a bore of radius 0.6 along z
                          through (2, 2)
  DIR/v/v1_r0.70.step ... the same with bore radius 0.7, 0.8, 0.9, 1.0 (v1, v2, v4, v5)
  DIR/v/v3_hole.step      radius 0.8 and a second hole of radius 0.3: another topology
  DIR/M0.msh              gmsh tet mesh of G0 (msh 4.1), element size 0.45
  DIR/list.txt            the five variants as a list file (comments, a blank line, relative
                          paths relative to the list file)
  DIR/bad_missing.txt     a list whose line 3 names a file that does not exist
  DIR/bad_empty.txt       a list of comments and blank lines only
OpenCASCADE's transfer statistics go to /dev/null (they are printed on stdout).
"""
import os
import sys

import gmsh

VARIANTS = [("v1_r0.70", 0.7, False), ("v2_r0.80", 0.8, False), ("v3_hole", 0.8, True),
            ("v4_r0.90", 0.9, False), ("v5_r1.00", 1.0, False)]


def build(radius, hole):
    occ = gmsh.model.occ
    block = occ.addBox(0, 0, 0, 4, 4, 2)
    tools = [(3, occ.addCylinder(2, 2, -1, 0, 0, 4, radius))]
    if hole:
        tools.append((3, occ.addCylinder(3.4, 3.4, -1, 0, 0, 4, 0.3)))
    occ.cut([(3, block)], tools)
    occ.synchronize()


def write(path, radius, hole, mesh=None):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("variant")
    build(radius, hole)
    gmsh.write(path)
    if mesh:
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.45)
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.model.mesh.generate(3)
        gmsh.write(mesh)
    gmsh.finalize()


def main():
    out = os.path.abspath(sys.argv[1])
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.makedirs(os.path.join(out, "v"), exist_ok=True)
    write(os.path.join(out, "G0.step"), 0.6, False, os.path.join(out, "M0.msh"))
    for name, radius, hole in VARIANTS:
        write(os.path.join(out, "v", name + ".step"), radius, hole)
    with open(os.path.join(out, "list.txt"), "w") as f:
        f.write("# bore radius 0.7 .. 1.0, and one variant with another hole\n")
        for name, _, _ in VARIANTS:
            f.write("  v/%s.step   # %s\n" % (name, name) if name == "v3_hole" else "v/%s.step\n" % name)
        f.write("\n")
    with open(os.path.join(out, "bad_missing.txt"), "w") as f:
        f.write("v/v1_r0.70.step\n# the next one is missing\nv/nope.step\n")
    with open(os.path.join(out, "bad_empty.txt"), "w") as f:
        f.write("# nothing but comments\n\n   # and blanks\n")


if __name__ == "__main__":
    main()
