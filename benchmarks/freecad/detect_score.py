"""`cadmorph detect` on a gmsh surface mesh of a STEP part scored against the CAD face types
: each triangle's CAD face is its gmsh surface tag, whose type gmsh reports.
usage: detect_score.py CADMORPH G.step OUT_PREFIX
Per triangle: precision = triangles labelled with the type of their CAD face / labelled
triangles; recall = the same / triangles of plane, cylinder, sphere or cone faces. Per CAD face
(of those types): found when one primitive of the right type covers >= 90 % of its triangles."""
import subprocess
import sys
import gmsh
import meshio
import numpy as np
from scipy.spatial import cKDTree

cm, step, out = sys.argv[1:4]
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.occ.importShapes(step)
gmsh.model.occ.synchronize()
lo = np.array(gmsh.model.getBoundingBox(-1, -1))
diag = np.linalg.norm(lo[3:] - lo[:3])
gmsh.option.setNumber("Mesh.MeshSizeMax", diag / 40)
gmsh.model.mesh.generate(2)
names = {"Plane": "plane", "Cylinder": "cylinder", "Sphere": "sphere", "Cone": "cone"}
cen, ftype, ftag = [], [], []
for dim, tag in gmsh.model.getEntities(2):
    kind = names.get(gmsh.model.getType(dim, tag), gmsh.model.getType(dim, tag))
    _, elems, nodes = gmsh.model.mesh.getElements(2, tag)
    nt, xyz, _ = gmsh.model.mesh.getNodes()
    pos = dict(zip(nt, xyz.reshape(-1, 3)))
    for tri in np.asarray(nodes[0]).reshape(-1, 3):
        cen.append(np.mean([pos[n] for n in tri], axis=0))
        ftype.append(kind)
        ftag.append(tag)
gmsh.write(out + "_surf.msh")
gmsh.finalize()
cen = np.array(cen)
subprocess.run([cm, "detect", out + "_surf.msh", "-o", out + ".csv", "--faces-out", out + "_faces.vtu",
                "--threads", "1"], check=True, stdout=subprocess.DEVNULL)
prim_type = {}
for line in open(out + ".csv").read().splitlines()[1:]:
    f = line.split(",")
    prim_type[int(f[0])] = f[1]
fo = meshio.read(out + "_faces.vtu")
tris = [c for c in fo.cells if c.type == "triangle"][0].data
label = np.concatenate([d for c, d in zip(fo.cells, fo.cell_data["primitive"]) if c.type == "triangle"]).ravel()
bc = fo.points[tris].mean(axis=1)
dist, idx = cKDTree(cen).query(bc)
assert dist.max() < 1e-6 * diag, "faces-out triangles do not match the gmsh mesh"
ttype = np.array(ftype)[idx]
ttag = np.array(ftag)[idx]
ptype = np.array([prim_type.get(int(k), "none") for k in label])
labelled = label >= 0
detectable = np.isin(ttype, list(names.values()))
right = labelled & (ptype == ttype)
found, total = 0, 0
for tag in np.unique(ttag[detectable]):
    sel = ttag == tag
    total += 1
    ids, counts = np.unique(label[sel], return_counts=True)
    best = ids[np.argmax(counts)]
    if best >= 0 and prim_type[int(best)] == ttype[sel][0] and counts.max() >= 0.9 * sel.sum():
        found += 1
print("triangles %d, primitives %d (%s), CAD faces %s; precision %.3f recall %.3f; CAD faces found %d of %d"
      % (len(tris), len(prim_type), " ".join(sorted(set(prim_type.values()))),
         " ".join("%s:%d" % (t, len(set(ttag[ttype == t]))) for t in sorted(set(ttype))),
         right.sum() / max(labelled.sum(), 1), right.sum() / max(detectable.sum(), 1), found, total))
