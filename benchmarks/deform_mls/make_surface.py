#!/usr/bin/python3
"""Large surface case of the MLS scale block ([CMLS §7.1]): a gmsh torus
surface (R = 2, r = 0.6) of triangles; the handle is the cap x > 2.3 (moved by (0, 0, 0.3)),
the fixed region the cap x < -2.3.
usage: make_surface.py OUTDIR SIZE"""
import sys, os
import gmsh
import numpy as np

out, size = sys.argv[1], float(sys.argv[2])
os.makedirs(out, exist_ok=True)
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("torus")
gmsh.model.occ.addTorus(0, 0, 0, 2, 0.6)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", size)
gmsh.option.setNumber("Mesh.MeshSizeMin", size)
gmsh.model.mesh.generate(2)
gmsh.model.mesh.renumberNodes()
gmsh.model.addPhysicalGroup(2, [s for _, s in gmsh.model.getEntities(2)], 1)
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.write(os.path.join(out, "torus.msh"))
tags, xyz, _ = gmsh.model.mesh.getNodes()
xyz = xyz.reshape(-1, 3)[np.argsort(tags)]
h, f = xyz[:, 0] > 2.3, xyz[:, 0] < -2.3
with open(os.path.join(out, "torus_H.csv"), "w") as o:
    o.write("node,dx,dy,dz\n" + "".join("%d,0,0,0.3\n" % i for i in np.nonzero(h)[0]))
with open(os.path.join(out, "torus_F.csv"), "w") as o:
    o.write("node\n" + "".join("%d\n" % i for i in np.nonzero(f)[0]))
print("torus: %d nodes, %d handle, %d fixed" % (len(xyz), h.sum(), f.sum()))
gmsh.finalize()
