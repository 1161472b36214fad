#!/usr/bin/python3
"""Abaqus decks against independent readers and writers, and CalculiX.

usage: test_abaqus_crosscheck.py CADMORPH BUILD_PYTHON WORK CASE
  roundtrip  gmsh-written decks (tet4, tet10, hex8, wedge6) read as meshio reads them (wedges in
             Abaqus's order, which meshio does not permute); meshio-written decks read back;
             cadmorph's new deck read by meshio and run by ccx (gmsh writes .inp but does not
             read it); an affine motion of every node written back is the affine image, and
             nothing but *NODE numbers changes
  ccx        the bore's C3D10 mesh (gmsh, second order) morphed onto another bore: mid-side
             nodes on the new bore; CalculiX ccx runs a static step on the written deck
  cli        quality, warp, deform, optimize on a deck (written back and as .vtu)
"""
import os
import re
import shutil
import subprocess
import sys

import numpy as np

CLI, PYDIR, WORK, CASE = sys.argv[1:5]
sys.path.insert(0, PYDIR)
import cadmorph  # noqa: E402
import gmsh  # noqa: E402
import meshio  # noqa: E402

os.makedirs(WORK, exist_ok=True)
WEDGE = [0, 2, 1, 3, 5, 4]
failures = []


def check(cond, msg):
    print(("ok   " if cond else "FAIL ") + msg)
    if not cond:
        failures.append(msg)


def gmsh_deck(path, kind, order=1, size=0.5):
    """A box meshed by gmsh and written as .inp: tets, hexes (transfinite) or wedges (extruded
    triangles); volume elements only (a physical volume)."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(kind)
    occ = gmsh.model.occ
    if kind == "wedge":
        s = occ.addRectangle(0, 0, 0, 1, 2)
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        ex = occ.extrude([(2, s)], 0, 0, 1.5, numElements=[3], recombine=True)
        occ.synchronize()
        vol = [e[1] for e in ex if e[0] == 3]
    else:
        vol = [occ.addBox(0, 0, 0, 1, 2, 1.5)]
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", size)
        if kind == "hex":
            for c in gmsh.model.getEntities(1):
                gmsh.model.mesh.setTransfiniteCurve(c[1], 4)
            for f in gmsh.model.getEntities(2):
                gmsh.model.mesh.setTransfiniteSurface(f[1])
                gmsh.model.mesh.setRecombine(2, f[1])
            gmsh.model.mesh.setTransfiniteVolume(vol[0])
    gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, vol), "solid")
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(order)
    gmsh.write(path)
    gmsh.finalize()


def roundtrip():
    for kind, order, ctype in (("tet", 1, "tet4"), ("tet", 2, "tet10"), ("hex", 1, "hex8"), ("wedge", 1, "wedge6")):
        path = os.path.join(WORK, f"gmsh_{kind}{order}.inp")
        gmsh_deck(path, kind, order)
        m = cadmorph.read_mesh(path)
        ref = meshio.read(path)
        check(np.array_equal(m.points, ref.points), f"{path}: points as meshio reads them")
        ours = dict(m.cells)
        theirs = {c.type: c.data for c in ref.cells}
        key = {"tet4": "tetra", "tet10": "tetra10", "hex8": "hexahedron", "wedge6": "wedge"}[ctype]
        want = theirs[key][:, WEDGE] if ctype == "wedge6" else theirs[key]
        check(ctype in ours and np.array_equal(ours[ctype], want), f"{path}: {ctype} cells as meshio's (wedges permuted)")
        q = subprocess.run([CLI, "quality", path], capture_output=True, text=True)
        check(q.returncode == 0 and " inverted=0 " in q.stdout, f"{path}: cadmorph quality: no inverted cell")
        if order == 2:
            c = ours[ctype]
            edges = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
            err = max(np.abs(m.points[c[:, 4 + k]] - 0.5 * (m.points[c[:, i]] + m.points[c[:, j]])).max()
                      for k, (i, j) in enumerate(edges))
            check(err < 1e-12, f"{path}: mid-side nodes on VTK's edges ({err:.2g})")
        # meshio writes the mesh cadmorph read (not wedges: meshio writes VTK's wedge as C3D6)
        if ctype != "wedge6":
            back = os.path.join(WORK, f"meshio_{kind}{order}.inp")
            meshio.write(back, meshio.Mesh(m.points, [(key, ours[ctype])]))
            b = cadmorph.read_mesh(back)
            etype = re.search(r"type=(\w+)", open(back).read(), re.I).group(1)
            check(np.array_equal(b.points, m.points) and np.array_equal(dict(b.cells)[ctype], ours[ctype]),
                  f"{back}: meshio's deck (type {etype}) read back")
        # cadmorph's new deck (from a .vtu), read by meshio and gmsh
        vtu = os.path.join(WORK, f"new_{kind}{order}.vtu")
        new = os.path.join(WORK, f"new_{kind}{order}.inp")
        cadmorph.write_mesh(vtu, m)
        cadmorph.write_mesh(new, cadmorph.read_mesh(vtu))
        r = meshio.read(new)
        rc = {c.type: c.data for c in r.cells}
        check(np.allclose(r.points, m.points, rtol=0, atol=0) and np.array_equal(
            rc[key][:, WEDGE] if ctype == "wedge6" else rc[key], ours[ctype]), f"{new}: meshio reads cadmorph's new deck")
        # gmsh writes .inp but has no reader for it; CalculiX reads the new deck and runs a step
        if ctype == "tet4" and shutil.which("ccx"):
            P = m.points
            fix = np.flatnonzero(np.abs(P[:, 2]) < 1e-9) + 1
            top = np.flatnonzero(np.abs(P[:, 2] - 1.5) < 1e-9) + 1
            job = os.path.join(WORK, "new_job.inp")
            elset = re.search(r"ELSET=(\w+)", open(new).read()).group(1)
            with open(job, "w") as f:
                f.write(open(new).read() + "*NSET, NSET=FIX\n" + "\n".join(map(str, fix)) + "\n*NSET, NSET=TOP\n"
                        + "\n".join(map(str, top)) + "\n*MATERIAL, NAME=STEEL\n*ELASTIC\n210000., 0.3\n"
                        f"*SOLID SECTION, ELSET={elset}, MATERIAL=STEEL\n*BOUNDARY\nFIX, 1, 3\n*STEP\n*STATIC\n"
                        "*CLOAD\nTOP, 3, 0.01\n*NODE PRINT, NSET=TOP\nU\n*END STEP\n")
            r = subprocess.run(["ccx", "new_job"], cwd=WORK, capture_output=True, text=True, timeout=300)
            check(r.returncode == 0 and "Job finished" in r.stdout and "*ERROR" not in r.stdout,
                  f"{new}: ccx runs a static step on cadmorph's new deck")
    # an affine motion of every node written back: the affine image; only *NODE numbers change
    src = os.path.join(WORK, "gmsh_tet2.inp")
    m = cadmorph.read_mesh(src)
    A = np.array([[1.1, 0.2, 0.0], [-0.1, 0.9, 0.05], [0.0, 0.3, 1.25]])
    t = np.array([0.25, -1.5, 3.0])
    moved = m.points @ A.T + t
    m.points = moved
    os.makedirs(os.path.join(WORK, "affine"), exist_ok=True)
    out = os.path.join(WORK, "affine", "gmsh_tet2.inp")
    cadmorph.write_mesh(out, m)
    back = cadmorph.read_mesh(out)
    # exact where the shortest exact text fits in 20 characters (CalculiX's field), else 14 digits
    exact = np.mean(back.points == moved)
    rel = np.max(np.abs(back.points - moved) / np.maximum(np.abs(moved), 1e-300))
    check(exact > 0.99 and rel < 1e-13, f"affine motion written back: the affine image ({exact:.4f} exact, "
          f"the others within {rel:.2g})")
    a = open(src).read().split("\n")
    b = open(out).read().split("\n")
    same = len(a) == len(b)
    in_node = False
    for x, y in zip(a, b):
        if x.startswith("*"):
            in_node = x.upper().startswith("*NODE")
        if in_node and not x.startswith("*"):
            fx, fy = x.split(","), y.split(",")
            same &= len(fx) == len(fy) and fx[0] == fy[0]
        else:
            same &= x == y
    check(same, "affine motion written back: every other line, every node id and separator as before")


def ccx():
    if not shutil.which("ccx"):
        print("ccx missing")
        sys.exit(77)
    s0, s1 = os.path.join(WORK, "bore_0.step"), os.path.join(WORK, "bore_1.step")
    for t, p in (("0", s0), ("0.5", s1)):
        subprocess.run([CLI, "model", "bore", t, p], check=True, capture_output=True)
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(s0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.45)
    gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [e[1] for e in gmsh.model.getEntities(3)]), "BORE")
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    mesh = os.path.join(WORK, "bore_mesh.inp")
    gmsh.write(mesh)
    gmsh.finalize()
    m = cadmorph.read_mesh(mesh)
    P = m.points
    fix = np.flatnonzero(np.abs(P[:, 2]) < 1e-9) + 1
    load = np.flatnonzero(np.abs(P[:, 2] - 2) < 1e-9) + 1

    def ids(v):
        return "\n".join(", ".join(str(i) for i in v[k:k + 16]) for k in range(0, len(v), 16))
    job = os.path.join(WORK, "job.inp")
    with open(job, "w") as f:
        f.write(f"** a static step on the bore\n*INCLUDE, INPUT=bore_mesh.inp\n*NSET, NSET=FIX\n{ids(fix)}\n"
                f"*NSET, NSET=LOAD\n{ids(load)}\n*MATERIAL, NAME=STEEL\n*ELASTIC\n210000., 0.3\n"
                "*SOLID SECTION, ELSET=BORE, MATERIAL=STEEL\n*BOUNDARY\nFIX, 1, 3\n*STEP\n*STATIC\n"
                f"*CLOAD\nLOAD, 3, {1.0 / len(load)}\n*NODE PRINT, NSET=LOAD\nU\n*NODE FILE\nU\n*END STEP\n")
    outdir = os.path.join(WORK, "morphed")
    shutil.rmtree(outdir, ignore_errors=True)
    os.makedirs(outdir)
    out = os.path.join(outdir, "job.inp")
    r = subprocess.run([CLI, "morph", "--from", s0, "--to", s1, "--mesh", job, "-o", out], capture_output=True, text=True)
    print(r.stdout[-400:], r.stderr[-800:])
    check(r.returncode == 0 and " inverted=0 " in r.stdout, "morph of the C3D10 bore deck")
    check(os.path.exists(os.path.join(outdir, "bore_mesh.inp")), "the included mesh written beside the deck")
    check(open(out).read() == open(job).read(), "the deck itself (no node in it) unchanged byte for byte")
    mm = cadmorph.read_mesh(out)
    # boundary mid-side nodes of the bore's face: at the new radius from the new axis
    tet = dict(m.cells)["tet10"]
    Q = mm.points

    def dist(X, radius_t):
        a = np.radians(25.0 * radius_t)
        d = np.array([0, -np.sin(a), np.cos(a)])
        v = X - np.array([0, 0, 1.0])
        return np.linalg.norm(v - np.outer(v @ d, d), axis=1)
    on0 = np.abs(dist(P, 0) - 0.6) < 1e-6
    mids = np.unique(tet[:, 4:].ravel())
    sel = mids[on0[mids]]
    err = np.abs(dist(Q[sel], 0.5) - 0.8).max()
    check(len(sel) > 50 and err < 1e-6, f"{len(sel)} mid-side nodes of the bore on the morphed bore (miss {err:.2g})")
    corners = np.unique(tet[:, :4].ravel())
    selc = corners[on0[corners]]
    errc = np.abs(dist(Q[selc], 0.5) - 0.8).max()
    check(errc < 1e-6, f"{len(selc)} corner nodes of the bore on the morphed bore (miss {errc:.2g})")
    r = subprocess.run(["ccx", "job"], cwd=outdir, capture_output=True, text=True, timeout=300)
    print(r.stdout[-600:])
    check(r.returncode == 0 and "Job finished" in r.stdout and "ERROR" not in r.stdout.upper().replace("ERROR ESTIMATOR", ""),
          "ccx runs the static step on the morphed deck")
    frd, dat = os.path.join(outdir, "job.frd"), os.path.join(outdir, "job.dat")
    check(os.path.exists(frd) and os.path.getsize(frd) > 0 and os.path.exists(dat) and "displacements" in open(dat).read(),
          "ccx wrote job.frd and job.dat")


def cli():
    deck = os.path.join(WORK, "cli_tet.inp")
    gmsh_deck(deck, "tet", 1, 0.35)
    m = cadmorph.read_mesh(deck)
    P = m.points
    r = subprocess.run([CLI, "quality", deck], capture_output=True, text=True)
    check(r.returncode == 0 and "inverted=0" in r.stdout, "cadmorph quality on a deck")
    # warp: the top face lifted
    top = np.flatnonzero(np.abs(P[:, 2] - 1.5) < 1e-9)
    disp = os.path.join(WORK, "cli_disp.csv")
    with open(disp, "w") as f:
        f.write("node,dx,dy,dz\n" + "".join(f"{i},0,0,{0.1 * P[i, 0]}\n" for i in top))
    os.makedirs(os.path.join(WORK, "cli_out"), exist_ok=True)
    for name, args in (("warp", ["warp", "--mesh", deck, "--displacements", disp]),
                       ("deform", ["deform", "--mesh", deck, "--handles", disp, "--fix-unlisted-boundary", "--method", "rbf"]),
                       ("optimize", ["optimize", deck])):
        for ext in ("inp", "vtu"):
            out = os.path.join(WORK, "cli_out", f"{name}.{ext}")
            r = subprocess.run([CLI] + args + ["-o", out], capture_output=True, text=True)
            check(r.returncode == 0 and os.path.exists(out), f"cadmorph {name} -o .{ext}: exit {r.returncode} {r.stderr[-300:]}")
        b = cadmorph.read_mesh(os.path.join(WORK, "cli_out", f"{name}.inp"))
        v = cadmorph.read_mesh(os.path.join(WORK, "cli_out", f"{name}.vtu"))
        check(np.allclose(b.points, v.points, rtol=1e-13, atol=1e-13), f"cadmorph {name}: the deck written back holds the .vtu's nodes")
        if name != "optimize":
            check(np.allclose(b.points[top, 2] - P[top, 2], 0.1 * P[top, 0]), f"cadmorph {name}: the top moved as listed")
    # a node set of the deck as the constraint set of deform: its nodes, all of them
    bottom = np.flatnonzero(np.abs(P[:, 2]) < 1e-9)
    sets = os.path.join(WORK, "cli_sets.inp")
    with open(sets, "w") as f:
        f.write(open(deck).read() + "*NSET, NSET=BOTTOM\n" + "\n".join(str(i + 1) for i in bottom) + "\n")
    out = os.path.join(WORK, "cli_out", "constrained.inp")
    r = subprocess.run([CLI, "deform", "--mesh", sets, "--handles", disp, "--method", "mls", "--constraint", "plane:BOTTOM",
                        "-o", out], capture_output=True, text=True)
    ok = r.returncode == 0 and os.path.exists(out) and f"plane:BOTTOM: {len(bottom)} nodes" in r.stdout + r.stderr
    check(ok, f"cadmorph deform --constraint plane:BOTTOM (an *NSET of the deck) {r.stderr[-300:]}")


{"roundtrip": roundtrip, "ccx": ccx, "cli": cli}[CASE]()
print(f"{len(failures)} failed")
sys.exit(1 if failures else 0)
