#!/usr/bin/python3
"""Where a morph of the car case broke it: the cells whose Verdict scaled Jacobian is <= 0 in
the morphed .vtu (cadmorph's cell field scaled_jacobian) but > 0 in the input .vtu, located by
their centre: height, distance to the nearest body node, whether every node of the cell is
within one layer-cell thickness of the body (a boundary-layer cell), the displacement there.
usage: locate_bad.py INPUT.vtu MORPHED.vtu BODY_NODES.csv [HANDLES.csv]"""
import sys

import numpy as np
from scipy.spatial import cKDTree
import vtk
from vtk.util.numpy_support import vtk_to_numpy


def read(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    return r.GetOutput()


g0, g1 = read(sys.argv[1]), read(sys.argv[2])
sj0 = vtk_to_numpy(g0.GetCellData().GetArray("scaled_jacobian"))
sj1 = vtk_to_numpy(g1.GetCellData().GetArray("scaled_jacobian"))
x0 = vtk_to_numpy(g0.GetPoints().GetData())
x1 = vtk_to_numpy(g1.GetPoints().GetData())
body = np.loadtxt(sys.argv[3], skiprows=1, dtype=np.int64, ndmin=1)
handles = np.loadtxt(sys.argv[4], delimiter=",", skiprows=1, ndmin=2)[:, 0].astype(np.int64) if len(sys.argv) > 4 else []
bad = np.nonzero((sj1 <= 0) & (sj0 > 0))[0]
print("cells %d; SJ<=0 in the input %d, in the morphed mesh %d, new %d" % (len(sj0), (sj0 <= 0).sum(), (sj1 <= 0).sum(), len(bad)))
tree = cKDTree(x0[body])
htree = cKDTree(x0[handles]) if len(handles) else None
disp = np.linalg.norm(x1 - x0, axis=1)
rows = []
for c in bad:
    ids = vtk.vtkIdList()
    g0.GetCellPoints(int(c), ids)
    pts = np.array([ids.GetId(i) for i in range(ids.GetNumberOfIds())])
    ctr = x0[pts].mean(axis=0)
    dmin = tree.query(x0[pts])[0]
    dh = htree.query(ctr)[0] if htree else np.nan
    rows.append((c, ctr[0], ctr[1], ctr[2], dmin.max(), tree.query(ctr)[0], dh, disp[pts].max(), sj1[c]))
rows = np.array(rows) if rows else np.zeros((0, 9))
if len(rows):
    print("centres: x %.3f..%.3f  y %.3f..%.3f  z %.3f..%.3f" % (rows[:, 1].min(), rows[:, 1].max(), rows[:, 2].min(), rows[:, 2].max(), rows[:, 3].min(), rows[:, 3].max()))
    for q in (0, 0.5, 0.9, 1):
        print("quantile %.1f: distance of the farthest node to the body %.4g, centre to the body %.4g, to a handle %.4g, largest node displacement %.4g"
              % (q, np.quantile(rows[:, 4], q), np.quantile(rows[:, 5], q), np.quantile(rows[:, 6], q), np.quantile(rows[:, 7], q)))
    print("largest displacement of a node: %.4g (node %d at %s)" % (disp.max(), disp.argmax(), x0[disp.argmax()]))
    print("worst 10: cell, centre, farthest node to body, centre to body, to handle, max disp, SJ")
    for r in rows[np.argsort(rows[:, 8])][:10]:
        print("  %d (%.3f %.3f %.3f) %.4g %.4g %.4g %.4g %.3g" % tuple(r))
