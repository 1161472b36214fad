"""Surface formats against meshio (python3-meshio): files meshio wrote (.obj, .off, ASCII and
binary .stl) are read by cadmorph and written as .vtu, which meshio reads back: the same
points (STL: the same set of distinct corners, meshio merges too) and the same faces; files
cadmorph wrote are read by meshio with the same points and faces.
usage: test_surface_io_meshio.py TEST_SURFACE_IO_BINARY WORK_DIR"""
import os
import subprocess
import sys

import meshio
import numpy as np
from scipy.spatial import cKDTree

exe, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)
rng = np.random.default_rng(15)

# a bumpy 9x7 grid of triangles (STL holds triangles only), coordinates with all digits
nx, ny = 9, 7
X, Y = np.meshgrid(np.linspace(0, 1, nx), np.linspace(0, 0.8, ny))
pts = np.c_[X.ravel(), Y.ravel(), 0.1 * np.sin(3 * X.ravel()) * Y.ravel()] + rng.normal(0, 1e-3, (nx * ny, 3))
tris = []
for j in range(ny - 1):
    for i in range(nx - 1):
        a = j * nx + i
        tris += [[a, a + 1, a + nx + 1], [a, a + nx + 1, a + nx]]
tris = np.array(tris)
failed = 0
passed = 0


def check(cond, msg):
    global failed, passed
    if cond:
        passed += 1
    else:
        failed += 1
        print("FAILED:", msg)


def same_faces(p, cp, q, cq, tol):
    """The faces (cp over points p, cq over q) are the same up to node numbering: every point of
    p has a point of q within tol, and the faces map onto each other as node sets."""
    d, idx = cKDTree(q).query(p)
    if d.max() > tol:
        return False
    mapped = sorted(tuple(sorted(idx[c])) for c in cp)
    return mapped == sorted(tuple(sorted(c)) for c in cq)


def tri_cells(m):
    return np.vstack([b.data for b in m.cells if b.type == "triangle"])


cases = [("mio.obj", "obj", {}), ("mio.off", "off", {}),
         ("mio_ascii.stl", "stl", {"binary": False}), ("mio_bin.stl", "stl", {"binary": True})]
for name, fmt, kw in cases:
    src = os.path.join(work, name)
    meshio.write(src, meshio.Mesh(pts, [("triangle", tris)]), file_format=fmt, **kw)
    ref = meshio.read(src, file_format=fmt)
    out = src + ".vtu"
    r = subprocess.run([exe, "convert", src, out], capture_output=True, text=True)
    check(r.returncode == 0, f"{name}: cadmorph cannot read it: {r.stderr}")
    if r.returncode:
        continue
    ours = meshio.read(out)
    if fmt != "stl":
        check(len(ours.points) == len(ref.points), f"{name}: {len(ours.points)} vs {len(ref.points)} points")
        check(np.array_equal(ours.points, ref.points), f"{name}: points differ")
        check(np.array_equal(tri_cells(ours), tri_cells(ref)), f"{name}: faces differ")
    else:
        # distinct corners: meshio merges STL corners too
        check(len(ours.points) == len(np.unique(ref.points, axis=0)),
              f"{name}: {len(ours.points)} nodes vs {len(np.unique(ref.points, axis=0))} distinct corners")
        check(same_faces(ours.points, tri_cells(ours), ref.points, tri_cells(ref), 0.0),
              f"{name}: faces differ")

# cadmorph writes, meshio reads
src = os.path.join(work, "mio_src.vtu")
meshio.write(src, meshio.Mesh(pts, [("triangle", tris)]))
for name, mode, fmt in [("ours.obj", "ascii", "obj"), ("ours.off", "ascii", "off"),
                        ("ours_ascii.stl", "ascii", "stl"), ("ours_bin.stl", "binary", "stl")]:
    dst = os.path.join(work, name)
    r = subprocess.run([exe, "convert", src, dst, mode], capture_output=True, text=True)
    check(r.returncode == 0, f"{name}: cadmorph cannot write it: {r.stderr}")
    if r.returncode:
        continue
    back = meshio.read(dst, file_format=fmt)
    if fmt != "stl":
        check(np.array_equal(back.points, pts), f"{name}: points differ (max {np.abs(back.points - pts).max()})")
        check(np.array_equal(tri_cells(back), tris), f"{name}: faces differ")
    else:
        # binary STL holds float32: corners within its rounding (1e-7 relative)
        check(same_faces(back.points, tri_cells(back), pts, tris, 0.0 if mode == "ascii" else 1e-7),
              f"{name}: faces differ")

print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
