#!/usr/bin/python3
"""Meshes and handle tables of the MLS benchmarks ([CMLS]), written with gmsh:
  sphere: a box with a spherical cavity (tets, ~13k nodes; paper section 7.2): outer boundary
          fixed, the cavity's nodes moved as the handle (sphere_H.csv, sphere_F.csv);
  plane:  a square plate (triangles, ~1,100 vertices; paper Figure 3): a central disc lifted,
          the border fixed (plane_H.csv, plane_F.csv).
usage: make_cases.py OUTDIR [sphere_size]"""
import sys, os
import gmsh
import numpy as np

out = sys.argv[1]
os.makedirs(out, exist_ok=True)

def write_tables(prefix, xyz, handle, fixed, disp):
    with open(prefix + "_H.csv", "w") as f:
        f.write("node,dx,dy,dz\n")
        for i in np.nonzero(handle)[0]:
            f.write("%d,%.17g,%.17g,%.17g\n" % (i, *disp))
    with open(prefix + "_F.csv", "w") as f:
        f.write("node\n")
        for i in np.nonzero(fixed)[0]:
            f.write("%d\n" % i)

def nodes_in_file_order():
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    order = np.argsort(tags)
    return xyz.reshape(-1, 3)[order]

# --- sphere: box [0,4]^2 x [0,2] ... a cube of side 4 with a cavity of radius 1 off centre
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("sphere")
box = gmsh.model.occ.addBox(0, 0, 0, 4, 4, 4)
ball = gmsh.model.occ.addSphere(2, 2, 2, 1)
gmsh.model.occ.cut([(3, box)], [(3, ball)])
gmsh.model.occ.synchronize()
size = float(sys.argv[2]) if len(sys.argv) > 2 else 0.24
gmsh.option.setNumber("Mesh.MeshSizeMax", size)
gmsh.option.setNumber("Mesh.MeshSizeMin", size * 0.5)
gmsh.option.setNumber("Mesh.Optimize", 1)
gmsh.model.mesh.generate(3)
gmsh.model.mesh.renumberNodes()
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.option.setNumber("Mesh.SaveAll", 0)
gmsh.model.addPhysicalGroup(3, [v for _, v in gmsh.model.getEntities(3)], 1)
gmsh.write(os.path.join(out, "sphere.msh"))
xyz = nodes_in_file_order()
r = np.linalg.norm(xyz - 2.0, axis=1)
outer = (np.min(xyz, axis=1) < 1e-9) | (np.max(xyz, axis=1) > 4 - 1e-9)
cavity = np.abs(r - 1) < 1e-6
# the paper moves the sphere far: half its radius towards a wall
write_tables(os.path.join(out, "sphere"), xyz, cavity, outer, (0.5, 0.0, 0.0))
print("sphere: %d nodes, %d handle, %d fixed" % (len(xyz), cavity.sum(), outer.sum()))
gmsh.finalize()

# --- plane: unit square, triangles
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("plane")
gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.033)
gmsh.option.setNumber("Mesh.MeshSizeMin", 0.033)
gmsh.model.mesh.generate(2)
gmsh.model.mesh.renumberNodes()
gmsh.model.addPhysicalGroup(2, [s for _, s in gmsh.model.getEntities(2)], 1)
gmsh.write(os.path.join(out, "plane.msh"))
xyz = nodes_in_file_order()
border = (np.min(xyz[:, :2], axis=1) < 1e-9) | (np.max(xyz[:, :2], axis=1) > 1 - 1e-9)
disc = np.linalg.norm(xyz[:, :2] - 0.5, axis=1) < 0.1
write_tables(os.path.join(out, "plane"), xyz, disc, border, (0.0, 0.0, 0.2))
print("plane: %d nodes, %d handle, %d fixed" % (len(xyz), disc.sum(), border.sum()))
gmsh.finalize()
