"""CGNS files written back change GridCoordinates' data only (docs/DESIGN.md, "Writing back
into the file a mesh came from"): the pairs <name>.cgns / <name>_moved.cgns that test_cgns left
in the work directory are compared node by node. HDF5 files with h5py (every group, attribute
and dataset identical except the " data" of GridCoordinates/Coordinate*, whose shape and dtype
are kept), both HDF5 and ADF files with CGNS's own cgnsdiff (only the coordinates' data
differ) and cgnscheck (no error). A new file that cadmorph writes (tetrahedra and boundary
groups) is checked by cgnscheck and read by meshio (which reads a tetrahedra-only zone).

usage: test_cgns_tree.py CADMORPH WORKDIR
"""
import os
import shutil
import subprocess
import sys

import h5py
import numpy as np

failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def is_coordinate(path):
    parts = path.strip("/").split("/")
    return (len(parts) >= 3 and parts[-1] == " data" and parts[-3] == "GridCoordinates"
            and parts[-2].startswith("Coordinate"))


def compare_h5(a_path, b_path):
    a, b = h5py.File(a_path, "r"), h5py.File(b_path, "r")
    names_a, names_b = [], []
    a.visit(names_a.append)
    b.visit(names_b.append)
    check(names_a == names_b, f"{b_path}: the same nodes in the same order")
    moved = 0
    for n in names_a:
        x, y = a[n], b.get(n)
        if y is None:
            continue
        check(dict(x.attrs) .keys() == dict(y.attrs).keys(), f"{n}: attributes")
        for k in x.attrs:
            check(np.array_equal(np.asarray(x.attrs[k]), np.asarray(y.attrs[k])), f"{n}: attribute {k}")
        if isinstance(x, h5py.Dataset):
            check(x.dtype == y.dtype and x.shape == y.shape, f"{n}: dtype and shape kept")
            if is_coordinate("/" + n):
                moved += not np.array_equal(x[()], y[()])
            else:
                check(np.array_equal(x[()], y[()]), f"{n}: data unchanged")
    check(moved > 0, f"{b_path}: the coordinates moved")


def cgnsdiff_only_coordinates(a_path, b_path):
    out = subprocess.run(["cgnsdiff", "-d", a_path, b_path], capture_output=True, text=True)
    lines = [l for l in out.stdout.splitlines() if l.strip()]
    check(lines, f"cgnsdiff {b_path}: some difference")
    for l in lines:
        check("/GridCoordinates/Coordinate" in l and "data values differ" in l, f"cgnsdiff: {l}")


def cgnscheck_clean(path):
    out = subprocess.run(["cgnscheck", path], capture_output=True, text=True)
    check(out.returncode == 0 and "ERROR" not in out.stdout, f"cgnscheck {path}: {out.stdout[-500:]}")


def independent_writers(cli, work):
    """A gmsh tet mesh through CGNS's own tetgen_to_cgns, read by cadmorph (gmsh's Debian
    build has no CGNS writer); meshio's .cgns (HDF5 without CGNS labels) refused clearly."""
    import gmsh
    import meshio

    gmsh.initialize()
    gmsh.option.setNumber("General.Verbosity", 1)
    gmsh.model.occ.addBox(0, 0, 0, 1, 2, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.4)
    gmsh.model.mesh.generate(3)
    _, x, _ = gmsh.model.mesh.getNodes()
    x = np.asarray(x).reshape(-1, 3)
    _, _, conn = gmsh.model.mesh.getElements(3)
    tets = np.asarray(conn[0], dtype=np.int64).reshape(-1, 4) - 1  # gmsh tags are 1..n here
    gmsh.finalize()
    base = os.path.join(work, "tg")
    with open(base + ".node", "w") as f:
        f.write(f"{len(x)} 3 0 0\n")
        f.writelines(f"{i + 1} {p[0]!r} {p[1]!r} {p[2]!r}\n" for i, p in enumerate(x))
    with open(base + ".ele", "w") as f:
        f.write(f"{len(tets)} 4 0\n")
        f.writelines(f"{i + 1} {t[0] + 1} {t[1] + 1} {t[2] + 1} {t[3] + 1}\n" for i, t in enumerate(tets))
    faces = np.sort(np.concatenate([tets[:, [0, 2, 1]], tets[:, [0, 1, 3]], tets[:, [1, 2, 3]], tets[:, [0, 3, 2]]]), axis=1)
    u, n = np.unique(faces, axis=0, return_counts=True)
    with open(base + ".face", "w") as f:
        f.write(f"{(n == 1).sum()} 1\n")
        f.writelines(f"{i + 1} {t[0] + 1} {t[1] + 1} {t[2] + 1} 1\n" for i, t in enumerate(u[n == 1]))
    with open(base + "_zero.csv", "w") as f:
        f.write("node,dx,dy,dz\n0,0,0,0\n")
    r = subprocess.run(["tetgen_to_cgns", base, base + ".cgns"], capture_output=True, text=True)
    check(r.returncode == 0, "tetgen_to_cgns")
    # a warp by zero: the mesh as read
    r = subprocess.run([cli, "warp", "--mesh", base + ".cgns", "--displacements", base + "_zero.csv",
                        "-o", base + "_out.vtu"], capture_output=True, text=True)
    check(r.returncode == 0, f"cadmorph reads tetgen_to_cgns's file: {r.stderr[-300:]}")
    if os.path.exists(base + "_out.vtu"):
        m = meshio.read(base + "_out.vtu")
        # tetgen_to_cgns stores RealSingle
        check(np.allclose(m.points, x.astype(np.float32), rtol=0, atol=1e-12), "tetgen_to_cgns: the points")
        t = [c.data for c in m.cells if c.type == "tetra"]
        check(len(t) == 1 and np.array_equal(t[0], tets), "tetgen_to_cgns: the tetrahedra")
    mio = os.path.join(work, "meshio.cgns")
    meshio.write(mio, meshio.Mesh(x, [("tetra", tets)]))
    r = subprocess.run([cli, "quality", mio], capture_output=True, text=True)
    check(r.returncode == 2 and "meshio.cgns: /: not a CGNS file" in r.stderr, f"meshio's file: {r.stderr}")


def main():
    cli, work = sys.argv[1], sys.argv[2]
    if not shutil.which("cgnsdiff") or not shutil.which("cgnscheck"):
        print("cgns-convert is not installed (scripts/setup.sh)")
        return 77
    for name in ("zones", "zones_adf"):
        a, b = os.path.join(work, name + ".cgns"), os.path.join(work, name + "_moved.cgns")
        if name == "zones":
            compare_h5(a, b)
        cgnsdiff_only_coordinates(a, b)
        cgnscheck_clean(b)
    # a new file: a tetrahedron mesh with boundary groups, from the CLI's own writer path
    import meshio

    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], float)
    tets = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])
    tris = np.array([[0, 2, 1], [0, 1, 3]])
    msh = os.path.join(work, "new.vtu")
    meshio.write(msh, meshio.Mesh(pts, [("tetra", tets), ("triangle", tris)],
                                  cell_data={"gmsh:physical": [np.array([1, 1]), np.array([2, 3])]}))
    new = os.path.join(work, "new.cgns")
    # quality reads the .vtu; optimize writes the same mesh (nothing to untangle) as CGNS
    run = subprocess.run([cli, "optimize", msh, "-o", new], capture_output=True, text=True)
    if run.returncode != 0:
        print(run.stdout, run.stderr)
    check(run.returncode == 0, "cadmorph optimize -o new.cgns")
    if os.path.exists(new):
        cgnscheck_clean(new)
        m = meshio.read(new)
        check(np.allclose(m.points, pts), "meshio: points")
        check(len(m.cells) == 1 and m.cells[0].type == "tetra"
              and np.array_equal(np.sort(m.cells[0].data, axis=1), np.sort(tets, axis=1)), "meshio: tetrahedra")
    independent_writers(cli, work)
    print(f"{len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
