#!/usr/bin/python3
"""Regenerates the gmsh fixtures of tests/mesh/test_msh.c with the gmsh CLI (gmsh 4.8):
   box_hole_{22,22b,41,41b}.msh  first-order tets + boundary triangles, 4 encodings of one mesh
   hybrid_o2_41.msh              complete 2nd order: hex27, wedge18, pyramid14, tet10 (+ quad9, tri6)
   hybrid_o2i_22b.msh            incomplete 2nd order: hex20, wedge15, pyramid13, tet10 (+ quad8, tri6)
Run from anywhere: /usr/bin/python3 tests/data/msh/generate.py"""
import os
import subprocess

here = os.path.dirname(os.path.abspath(__file__))


def gmsh(*args):
    subprocess.run(["gmsh", *args, "-v", "2"], cwd=here, check=True)


for fmt, binary, name in [("msh22", False, "box_hole_22"), ("msh22", True, "box_hole_22b"),
                          ("msh41", False, "box_hole_41"), ("msh41", True, "box_hole_41b")]:
    gmsh("-3", "box_hole.geo", "-format", fmt, *(["-bin"] if binary else []), "-o", name + ".msh")
gmsh("-3", "hybrid.geo", "-order", "2", "-format", "msh41", "-o", "hybrid_o2_41.msh")
gmsh("-3", "hybrid.geo", "-order", "2", "-setnumber", "Mesh.SecondOrderIncomplete", "1",
     "-format", "msh22", "-bin", "-o", "hybrid_o2i_22b.msh")
