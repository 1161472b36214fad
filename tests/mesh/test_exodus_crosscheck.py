"""Exodus II against independent readers and writers: meshio writes the bore's hex mesh as
Exodus (netCDF-4), SEACAS's library the mixed quadratic fixture (netCDF classic, float and
double); cadmorph reads them, moves them and writes them back; netCDF4 checks that every
variable, dimension and attribute but the coordinates is unchanged, and meshio reads the
written files. The CLI's quality, warp, morph, deform and optimize run on the Exodus mesh.

usage: test_exodus_crosscheck.py TEST_EXODUS CADMORPH WORKDIR
"""
import os
import shutil
import subprocess
import sys

import meshio
import netCDF4
import numpy as np

import cadmorph

fixture_exe, cli, work = (os.path.abspath(a) for a in sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
COORDS = {"coord", "coordx", "coordy", "coordz"}


def run(*args):
    r = subprocess.run([cli, *args], capture_output=True, text=True, cwd=work)
    assert r.returncode == 0, f"{' '.join(args)}: exit {r.returncode}\n{r.stderr}"
    return r.stdout


def attrs(obj):
    return {k: obj.getncattr(k) for k in obj.ncattrs()}


def same(a, b):
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b))
    return a == b


def compare(src, out):
    """Every dimension, attribute and variable of out as in src, but the coordinates."""
    with netCDF4.Dataset(src) as a, netCDF4.Dataset(out) as b:
        a.set_auto_maskandscale(False)
        b.set_auto_maskandscale(False)
        assert a.data_model == b.data_model, (a.data_model, b.data_model)
        assert {k: len(v) for k, v in a.dimensions.items()} == {k: len(v) for k, v in b.dimensions.items()}
        ga, gb = attrs(a), attrs(b)
        assert ga.keys() == gb.keys() and all(same(ga[k], gb[k]) for k in ga), (ga, gb)
        assert list(a.variables) == list(b.variables)
        coords = []
        for name, va in a.variables.items():
            vb = b.variables[name]
            assert va.dtype == vb.dtype and va.dimensions == vb.dimensions, name
            aa, ab = attrs(va), attrs(vb)
            assert aa.keys() == ab.keys() and all(same(aa[k], ab[k]) for k in aa), name
            if name in COORDS:
                coords.append(name)
            else:
                assert np.array_equal(va[...], vb[...]), f"{out}: variable {name} changed"
        assert coords, "no coordinate variable"
        return coords


def coordinates(path):
    """The nodes as the file stores them (num_nodes x 3), by netCDF4 alone."""
    with netCDF4.Dataset(path) as d:
        d.set_auto_maskandscale(False)
        if "coord" in d.variables:
            c = np.asarray(d.variables["coord"][...]).T
        else:
            c = np.stack([np.asarray(d.variables[k][...]) for k in ("coordx", "coordy", "coordz")
                          if k in d.variables], axis=1)
    if c.shape[1] == 2:
        c = np.column_stack([c, np.zeros(len(c))])
    return c


A = np.array([[1.5, 0.25, -0.5], [-0.25, 0.75, 0.125], [0.5, 0.5, 2.0]])
b = np.array([3.0, -1.0, 0.5])

# ---- the library-written fixture: affine motion written back, word sizes 8 and 4 ----
for ws in (8, 4):
    src = os.path.join(work, f"mixed_{ws}.exo")
    subprocess.run([fixture_exe, "--fixture", src, str(ws)], check=True)
    m = cadmorph.read_mesh(src)
    assert m.n_nodes == 72, m.n_nodes
    names = {g[2] for g in m.groups}
    assert {"solid", "block 20", "cube27", "prisms", "tets", "inlet", "nodeset 6", "wall"} <= names, names
    moved = m.points @ A.T + b
    m.points = moved
    out = os.path.join(work, f"mixed_{ws}_moved.e")
    cadmorph.write_mesh(out, m)
    assert compare(src, out) == ["coordx", "coordy", "coordz"]
    want = moved if ws == 8 else moved.astype(np.float32).astype(np.float64)
    assert np.array_equal(coordinates(out), want), f"word size {ws}: not the affine image"
    # (meshio 5 knows no WEDGE15: it reads the bore's files below)


# ---- hostile variants of the fixture: a connectivity declared over other dimensions than its
# block's (the library would read 400 values into room for 4), two blocks with one id ----
def variant(src, out, bogus_connect=False, dup_id=False):
    with netCDF4.Dataset(src) as a, netCDF4.Dataset(out, "w", format=a.data_model) as b:
        a.set_auto_maskandscale(False)
        b.setncatts(attrs(a))
        for name, dim in a.dimensions.items():
            b.createDimension(name, None if dim.isunlimited() else len(dim))
        b.createDimension("bogus", 100)
        for name, va in a.variables.items():
            dims = va.dimensions
            if bogus_connect and name == "connect5":
                dims = ("bogus", dims[1])
            vb = b.createVariable(name, va.dtype, dims)
            vb.set_auto_maskandscale(False)
            vb.setncatts(attrs(va))
            data = np.asarray(va[...])
            if bogus_connect and name == "connect5":
                data = np.resize(data, (100, data.shape[1]))
            if dup_id and name == "eb_prop1":
                data = data.copy()
                data[1] = data[0]
            vb[...] = data


for kind, needle in (("bogus_connect", "variable connect5 holds 400 values, expected 4"),
                     ("dup_id", "two element blocks have the id 10")):
    bad = os.path.join(work, f"{kind}.exo")
    variant(os.path.join(work, "mixed_8.exo"), bad, **{kind: True})
    try:
        cadmorph.read_mesh(bad)
        raise AssertionError(f"{bad}: read")
    except cadmorph.Error as e:
        assert bad in str(e) and needle in str(e), str(e)

# ---- meshio's file of the bore's hex mesh, with a node set ----
run("model", "bore", "0", "bore_0.step", "--hex-mesh", "bore_0.vtu", "--scale", "0.5")
run("model", "bore", "1", "bore_1.step")
v = meshio.read(os.path.join(work, "bore_0.vtu"))
z = v.points[:, 2]
bottom = np.flatnonzero(np.isclose(z, z.min())).astype(np.int64)
exo = meshio.Mesh(v.points, [(c.type, c.data) for c in v.cells], point_sets={"bottom": bottom})
meshio.write(os.path.join(work, "bore_0.exo"), exo, file_format="exodus")
src = os.path.join(work, "bore_0.exo")
m = cadmorph.read_mesh(src)
assert m.n_nodes == len(v.points)
assert any(g[2] == "bottom" and g[0] == 0 for g in m.groups), m.groups

# the CLI on the Exodus mesh; every output written back into a copy of bore_0.exo
q = run("quality", "bore_0.exo")
assert "inverted=0" in q.splitlines()[-1], q
run("morph", "--from", "bore_0.step", "--to", "bore_1.step", "--mesh", "bore_0.exo", "-o", "bore_1.exo")
run("morph", "--from", "bore_0.step", "--to", "bore_1.step", "--mesh", "bore_0.vtu", "-o", "bore_1.vtu")
compare(src, os.path.join(work, "bore_1.exo"))
morphed = meshio.read(os.path.join(work, "bore_1.exo"))
assert np.array_equal(morphed.points, meshio.read(os.path.join(work, "bore_1.vtu")).points)
assert not np.array_equal(morphed.points, v.points)

# warp: the top face lifted by 0.05, the rest of the boundary still
top = np.flatnonzero(np.isclose(z, z.max()))
with open(os.path.join(work, "disp.csv"), "w") as f:
    f.write("node,dx,dy,dz\n")
    f.writelines(f"{i},0,0,0.05\n" for i in top)
run("warp", "--mesh", "bore_0.exo", "--displacements", "disp.csv", "-o", "warped.exo")
compare(src, os.path.join(work, "warped.exo"))
w = coordinates(os.path.join(work, "warped.exo"))
assert np.allclose(w[top, 2], v.points[top, 2] + 0.05, atol=1e-12)

# deform: the same handles, the node set "bottom" (a group of the Exodus file) kept planar
run("deform", "--mesh", "bore_0.exo", "--handles", "disp.csv", "--fix-unlisted-boundary",
    "--constraint", "plane:bottom", "--constraint-snap", "-o", "deformed.exo")
compare(src, os.path.join(work, "deformed.exo"))
d = coordinates(os.path.join(work, "deformed.exo"))
p = d[bottom] - d[bottom].mean(axis=0)
assert np.linalg.svd(p, compute_uv=False)[-1] < 1e-9, "the node set 'bottom' is not planar"
assert np.abs(d - v.points).max() > 1e-2

# optimize the morphed mesh: written back into its Exodus file
run("optimize", "bore_1.exo", "-o", "optimized.exo")
compare(src, os.path.join(work, "optimized.exo"))
assert meshio.read(os.path.join(work, "optimized.exo")).points.shape == v.points.shape

# a mesh not read from Exodus: refused with the reason, no file written
r = subprocess.run([cli, "warp", "--mesh", "bore_0.vtu", "--displacements", "disp.csv", "-o", "new.exo"],
                   capture_output=True, text=True, cwd=work)
assert r.returncode != 0 and "Exodus II is written only back" in r.stderr, r.stderr
assert not os.path.exists(os.path.join(work, "new.exo"))
print("exodus cross-check: ok")
