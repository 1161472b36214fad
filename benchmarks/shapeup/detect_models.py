#!/usr/bin/python3
"""RANSAC's primitives (`cadmorph detect`) against the CAD's face types: each STEP model is
meshed by gmsh (surface, one physical group per CAD face), detected, and compared face by
face. A CAD face of an analytic type (plane, cylinder, sphere, cone) is found when one
primitive of its type holds >= 95 % of its triangles (recall); a primitive is true when >= 95 %
of its triangles lie on one CAD face of its type that no other primitive claims (precision).
usage: detect_models.py CADMORPH OUT STEP... (mesh size: 1/40 of each model's diagonal)"""
import csv, os, subprocess, sys
import numpy as np
import gmsh
import meshio

cad, out = sys.argv[1], sys.argv[2]
os.makedirs(out, exist_ok=True)
rows = []
for step in sys.argv[3:]:
    name = os.path.splitext(os.path.basename(step))[0]
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.occ.importShapes(step)
    gmsh.model.occ.synchronize()
    types = {}
    for d, t in gmsh.model.getEntities(2):
        gmsh.model.addPhysicalGroup(2, [t], t)
        types[t] = gmsh.model.getType(d, t).lower()
    bb = gmsh.model.getBoundingBox(-1, -1)
    diag = np.linalg.norm(np.subtract(bb[3:], bb[:3]))
    gmsh.option.setNumber("Mesh.MeshSizeMax", diag / 40)
    gmsh.model.mesh.generate(2)
    msh = os.path.join(out, name + ".msh")
    gmsh.write(msh)
    gmsh.finalize()
    pcsv, faces = os.path.join(out, name + "_prims.csv"), os.path.join(out, name + "_faces.vtu")
    pr = subprocess.run([cad, "detect", msh, "-o", pcsv, "--faces-out", faces], capture_output=True, text=True)
    if pr.returncode:
        sys.exit(pr.stderr)
    m = meshio.read(msh)
    truth = np.concatenate([np.ravel(d) for c, d in zip(m.cells, m.cell_data["gmsh:physical"]) if c.type == "triangle"])
    got = np.ravel(meshio.read(faces).cell_data["primitive"][0]).astype(int)
    prims = list(csv.DictReader(open(pcsv)))
    analytic = {t: ty for t, ty in types.items() if ty in ("plane", "cylinder", "sphere", "cone")}
    found, claimed = 0, {}
    for tag, ty in analytic.items():
        sel = got[truth == tag]
        ids, cnt = np.unique(sel, return_counts=True)
        k = ids[np.argmax(cnt)]
        if k >= 0 and cnt.max() >= 0.95 * len(sel) and prims[k]["type"] == ty:
            found += 1
    true = 0
    for i, p in enumerate(prims):
        sel = truth[got == i]
        tags, cnt = np.unique(sel, return_counts=True)
        t = tags[np.argmax(cnt)]
        if cnt.max() >= 0.95 * len(sel) and types.get(t) == p["type"] and t not in claimed:
            claimed[t] = i
            true += 1
    other = sorted(set(types.values()) - {"plane", "cylinder", "sphere", "cone"})
    rows.append({"model": name, "triangles": len(truth), "cad_faces": len(types),
                 "analytic_faces": len(analytic), "other_faces": len(types) - len(analytic),
                 "other_types": " ".join(other), "primitives": len(prims),
                 "recall": "%d/%d" % (found, len(analytic)), "precision": "%d/%d" % (true, len(prims)),
                 "detect": pr.stdout.strip()})
    print(rows[-1])
with open(os.path.join(out, "detect_models.csv"), "w") as f:
    w = csv.DictWriter(f, fieldnames=list(rows[0]))
    w.writeheader()
    w.writerows(rows)
