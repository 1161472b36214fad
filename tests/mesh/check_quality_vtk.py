"""Cross-check of cadmorph's scaled Jacobian against VTK's vtkMeshQuality (Verdict).

Reads WORK/quality_vtk_cases.txt written by test_quality_vtk_cases (type, corner coordinates,
our value per line), rebuilds the cells in a vtkUnstructuredGrid, runs vtkMeshQuality with the
scaled Jacobian measure for tets and hexes, and fails if any value differs by more than 1e-9
(relative for the +-1e30 clamps). VTK 9.1's vtkMeshQuality has no wedge scaled Jacobian, so
wedges are checked against the same Verdict build (libvtkverdict's wedge_scaled_jacobian,
called through ctypes) after VTK's mirror to Verdict's numbering; skipped if not found.
Usage: check_quality_vtk.py WORK
"""
import ctypes
import ctypes.util
import glob
import sys

import numpy as np
import vtk

TOL = 1e-9


def load(path):
    cells = {"tet": [], "hex": [], "wedge": []}
    with open(path) as f:
        for line in f:
            t, *v = line.split()
            v = [float(x) for x in v]
            cells[t].append((np.array(v[:-1]).reshape(-1, 3), v[-1]))
    return cells


def vtk_quality(cells, vtk_type, setter):
    pts = vtk.vtkPoints()
    pts.SetDataTypeToDouble()  # the default float32 would cost 1e-7
    grid = vtk.vtkUnstructuredGrid()
    for xyz, _ in cells:
        ids = vtk.vtkIdList()
        for p in xyz:
            ids.InsertNextId(pts.InsertNextPoint(*p))
        grid.InsertNextCell(vtk_type, ids)
    grid.SetPoints(pts)
    q = vtk.vtkMeshQuality()
    q.SetInputData(grid)
    getattr(q, setter)()
    q.Update()
    arr = q.GetOutput().GetCellData().GetArray("Quality")
    return np.array([arr.GetValue(i) for i in range(arr.GetNumberOfTuples())])


def verdict_wedges(cells):
    libs = sorted(glob.glob("/usr/lib/*/libvtkverdict-9.*.so*")) or [ctypes.util.find_library("vtkverdict")]
    for lib in filter(None, libs):
        try:
            L = ctypes.CDLL(lib)
        except OSError:
            continue
        for name in ("vtkverdict__wedge_scaled_jacobian", "wedge_scaled_jacobian"):
            fn = getattr(L, name, None)
            if fn is None:
                continue
            fn.restype = ctypes.c_double
            out = []
            for xyz, _ in cells:
                a = np.ascontiguousarray(xyz[[1, 0, 2, 4, 3, 5]], dtype=np.float64)
                out.append(fn(ctypes.c_int(6), a.ctypes.data_as(ctypes.c_void_p)))
            return np.array(out), lib
    return None, None


def compare(name, ours, ref):
    diff = np.abs(ours - ref) / np.maximum(1.0, np.abs(ref))
    worst = int(np.argmax(diff)) if len(diff) else -1
    print(f"{name}: {len(ours)} cells, {int(np.sum(ref <= 0))} with SJ <= 0 in VTK, "
          f"max |diff| = {diff.max() if len(diff) else 0:.3e}"
          + (f" (cell {worst}: ours {ours[worst]!r}, VTK {ref[worst]!r})" if len(diff) else ""))
    return len(diff) > 0 and diff.max() <= TOL


def main():
    cells = load(sys.argv[1] + "/quality_vtk_cases.txt")
    ok = True
    for name, vtk_type, setter, minimum in (
            ("tet", vtk.VTK_TETRA, "SetTetQualityMeasureToScaledJacobian", 1000),
            ("hex", vtk.VTK_HEXAHEDRON, "SetHexQualityMeasureToScaledJacobian", 1000)):
        ours = np.array([v for _, v in cells[name]])
        if len(ours) < minimum:
            print(f"{name}: only {len(ours)} cells")
            ok = False
            continue
        ok &= compare(name, ours, vtk_quality(cells[name], vtk_type, setter))
    ref, lib = verdict_wedges(cells["wedge"])
    if ref is None:
        print("wedge: libvtkverdict not found, skipped")
    else:
        print(f"wedge: reference {lib}")
        ok &= compare("wedge", np.array([v for _, v in cells["wedge"]]), ref)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
