#!/usr/bin/python3
"""Assemblies: solids that touch are meshed as one conformal mesh, overlapping solids refused.
usage: test_assembly.py CADMORPH WORKDIR CASE
The STEP files are made by gmsh's OpenCASCADE kernel (separate solids, not fused); the mesh
is read back by gmsh (.msh), not by cadmorph. Conformal: the tets of both solids use the same
interface nodes, and no two nodes share a position."""
import os
import re
import subprocess
import sys

import numpy as np

CLI, WORK = sys.argv[1], sys.argv[2]


def fail(msg):
    print("FAIL:", msg)
    sys.exit(1)


def step(name, shapes):
    """STEP of separate solids: each shape is (kind, args) of gmsh.model.occ.add<kind>."""
    p = os.path.join(WORK, name + ".step")
    code = ("import gmsh\ngmsh.initialize()\ngmsh.option.setNumber('General.Terminal', 0)\n" +
            "".join(f"gmsh.model.occ.add{k}({','.join(map(str, a))})\n" for k, a in shapes) +
            f"gmsh.model.occ.synchronize()\ngmsh.write({p!r})\ngmsh.finalize()\n")
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
    return p


def run(args, code, pattern=None):
    p = subprocess.run([CLI] + args, capture_output=True, text=True, timeout=120)
    print(f"$ cadmorph {' '.join(args)}\nexit {p.returncode}\nstderr: {p.stderr[:800]}")
    if p.returncode != code:
        fail(f"exit {p.returncode}, expected {code}")
    if pattern and not re.search(pattern, p.stderr):
        fail(f"stderr does not match {pattern!r}")
    return p


def read_msh(path):
    """Nodes, tets with their physical tag, triangles with theirs, group names (gmsh's reader)."""
    import gmsh
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.open(path)
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    index = {t: i for i, t in enumerate(tags)}
    xyz = xyz.reshape(-1, 3)
    out = {}
    for dim, n in ((3, 4), (2, 3)):
        cells, phys = [], []
        for _, tag in gmsh.model.getEntities(dim):
            groups = gmsh.model.getPhysicalGroupsForEntity(dim, tag)
            for etype, _, enodes in zip(*gmsh.model.mesh.getElements(dim, tag)):
                c = np.array([index[v] for v in enodes]).reshape(-1, n)
                cells.append(c)
                phys += [groups[0] if len(groups) else 0] * len(c)
        out[dim] = (np.vstack(cells), np.array(phys))
    names = {(d, t): gmsh.model.getPhysicalName(d, t) for d, t in gmsh.model.getPhysicalGroups()}
    gmsh.finalize()
    return xyz, out[3], out[2], names


def check_assembly(msh, n_solids):
    """Groups solid_<k>, no duplicate node positions, interface nodes shared; returns
    (xyz, tets, tet_solid, interface nodes)."""
    xyz, (tets, tphys), (tris, _), names = read_msh(msh)
    want = {f"solid_{k}" for k in range(n_solids)}
    got = {n for (d, _), n in names.items() if d == 3}
    if got != want:
        fail(f"volume groups {sorted(got)}, expected {sorted(want)}")
    if sorted(set(tphys)) != list(range(1, n_solids + 1)):
        fail(f"tet tags {sorted(set(tphys))}")
    dup = len(xyz) - len(np.unique(np.round(xyz, 10), axis=0))
    if dup:
        fail(f"{dup} nodes at the position of another: the mesh is not conformal")
    per = [set(tets[tphys == k + 1].ravel()) for k in range(n_solids)]
    shared = set()
    for a in range(n_solids):
        for b in range(a + 1, n_solids):
            shared |= per[a] & per[b]
    if not shared:
        fail("no node shared by two solids")
    # every triangle of the mesh is on the boundary or on an interface, each on a tet
    print(f"{len(xyz)} nodes, {len(tets)} tets, {len(tris)} triangles, {len(shared)} interface nodes")
    return xyz, tets, tphys, np.array(sorted(shared))


def on_g(p, msh):
    """Every boundary and interface node on the CAD model: the morph onto the model itself
    classifies them (a node off it is refused) and reports the largest distance."""
    out = msh.replace(".msh", "_id.msh")
    r = run(["morph", "--from", p, "--to", p, "--mesh", msh, "-o", out], 0)
    m = re.search(r"largest distance to G1: \S+ \((\S+) x diagonal\)", r.stdout)
    if not m or float(m.group(1)) > 1e-8:
        fail(f"boundary nodes off the CAD model: {m.group(0) if m else r.stdout[:300]}")


def case_two_boxes():
    p = step("two_boxes", [("Box", (0, 0, 0, 1, 1, 1)), ("Box", (1, 0, 0, 1, 1, 1))])
    msh = os.path.join(WORK, "two_boxes.msh")
    run(["mesh", p, "-o", msh, "--size", "0.25"], 0)
    xyz, _, _, shared = check_assembly(msh, 2)
    if np.abs(xyz[shared, 0] - 1).max() > 1e-12:
        fail("an interface node is off the shared face x = 1")
    on_g(p, msh)


def case_box_cylinder():
    """A cylinder standing on part of a box's top face: the face is split where they touch."""
    p = step("box_cyl", [("Box", (0, 0, 0, 2, 2, 1)), ("Cylinder", (1, 1, 1, 0, 0, 1, 0.5))])
    msh = os.path.join(WORK, "box_cyl.msh")
    run(["mesh", p, "-o", msh, "--size", "0.3"], 0)
    xyz, _, _, shared = check_assembly(msh, 2)
    r = np.hypot(xyz[shared, 0] - 1, xyz[shared, 1] - 1)
    if np.abs(xyz[shared, 2] - 1).max() > 1e-12 or r.max() > 0.5 + 1e-9:
        fail("an interface node is off the cylinder's base disc")
    on_g(p, msh)


def case_stack():
    p = step("stack3", [("Box", (0, 0, 0, 1, 1, 1)), ("Box", (0, 0, 1, 1, 1, 1)),
                        ("Box", (0, 0, 2, 1, 1, 1))])
    msh = os.path.join(WORK, "stack3.msh")
    run(["mesh", p, "-o", msh, "--size", "0.3"], 0)
    check_assembly(msh, 3)


def case_overlap():
    p = step("overlap", [("Box", (0, 0, 0, 1, 1, 1)), ("Box", (0.5, 0.2, 0.2, 1, 1, 1))])
    out = os.path.join(WORK, "overlap.msh")
    run(["mesh", p, "-o", out], 2,
        r"solids 0 and 1 \(of 2\) overlap \(they cross: common volume 0\.32, 32% .*fuse them .*fragment")
    if os.path.exists(out):
        fail("an output was written")


def case_nested():
    p = step("nested", [("Box", (0, 0, 0, 3, 3, 3)), ("Box", (1, 1, 1, 1, 1, 1))])
    run(["mesh", p, "-o", os.path.join(WORK, "nested.msh")], 2,
        r"solids 0 and 1 \(of 2\) overlap \(one is inside the other")


def case_tetgen_touching():
    p = step("two_boxes_tg", [("Box", (0, 0, 0, 1, 1, 1)), ("Box", (1, 0, 0, 1, 1, 1))])
    run(["mesh", p, "-o", os.path.join(WORK, "tg.msh"), "--mesher", "tetgen"], 2,
        r"solids 0 and 1 \(of 2\) touch \(share a face\): TetGen .*--mesher gmsh")


def case_morph_edit():
    """The first box 20% longer, the second moved with it: the interface moves to x = 1.2."""
    p = step("pair", [("Box", (0, 0, 0, 1, 1, 1)), ("Box", (1, 0, 0, 1, 1, 1))])
    q = step("pair_edit", [("Box", (0, 0, 0, 1.2, 1, 1)), ("Box", (1.2, 0, 0, 1, 1, 1))])
    msh, out = os.path.join(WORK, "pair.msh"), os.path.join(WORK, "pair_edit.msh")
    run(["mesh", p, "-o", msh, "--size", "0.25"], 0)
    r = run(["morph", "--from", p, "--to", q, "--mesh", msh, "-o", out], 0)
    if not re.search(r"inverted=0 ", r.stdout):
        fail("the morph inverted cells")
    xyz0, tets0, _, shared0 = check_assembly(msh, 2)
    xyz, tets, _, shared = check_assembly(out, 2)
    if not np.array_equal(tets0, tets) or not np.array_equal(shared0, shared):
        fail("the morph changed the connectivity")
    err = np.abs(xyz[shared, 0] - 1.2).max()
    print(f"interface nodes: largest distance to the edited interface {err:.3g}")
    if err > 1e-9:
        fail("interface nodes off the edited shared face x = 1.2")


CASES = {k[5:]: v for k, v in globals().items() if k.startswith("case_")}

if __name__ == "__main__":
    os.makedirs(WORK, exist_ok=True)
    CASES[sys.argv[3]]()
    print("ok")
