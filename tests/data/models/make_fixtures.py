#!/usr/bin/python3
"""Writes the STEP fixtures of the tet meshing tests through gmsh's OpenCASCADE kernel (an
independent writer: cadmorph's own models come from cad/models.cpp). Run with Debian's
/usr/bin/python3 from this directory:
  bore_0.step  the bore benchmark model at t = 0: block [-2,2] x [-2,2] x [0,2] minus a
               cylinder of radius 0.6 along z through its centre
  sheet.step   a single 2 x 1 rectangle: faces, but no solid
"""
import gmsh


def write(name, build):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)
    build(gmsh.model.occ)
    gmsh.model.occ.synchronize()
    gmsh.write(name + ".step")
    gmsh.finalize()


def bore(occ):
    block = occ.addBox(-2, -2, 0, 4, 4, 2)
    occ.cut([(3, block)], [(3, occ.addCylinder(0, 0, -1, 0, 0, 4, 0.6))])


def sheet(occ):
    occ.addRectangle(0, 0, 0, 2, 1)


write("bore_0", bore)
write("sheet", sheet)
