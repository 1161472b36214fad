#!/usr/bin/python3
"""Cross-check of cadmorph's VTK/Medit I/O against code nobody here wrote.

Usage: test_vtk_crosscheck.py DATA_DIR WORK_DIR   (after test_vtk_io has filled WORK_DIR/vtk)

1. Every fixture cadmorph read (WORK_DIR/vtk/fx_<name>.dump) must hold exactly the points,
   cell types and connectivity (polyhedra: face streams) that VTK 9 reads from the same file
   (Medit files: meshio).
2. Every file cadmorph wrote (WORK_DIR/vtk/rt_*) must load in VTK and, where meshio supports
   the cells, in meshio, with the same points (bit-exact), cells and gmsh:physical tags.
Prints 'N passed, N failed' and exits non-zero on any failure."""
import glob
import os
import sys

import meshio
import numpy as np
import vtk
from vtk.util import numpy_support as ns

passed = failed = 0


def check(cond, what):
    global passed, failed
    if cond:
        passed += 1
    else:
        failed += 1
        print("FAILED:", what)


def read_dump(path):
    with open(path) as f:
        lines = f.read().split("\n")
    n = int(lines[0].split()[1])
    pts = np.array([[float.fromhex(v) for v in lines[1 + i].split()] for i in range(n)]).reshape(n, 3)
    m = int(lines[1 + n].split()[1])
    cells, phys = [], []
    for i in range(m):
        v = [int(x) for x in lines[2 + n + i].split()]
        cells.append((v[0], tuple(v[2:2 + v[1]])))
        phys.append(v[2 + v[1]])
    return pts, cells, phys


def read_vtk(path):
    if path.endswith(".vtu"):
        r = vtk.vtkXMLUnstructuredGridReader()
    else:
        r = vtk.vtkUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    pts = ns.vtk_to_numpy(g.GetPoints().GetData()).astype(np.float64) if g.GetPoints() else np.zeros((0, 3))
    cells = []
    ids = vtk.vtkIdList()
    for i in range(g.GetNumberOfCells()):
        t = g.GetCellType(i)
        if t == vtk.VTK_POLYHEDRON:
            g.GetFaceStream(i, ids)
        else:
            g.GetCellPoints(i, ids)
        cells.append((t, tuple(ids.GetId(k) for k in range(ids.GetNumberOfIds()))))
    return pts, cells, g


WEDGE = [0, 2, 1, 3, 5, 4]  # meshio's wedge is gmsh's prism


def read_meshio(path):
    m = meshio.read(path)
    cells, phys = [], []
    for k, block in enumerate(m.cells):
        t = meshio._vtk_common.meshio_to_vtk_type[block.type]
        for e in block.data:
            e = [int(v) for v in e]
            if block.type == "wedge":
                e = [e[j] for j in WEDGE]
            cells.append((t, tuple(e)))
        for key in ("gmsh:physical", "medit:ref"):
            if key in m.cell_data:
                phys += [int(v) for v in m.cell_data[key][k]]
    return np.asarray(m.points, dtype=np.float64), cells, phys, m


def main():
    data, work = sys.argv[1], os.path.join(sys.argv[2], "vtk")
    dumps = sorted(glob.glob(os.path.join(work, "fx_*.dump")))
    check(len(dumps) >= 15, "test_vtk_io left %d fixture dumps in %s" % (len(dumps), work))
    for d in dumps:
        name = os.path.basename(d)[3:-5]
        path = os.path.join(data, "vtk", name)
        pts, cells, _ = read_dump(d)
        if name.endswith(".mesh"):
            vp, vc, _, _ = read_meshio(path)
        elif name.endswith(".msh"):
            continue
        else:
            vp, vc, _ = read_vtk(path)
        check(vp.shape == pts.shape and np.array_equal(vp, pts), name + ": points differ from VTK/meshio")
        check(vc == cells, name + ": cells differ from VTK/meshio")

    ref = os.path.join(work, "rt_reference.dump")
    check(os.path.exists(ref), "rt_reference.dump exists")
    if os.path.exists(ref):
        pts, cells, phys = read_dump(ref)
        written = sorted(glob.glob(os.path.join(work, "rt_*.vtu")) + glob.glob(os.path.join(work, "rt_*.vtk")))
        written = [w for w in written if "rt_std_" not in w]
        check(len(written) == 7, "7 variants written")
        for w in written:
            vp, vc, g = read_vtk(w)
            name = os.path.basename(w)
            check(np.array_equal(vp, pts), name + ": VTK reads other points")
            check(vc == cells, name + ": VTK reads other cells")
            cd, pd = g.GetCellData(), g.GetPointData()
            a = cd.GetArray("gmsh:physical")
            check(a is not None and [int(a.GetValue(i)) for i in range(a.GetNumberOfTuples())] == phys,
                  name + ": gmsh:physical")
            check(cd.GetArray("scaled_jacobian") is not None, name + ": scaled_jacobian")
            d = pd.GetArray("displacement")
            check(d is not None and d.GetNumberOfComponents() == 3, name + ": displacement")

    std = os.path.join(work, "rt_std.dump")
    check(os.path.exists(std), "rt_std.dump exists")
    if os.path.exists(std):
        pts, cells, phys = read_dump(std)
        for w in sorted(glob.glob(os.path.join(work, "rt_std_*"))):
            name = os.path.basename(w)
            vp, vc, g = read_vtk(w)
            check(np.array_equal(vp, pts) and vc == cells, name + ": VTK")
            mp, mc, mphys, _ = read_meshio(w)
            check(np.array_equal(mp, pts), name + ": meshio points")
            check(sorted(mc) == sorted(cells), name + ": meshio cells")
            check(sorted(zip(mc, mphys)) == sorted(zip(cells, phys)), name + ": meshio gmsh:physical")
        med = os.path.join(work, "rt_medit.mesh")
        mp, mc, mphys, _ = read_meshio(med)
        mpts, mcells, mref = read_dump(os.path.join(work, "rt_medit.dump"))
        check(np.array_equal(mp, mpts) and mc == mcells and mphys == mref, "rt_medit.mesh: meshio")

    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
