#!/usr/bin/python3
"""Cross-checks a mesh written by `cadmorph mesh` with code nobody here wrote.
usage: test_tetmesh_vtk.py MESH.vtu MESH.msh N_FACES
  VTK reads the .vtu: its vtkMeshQuality scaled Jacobian of every tet equals the file's
  scaled_jacobian field (1e-9) and is > 0; gmsh reads the .msh: the same node and tet counts,
  and the boundary triangles carry N_FACES distinct CAD face tags."""
import sys

import gmsh
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy


def main():
    vtu, msh, n_faces = sys.argv[1], sys.argv[2], int(sys.argv[3])
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(vtu)
    r.Update()
    grid = r.GetOutput()
    types = vtk_to_numpy(grid.GetCellTypesArray())
    tets = types == vtk.VTK_TETRA
    q = vtk.vtkMeshQuality()
    q.SetInputData(grid)
    q.SetTetQualityMeasureToScaledJacobian()
    q.Update()
    vq = vtk_to_numpy(q.GetOutput().GetCellData().GetArray("Quality"))[tets]
    ours = vtk_to_numpy(grid.GetCellData().GetArray("scaled_jacobian"))[tets]
    err = np.max(np.abs(vq - ours))
    print(f"vtk: {grid.GetNumberOfPoints()} points, {tets.sum()} tets, min SJ {vq.min():.6g}, "
          f"max |VTK - cadmorph| {err:.3g}")
    ok = err <= 1e-9 and vq.min() > 0

    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(msh)
    node_tags, _, _ = gmsh.model.mesh.getNodes()
    n_tets = sum(len(t) for t in gmsh.model.mesh.getElementsByType(4)[:1])
    faces = {tag for dim, tag in gmsh.model.getEntities(2)
             if len(gmsh.model.mesh.getElements(2, tag)[1])}
    gmsh.finalize()
    print(f"gmsh: {len(node_tags)} nodes, {n_tets} tets, {len(faces)} tagged CAD faces")
    ok = ok and len(node_tags) == grid.GetNumberOfPoints() and n_tets == tets.sum()
    ok = ok and len(faces) == n_faces
    return 0 if ok else 1


sys.exit(main())
