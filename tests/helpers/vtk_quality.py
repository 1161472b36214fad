"""The scaled Jacobian of a .vtu by VTK's vtkMeshQuality (Verdict), for the cross-checks of
cadmorph's own figures in the study and sweep tests."""
import vtk


def vtk_min_sj(path, cell_types=(vtk.VTK_TETRA, vtk.VTK_HEXAHEDRON)):
    """(min, inverted, cells) of the scaled Jacobian over the cells of those VTK types;
    Verdict's +-1e30 marks a collapsed cell, which cadmorph's summary counts as 0 (inverted)."""
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    grid = r.GetOutput()
    q = vtk.vtkMeshQuality()
    q.SetInputData(grid)
    q.SetTetQualityMeasureToScaledJacobian()
    q.SetHexQualityMeasureToScaledJacobian()
    q.Update()
    arr = q.GetOutput().GetCellData().GetArray("Quality")
    vals = [0.0 if abs(arr.GetValue(i)) >= 1e30 else arr.GetValue(i)
            for i in range(grid.GetNumberOfCells()) if grid.GetCellType(i) in cell_types]
    return min(vals), sum(1 for v in vals if v <= 0), len(vals)
