"""Generates the fixtures of `cadmorph quality` tests (run with /usr/bin/python3 from anywhere):

box_tets.vtu   gmsh tet mesh of a 1 x 1 x 0.5 box (meshio-written VTU, with the boundary
               triangles too), one tet turned inside out (two nodes swapped) so that the
               report has an inverted cell.
mixed.vtu      one hex, one VTK wedge and one pyramid sharing faces (hand-written).

Prints the summary line that VTK's vtkMeshQuality (Verdict) gives for box_tets.vtu; the
expected line in tests/cli/quality.cmake comes from this output.
"""
import os

import gmsh
import meshio
import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

HERE = os.path.dirname(os.path.abspath(__file__))


def box_tets(path):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add("box")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 0.5)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.25)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    gmsh.model.mesh.generate(3)
    msh = path + ".tmp.msh"
    gmsh.write(msh)
    gmsh.finalize()
    m = meshio.read(msh)
    os.remove(msh)
    cells = []
    for block in m.cells:
        if block.type in ("tetra", "triangle"):
            cells.append((block.type, block.data.copy()))
    for t, data in cells:
        if t == "tetra":
            data[len(data) // 2, [1, 2]] = data[len(data) // 2, [2, 1]]  # one inverted tet
    meshio.write(path, meshio.Mesh(m.points, cells), binary=False)


def mixed(path):
    s = np.sqrt(3) / 2
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1],
                    [1.5, 0.5, 0.5],                       # pyramid apex on the x=1 face
                    [0, 1 + s, 0], [0, 1 + s, 1]], float)  # wedge on the y=1 face
    cells = [("hexahedron", np.array([[0, 1, 2, 3, 4, 5, 6, 7]])),
             ("pyramid", np.array([[1, 2, 6, 5, 8]])),
             ("wedge", np.array([[3, 2, 9, 7, 6, 10]]))]
    meshio.write(path, meshio.Mesh(pts, cells), binary=False)


def vtk_summary(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    q = vtk.vtkMeshQuality()
    q.SetInputData(r.GetOutput())
    q.SetTetQualityMeasureToScaledJacobian()
    q.Update()
    out = q.GetOutput()
    v = vtk_to_numpy(out.GetCellData().GetArray("Quality"))
    types = np.array([out.GetCellType(i) for i in range(out.GetNumberOfCells())])
    v = v[types == vtk.VTK_TETRA]
    print(f"{os.path.basename(path)}: min_scaled_jacobian={v.min():.6g} "
          f"mean_scaled_jacobian={v.mean():.6g} inverted={int(np.sum(v <= 0))} cells={len(v)}")


if __name__ == "__main__":
    box_tets(os.path.join(HERE, "box_tets.vtu"))
    mixed(os.path.join(HERE, "mixed.vtu"))
    vtk_summary(os.path.join(HERE, "box_tets.vtu"))
