#!/usr/bin/python3
"""Regenerates the VTK / meshio / gmsh fixtures of tests/data/vtk (run from anywhere):
    /usr/bin/python3 tests/data/vtk/generate.py
Files are written by the real tools (VTK 9.1, meshio, gmsh 4.8), never by cadmorph, so the
readers are tested against what those tools produce. Keep the meshes tiny."""
import os
import subprocess

import meshio
import numpy as np
import vtk
from vtk.util import numpy_support as ns

HERE = os.path.dirname(os.path.abspath(__file__))


def mixed_grid():
    """Tet, hex, wedge, pyramid, triangles, a quad, a polyhedron; values that are not exactly
    representable in decimal so that bit-exactness is actually tested."""
    rng = np.random.default_rng(7)
    pts = []
    # hex corners (unit cube, jittered)
    cube = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
    for p in cube:
        pts.append(np.array(p, float) + rng.uniform(-0.05, 0.05, 3))
    apex = np.array([0.5, 0.5, 1.7]) + rng.uniform(-0.05, 0.05, 3)   # 8: pyramid on top
    pts.append(apex)
    pts.append(np.array([2.0, 0.1, 0.0]) + rng.uniform(-0.05, 0.05, 3))  # 9
    pts.append(np.array([2.0, 0.9, 0.0]) + rng.uniform(-0.05, 0.05, 3))  # 10
    pts.append(np.array([2.0, 0.1, 1.0]) + rng.uniform(-0.05, 0.05, 3))  # 11
    pts.append(np.array([2.0, 0.9, 1.0]) + rng.uniform(-0.05, 0.05, 3))  # 12
    pts.append(np.array([0.5, -1.0, 0.5]) + rng.uniform(-0.05, 0.05, 3))  # 13: tet apex
    # polyhedron: a cube (as faces) next to the hex at x in [-1, 0]
    base = len(pts)
    for p in cube:
        pts.append(np.array(p, float) + np.array([-1.2, 0, 0]) + rng.uniform(-0.02, 0.02, 3))
    pts = np.array(pts)
    g = vtk.vtkUnstructuredGrid()
    P = vtk.vtkPoints()
    P.SetDataTypeToDouble()
    for p in pts:
        P.InsertNextPoint(*p)
    g.SetPoints(P)
    cells = [
        (vtk.VTK_HEXAHEDRON, [0, 1, 2, 3, 4, 5, 6, 7]),
        (vtk.VTK_PYRAMID, [4, 5, 6, 7, 8]),
        (vtk.VTK_WEDGE, [1, 9, 2, 5, 11, 6]),
        (vtk.VTK_WEDGE, [2, 9, 10, 6, 11, 12]),
        (vtk.VTK_TETRA, [0, 1, 5, 13]),
        (vtk.VTK_TETRA, [0, 5, 4, 13]),
        (vtk.VTK_TRIANGLE, [0, 1, 13]),
        (vtk.VTK_TRIANGLE, [4, 8, 5]),
        (vtk.VTK_QUAD, [0, 3, 2, 1]),
        (vtk.VTK_LINE, [9, 10]),
        (vtk.VTK_VERTEX, [13]),
    ]
    for t, ids in cells:
        g.InsertNextCell(t, len(ids), ids)
    c = [base + i for i in range(8)]
    faces = [[c[0], c[3], c[2], c[1]], [c[4], c[5], c[6], c[7]], [c[0], c[1], c[5], c[4]],
             [c[1], c[2], c[6], c[5]], [c[2], c[3], c[7], c[6]], [c[3], c[0], c[4], c[7]]]
    stream = [len(faces)]
    for f in faces:
        stream += [len(f)] + f
    ids = vtk.vtkIdList()
    for v in stream:
        ids.InsertNextId(v)
    g.InsertNextCell(vtk.VTK_POLYHEDRON, ids)
    n, m = g.GetNumberOfPoints(), g.GetNumberOfCells()
    def arr(a, name, comps=1):
        v = ns.numpy_to_vtk(np.ascontiguousarray(a), deep=1)
        v.SetName(name)
        v.SetNumberOfComponents(comps)
        return v
    g.GetPointData().AddArray(arr(rng.standard_normal((n, 3)), "displacement", 3))
    g.GetPointData().AddArray(arr(rng.standard_normal(n).astype(np.float32), "temperature"))
    g.GetPointData().AddArray(arr(np.arange(n, dtype=np.int16) - 5, "i16"))
    g.GetCellData().AddArray(arr(rng.uniform(0, 1, m), "scaled_jacobian"))
    g.GetCellData().AddArray(arr(np.arange(m, dtype=np.uint8) * 20, "u8"))
    g.GetCellData().AddArray(arr(np.arange(m, dtype=np.int64) * 10**12, "i64"))
    g.GetCellData().AddArray(arr(np.arange(m, dtype=np.uint32) + 3, "u32"))
    g.GetCellData().AddArray(arr(np.arange(m, dtype=np.int8) - 3, "i8"))
    phys = np.array([1, 1, 2, 2, 3, 3, 10, 11, 12, 0, 0, 4], dtype=np.int32)
    g.GetCellData().AddArray(arr(phys, "gmsh:physical"))
    g.GetCellData().AddArray(arr(phys * 100 + 1, "gmsh:geometrical"))
    return g


def xml(g, name, mode, compress, header64, encode=False, idtype32=False, big=False, block=None):
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(g)
    w.SetFileName(os.path.join(HERE, name))
    {"ascii": w.SetDataModeToAscii, "binary": w.SetDataModeToBinary,
     "appended": w.SetDataModeToAppended}[mode]()
    w.SetEncodeAppendedData(1 if encode else 0)
    if compress:
        w.SetCompressorTypeToZLib()
    else:
        w.SetCompressorTypeToNone()
    if header64:
        w.SetHeaderTypeToUInt64()
    else:
        w.SetHeaderTypeToUInt32()
    if idtype32:
        w.SetIdTypeToInt32()
    if big:
        w.SetByteOrderToBigEndian()
    if block:
        w.SetBlockSize(block)
    assert w.Write() == 1, name


def legacy(g, name, binary):
    w = vtk.vtkUnstructuredGridWriter()
    w.SetInputData(g)
    w.SetFileName(os.path.join(HERE, name))
    if binary:
        w.SetFileTypeToBinary()
    else:
        w.SetFileTypeToASCII()
    assert w.Write() == 1, name


def meshio_mesh():
    """Same standard cells for meshio (no polyhedron, no vertex)."""
    rng = np.random.default_rng(11)
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1],
                    [0, 1, 1], [0.5, 0.5, 1.7], [2, 0.1, 0], [2, 0.9, 0], [2, 0.1, 1], [2, 0.9, 1],
                    [0.5, -1, 0.5]], float) + rng.uniform(-0.05, 0.05, (14, 3))
    cells = [("hexahedron", [[0, 1, 2, 3, 4, 5, 6, 7]]), ("pyramid", [[4, 5, 6, 7, 8]]),
             # meshio's wedge is gmsh's prism: (0,1,2) wound against VTK's
             ("wedge", [[1, 2, 9, 5, 6, 11], [2, 10, 9, 6, 12, 11]]),
             ("tetra", [[0, 1, 5, 13], [0, 5, 4, 13]]), ("triangle", [[0, 1, 13], [4, 8, 5]]),
             ("quad", [[0, 3, 2, 1]])]
    phys = [np.array([1]), np.array([2]), np.array([3, 3]), np.array([4, 4]), np.array([10, 11]),
            np.array([12])]
    return meshio.Mesh(pts, cells,
                       point_data={"displacement": rng.standard_normal((14, 3))},
                       cell_data={"scaled_jacobian": [rng.uniform(0, 1, len(c[1])) for c in cells],
                                  "medit:ref": phys})


GEO = """// three small blocks: extruded recombined (hexes), extruded triangles (prisms), free tets
SetFactory("Built-in");
Mesh.CharacteristicLengthMax = 0.5;
Point(1) = {0, 0, 0}; Point(2) = {1, 0, 0}; Point(3) = {1, 1, 0}; Point(4) = {0, 1, 0};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Transfinite Surface{1}; Recombine Surface{1};
Transfinite Curve{1, 2, 3, 4} = 3;
hex[] = Extrude {0, 0, 1} { Surface{1}; Layers{2}; Recombine; };
Point(101) = {2, 0, 0}; Point(102) = {3, 0, 0}; Point(103) = {3, 1, 0}; Point(104) = {2, 1, 0};
Line(101) = {101, 102}; Line(102) = {102, 103}; Line(103) = {103, 104}; Line(104) = {104, 101};
Curve Loop(101) = {101, 102, 103, 104}; Plane Surface(101) = {101};
pri[] = Extrude {0, 0, 1} { Surface{101}; Layers{2}; Recombine; };
Point(201) = {4, 0, 0}; Point(202) = {5, 0, 0}; Point(203) = {5, 1, 0}; Point(204) = {4, 1, 0};
Line(201) = {201, 202}; Line(202) = {202, 203}; Line(203) = {203, 204}; Line(204) = {204, 201};
Curve Loop(201) = {201, 202, 203, 204}; Plane Surface(201) = {201};
tet[] = Extrude {0, 0, 1} { Surface{201}; };
Physical Volume("hexes", 1) = {hex[1]};
Physical Volume("prisms", 2) = {pri[1]};
Physical Volume("tets", 3) = {tet[1]};
Physical Surface("bottom", 10) = {1, 101, 201};
"""


def gmsh_files():
    geo = os.path.join(HERE, "blocks.geo")
    with open(geo, "w") as f:
        f.write(GEO)
    for fmt, ext, extra in (("mesh", "mesh", []), ("vtk", "vtk", []), ("msh41", "msh", [])):
        out = os.path.join(HERE, "gmsh_blocks." + ext)
        subprocess.run(["gmsh", "-3", geo, "-format", fmt, "-o", out] + extra, check=True,
                       stdout=subprocess.DEVNULL)


def bad_files(g):
    """Broken copies of the fixtures above, one defect each, for the error-path tests
    (tests/mesh/test_vtk_errors.c and tests/cli/bad_input_vtk.cmake)."""
    import base64
    import re
    import struct
    import zlib
    out = os.path.join(HERE, "bad")
    os.makedirs(out, exist_ok=True)
    # valid, but a compressor cadmorph does not read (clear "unsupported" error)
    w = vtk.vtkXMLUnstructuredGridWriter()
    w.SetInputData(g)
    w.SetFileName(os.path.join(out, "lz4.vtu"))
    w.SetDataModeToBinary()
    w.SetCompressorTypeToLZ4()
    assert w.Write() == 1
    def rd(name):
        with open(os.path.join(HERE, name), "rb") as f:
            return f.read()
    def wr(name, data):
        with open(os.path.join(out, name), "wb") as f:
            f.write(data)
    def sub1(data, pattern, repl):
        new, n = re.subn(pattern, repl, data, count=1, flags=re.S)
        assert n == 1, pattern
        return new
    raw = rd("vtk_appended_raw_zlib_u64.vtu")
    wr("truncated_appended.vtu", raw[: int(len(raw) * 0.7)])
    inline = rd("vtk_binary_u64.vtu")
    i = inline.index(b'Name="Points"')
    wr("truncated_inline.vtu", inline[: i + 300])
    # a character outside the base64 alphabet inside the Points data
    j = inline.index(b">", i) + 30
    wr("bad_base64.vtu", inline[:j] + b"!" + inline[j + 1:])
    # corrupt the first zlib block of the Points array (after its 3+nb UInt64 header words)
    head = raw[: raw.index(b"_", raw.index(b"<AppendedData")) + 1]
    start = len(head)
    off = int(re.search(rb'Name="Points"[^>]*offset="(\d+)"', raw).group(1))
    nb = struct.unpack_from("<Q", raw, start + off)[0]
    k = start + off + 8 * (3 + nb) + 4
    wr("bad_zlib.vtu", raw[:k] + bytes(b ^ 0x5A for b in raw[k:k + 8]) + raw[k + 8:])
    # compression headers that would overflow or over-allocate if trusted
    h = bytearray(raw)
    struct.pack_into("<Q", h, start + off + 8, 2**62)  # block size
    wr("huge_block.vtu", bytes(h))
    h = bytearray(raw)
    struct.pack_into("<Q", h, start + off, 2**40)  # block count
    wr("huge_nblocks.vtu", bytes(h))
    asc = rd("vtk_ascii.vtu")
    wr("wrong_npoints.vtu", sub1(asc, rb'NumberOfPoints="22"', b'NumberOfPoints="23"'))
    conn = asc.index(b'Name="connectivity"')
    j = asc.index(b">", conn) + 1
    wr("node_out_of_range.vtu", asc[:j] + sub1(asc[j:], rb"^(\s*)0 ", rb"\g<1>999 "))
    ty = asc.index(b'Name="types"')
    j = asc.index(b">", ty) + 1
    wr("unknown_type.vtu", asc[:j] + sub1(asc[j:], rb"^(\s*)12 ", rb"\g<1>99 "))
    pt = asc.index(b'Name="Points"')
    j = asc.index(b">", pt) + 1
    wr("nan.vtu", asc[:j] + sub1(asc[j:], rb"^(\s*)\S+", rb"\g<1>nan"))
    wr("not_xml.vtu", b"this is not a VTK file\n")
    leg = rd("vtk_legacy_ascii.vtk")
    wr("node_out_of_range.vtk", sub1(leg, rb"(CONNECTIVITY vtktypeint64\n)0 ", rb"\g<1>999 "))
    wr("unknown_type.vtk", sub1(leg, rb"(CELL_TYPES 12\n)12\n", rb"\g<1>99\n"))
    wr("nan.vtk", sub1(leg, rb"(POINTS 22 double\n)\S+", rb"\g<1>nan"))
    wr("wrong_npoints.vtk", sub1(leg, rb"POINTS 22 double", b"POINTS 23 double"))
    legb = rd("vtk_legacy_binary.vtk")
    wr("truncated_binary.vtk", legb[: legb.index(b"CONNECTIVITY") + 60])
    med = rd("meshio.mesh")
    wr("truncated.mesh", med[: med.index(b"Tetrahedra") + 20])
    wr("node_out_of_range.mesh", sub1(med, rb"(Hexahedra\n1\n)1 ", rb"\g<1>99 "))
    wr("nan.mesh", sub1(med, rb"(Vertices\n14\n)\S+", rb"\g<1>nan"))
    wr("wrong_count.mesh", sub1(med, rb"Vertices\n14\n", b"Vertices\n15\n"))
    wr("unknown.xyz", b"1 2 3\n")


def main():
    g = mixed_grid()
    xml(g, "vtk_ascii.vtu", "ascii", False, False)
    xml(g, "vtk_binary_u32.vtu", "binary", False, False)
    xml(g, "vtk_binary_u64.vtu", "binary", False, True)
    xml(g, "vtk_binary_zlib_u32.vtu", "binary", True, False, block=256)
    xml(g, "vtk_binary_zlib_u64.vtu", "binary", True, True)
    xml(g, "vtk_appended_raw_u32.vtu", "appended", False, False, idtype32=True)
    xml(g, "vtk_appended_raw_zlib_u64.vtu", "appended", True, True, block=128)
    xml(g, "vtk_appended_b64_u32.vtu", "appended", False, False, encode=True)
    xml(g, "vtk_appended_b64_zlib_u64.vtu", "appended", True, True, encode=True, block=200)
    xml(g, "vtk_bigendian.vtu", "binary", False, False, big=True)
    legacy(g, "vtk_legacy_ascii.vtk", False)
    legacy(g, "vtk_legacy_binary.vtk", True)
    m = meshio_mesh()
    meshio.write(os.path.join(HERE, "meshio_binary.vtu"), m, file_format="vtu", binary=True)
    meshio.write(os.path.join(HERE, "meshio_ascii.vtu"), m, file_format="vtu", binary=False)
    meshio.write(os.path.join(HERE, "meshio_raw.vtu"), m, file_format="vtu", binary=True,
                 compression=None)
    meshio.write(os.path.join(HERE, "meshio_binary.vtk"), m, file_format="vtk", binary=True)
    meshio.write(os.path.join(HERE, "meshio_ascii.vtk"), m, file_format="vtk", binary=False)
    from meshio.vtk import _vtk_42  # the classic CELLS n size layout
    _vtk_42.write(os.path.join(HERE, "meshio_42.vtk"), m, binary=True)
    meshio.write(os.path.join(HERE, "meshio.mesh"), m, file_format="medit")
    gmsh_files()
    bad_files(g)


if __name__ == "__main__":
    main()
