#!/usr/bin/env python3
"""Python binding technologies over libcadmorph: the cost of one trivial library call and of
handing out a zero-copy NumPy view of a mesh's points, through cffi in ABI mode (the package
python/cadmorph), ctypes and a pybind11 extension (bench_pybind.cpp, compiled here).

usage: bench_binding.py BUILD_DIR WORK_DIR [MESH]
BUILD_DIR: a build of the repository (libcadmorph.so, build/python); MESH: a mesh file
(default tests/data/msh/box_hole_41.msh). Prints one table row per binding and operation.
"""
import ctypes
import os
import subprocess
import sys
import sysconfig
import timeit

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def per_call(stmt, number):
    """Best of 5 runs, nanoseconds per call."""
    return min(timeit.repeat(stmt, number=number, repeat=5)) / number * 1e9


def build_pybind(build, work):
    ext = sysconfig.get_config_var("EXT_SUFFIX")
    out = os.path.join(work, "cm_pybind" + ext)
    cmd = ["c++", "-O2", "-std=c++17", "-shared", "-fPIC", "-I" + sysconfig.get_paths()["include"],
           "-I" + os.path.join(ROOT, "include"), "-I" + os.path.join(build, "include"),
           os.path.join(HERE, "bench_pybind.cpp"), "-o", out, "-L" + build, "-lcadmorph",
           "-Wl,-rpath," + build]
    subprocess.run(cmd, check=True)
    return cmd


def main():
    if len(sys.argv) not in (3, 4):
        print(__doc__, file=sys.stderr)
        return 1
    build, work = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    mesh_path = sys.argv[3] if len(sys.argv) == 4 else os.path.join(
        ROOT, "tests/data/msh/box_hole_41.msh")
    os.makedirs(work, exist_ok=True)
    sys.path.insert(0, os.path.join(build, "python"))
    sys.path.insert(0, work)
    import cadmorph
    from cadmorph._capi import ffi, lib

    cmd = build_pybind(build, work)
    import cm_pybind

    cdll = ctypes.CDLL(cadmorph._capi.LIBRARY_PATH)
    cdll.cm_mesh_format_list.restype = ctypes.c_char_p

    class CellInfo(ctypes.Structure):
        _fields_ = [("name", ctypes.c_char_p)] + [(n, ctypes.c_int) for n in
                                                  ("dim", "nodes", "corners", "linear", "vtk",
                                                   "gmsh")]
    cdll.cm_cell_type_info.restype = ctypes.POINTER(CellInfo)
    cdll.cm_cell_type_info.argtypes = [ctypes.c_int]

    n = 200000
    rows = []
    rows.append(("cffi ABI", "cm_cell_type_info(tet4).nodes",
                 per_call(lambda: lib.cm_cell_type_info(8).nodes, n)))
    rows.append(("ctypes", "cm_cell_type_info(tet4).nodes",
                 per_call(lambda: cdll.cm_cell_type_info(8).contents.nodes, n)))
    rows.append(("pybind11", "cm_cell_type_info(tet4).nodes",
                 per_call(lambda: cm_pybind.cell_nodes(8), n)))
    rows.append(("cffi ABI", "cm_mesh_format_list() as str",
                 per_call(lambda: ffi.string(lib.cm_mesh_format_list()).decode(), n)))
    rows.append(("ctypes", "cm_mesh_format_list() as str",
                 per_call(lambda: cdll.cm_mesh_format_list().decode(), n)))
    rows.append(("pybind11", "cm_mesh_format_list() as str",
                 per_call(lambda: cm_pybind.format_list(), n)))
    rows.append(("Python", "a no-op Python function (reference)", per_call(lambda: None, n)))

    # zero-copy views of the points
    mesh = cadmorph.read_mesh(mesh_path)
    pm = cm_pybind.Mesh(str(mesh_path))
    m = mesh._owner
    nn = int(m.n_nodes)

    def cffi_frombuffer():
        return np.frombuffer(ffi.buffer(m.xyz, nn * 24), np.float64).reshape(nn, 3)
    checks = {}
    for name, make in (("cffi ABI (Mesh.points, __array_interface__)", lambda: mesh.points),
                       ("cffi ABI (ffi.buffer + np.frombuffer)", cffi_frombuffer),
                       ("pybind11 (py::array_t, base = Mesh)", pm.points)):
        a, b = make(), make()
        a[0, 0] += 1.0
        checks[name] = (np.shares_memory(a, b) and b[0, 0] == a[0, 0] and not a.flags.owndata)
        a[0, 0] -= 1.0
        rows.append((name, "points view of %d nodes" % nn, per_call(make, n // 10)))

    # a real call, for scale: reading the mesh (file I/O and parsing in the library)
    rows.append(("cffi ABI", "read_mesh(%s)" % os.path.basename(mesh_path),
                 per_call(lambda: cadmorph.read_mesh(mesh_path), 200)))
    rows.append(("pybind11", "read_mesh(%s)" % os.path.basename(mesh_path),
                 per_call(lambda: cm_pybind.Mesh(str(mesh_path)), 200)))

    print("exact command: %s %s" % (sys.executable, " ".join(sys.argv)))
    print("pybind11 module: %s" % " ".join(cmd))
    print("| binding | operation | ns per call |")
    print("|---|---|---:|")
    for b, op, t in rows:
        print("| %s | %s | %.0f |" % (b, op, t))
    for name, ok in checks.items():
        print("zero copy (two views share memory, a write shows in the other): %s: %s"
              % (name, "yes" if ok else "NO"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
