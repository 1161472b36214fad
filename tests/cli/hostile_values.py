#!/usr/bin/python3
"""Numbers at the edges and the messages about them: non-finite coordinates and weights in
every kind of input are bad input (exit 2, one line naming the file and the place), a .prm
whose weights overflow the lattice's arithmetic is refused before anything is written, an
empty handles table and a degenerate shell surface are bad input naming their file, every
non-zero exit says why on one line, and a message about a path of thousands of characters
keeps its reason (the path shortened in the middle). Frame: hostile.py.
"""
import os
import struct

import hostile
from hostile import case, run, path, write, fail, DATA, CLI

PRM = os.path.join(DATA or "", "deform", "bern222.prm")
MESSAGE_MAX = 2048  # the library's message buffer (core/context.c)


def absent(*names):
    for n in names:
        if os.path.exists(path(n)):
            fail(f"{n} was written")


def tet_msh(name="tet.msh", nodes=None):
    """One tet inside the unit box of bern222.prm."""
    nodes = nodes or ["0.1 0.1 0.1", "0.9 0.1 0.1", "0.1 0.9 0.1", "0.1 0.1 0.9"]
    body = "".join(f"{i + 1} {p}\n" for i, p in enumerate(nodes))
    return write(name, f"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n{body}$EndNodes\n"
                       f"$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n")


def grid_obj(name, change=None):
    """A 6 x 6 grid of triangles in z = 0; change(faces) may break it."""
    n = 6
    verts = [(i / (n - 1), j / (n - 1), 0.0) for j in range(n) for i in range(n)]
    faces = []
    for j in range(n - 1):
        for i in range(n - 1):
            a = j * n + i + 1
            faces += [(a, a + 1, a + n + 1), (a, a + n + 1, a + n)]
    if change:
        change(verts, faces)
    return write(name, "".join("v %r %r %r\n" % v for v in verts) +
                 "".join("f %d %d %d\n" % f for f in faces))


def ffd_refuses(mesh, pattern, name):
    """ffd reads the mesh after the lattice: exit 2, one line naming the mesh, no output."""
    run(["ffd", "--mesh", mesh, "--lattice", PRM, "-o", path("out.vtu")], 2, pattern, [name])
    absent("out.vtu")


# ---- non-finite coordinates in every mesh format the tests can write by hand ----
def text_meshes(v):
    return {
        "msh": f"$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n4\n1 0 0 0\n2 1 0 0\n3 0 {v} 0\n"
               f"4 0 0 1\n$EndNodes\n$Elements\n1\n1 4 2 0 1 1 2 3 4\n$EndElements\n",
        "vtk": f"# vtk DataFile Version 2.0\nx\nASCII\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n"
               f"0 0 0 1 0 0 0 {v} 0 0 0 1\nCELLS 1 5\n4 0 1 2 3\nCELL_TYPES 1\n10\n",
        "obj": f"v 0 0 0\nv 1 0 0\nv 0 {v} 0\nf 1 2 3\n",
        "stl": f"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
               f"vertex 0 {v} 0\nendloop\nendfacet\nendsolid x\n",
    }


def nonfinite(ext, line):
    """inf, nan, 1e999 (finite to no parser) and -inf as a y coordinate at the given line."""
    for v in ["inf", "nan", "1e999", "-inf"]:
        name = f"c_{v.replace('-', 'm')}.{ext}"
        write(name, text_meshes(v)[ext])
        ffd_refuses(path(name), rf"c_{v.replace('-', 'm')}\.{ext}:{line}: .*finite", name)


# the line of the bad coordinate: .msh 8, .vtk 5 (all points on one line), .obj 3, .stl 6
@case
def val_nonfinite_msh():
    nonfinite("msh", 8)


@case
def val_nonfinite_vtk():
    nonfinite("vtk", 5)


@case
def val_nonfinite_obj():
    nonfinite("obj", 3)


@case
def val_nonfinite_stl():
    nonfinite("stl", 6)


@case
def val_mesh_nonfinite_binary():
    # binary STL: the byte offset of the triangle; binary legacy VTK: the point
    for v, tag in [(float("inf"), "inf"), (float("nan"), "nan")]:
        name = f"b_{tag}.stl"
        write(name, b"\0" * 80 + struct.pack("<I", 1) +
              struct.pack("<12fH", 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, v, 0, 0), "wb")
        ffd_refuses(path(name), rf"b_{tag}\.stl: byte \d+: triangle 0, corner 2: coordinate is not finite", name)
        name = f"b_{tag}.vtk"
        pts = struct.pack(">12d", 0, 0, 0, 1, 0, 0, 0, v, 0, 0, 0, 1)
        write(name, b"# vtk DataFile Version 2.0\nx\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 4 double\n" +
              pts + b"\nCELLS 1 5\n" + struct.pack(">5i", 4, 0, 1, 2, 3) + b"\nCELL_TYPES 1\n" +
              struct.pack(">i", 10) + b"\n", "wb")
        ffd_refuses(path(name), rf"b_{tag}\.vtk:\d+: point 2: coordinate y is not finite", name)


# ---- non-finite numbers in the CSV tables ----
@case
def val_csv_nan():
    d = write("d_nan.csv", "node,dx,dy,dz\n0,0,nan,0\n")
    run(["warp", "--mesh", tet_msh(), "--displacements", d, "-o", path("w.vtu")], 2,
        r"d_nan\.csv:2: dy of node 0 is not finite", ["d_nan.csv"])
    absent("w.vtu")
    h = write("h_nan.csv", "node,dx,dy,dz\n14,0,0,1e999\n")
    run(["deform", "--mesh", grid_obj("grid.obj"), "--handles", h, "--method", "shell", "-o", path("s.obj")],
        2, r"h_nan\.csv:2: dz of node 14 is not finite", ["h_nan.csv"])
    absent("s.obj")
    c = write("c_nan.csv", "i,j,k,dx,dy,dz\n0,0,0,0,inf,0\n")
    run(["ffd", "--mesh", tet_msh(), "--lattice", PRM, "--displacements", c, "-o", path("f.vtu")], 2,
        r"c_nan\.csv:2: dy 'inf' is not a finite number", ["c_nan.csv"])
    absent("f.vtu")


# ---- .prm lattices: finite but overflowing weights, NaN, a flat box ----
def prm(name, old, new):
    with open(PRM) as f:
        text = f.read()
    if old not in text:
        fail(f"{old!r} not in {PRM}")
    return write(name, text.replace(old, new))


def ffd_prm(p, pattern, name):
    run(["ffd", "--mesh", tet_msh(), "--lattice", p, "-o", path("out.vtu")], 2, pattern, [name])
    absent("out.vtu")


@case
def val_prm_1e308():
    # finite, but times the box length it is no displacement: inf/nan coordinates once applied
    p = prm("w308.prm", "parameter x: 0   0   0   0.0", "parameter x: 0   0   0   1e308")
    ffd_prm(p, r"w308\.prm:48: weight 1e\+308 of control point \(0, 0, 0\) along x .*beyond any mesh", "w308.prm")
    p = prm("w308y.prm", "             1   1   1   0.06814845183621833", "             1   1   1   -1e300")
    ffd_prm(p, r"w308y\.prm:\d+: weight -1e\+300 of control point \(1, 1, 1\) along y", "w308y.prm")


@case
def val_prm_nan():
    p = prm("wnan.prm", "parameter x: 0   0   0   0.0", "parameter x: 0   0   0   nan")
    ffd_prm(p, r"wnan\.prm:48: expected a finite number", "wnan.prm")
    p = prm("onan.prm", "box origin y: 0.0", "box origin y: -inf")
    ffd_prm(p, r"onan\.prm:\d+: 'box origin y' is not a number", "onan.prm")


@case
def val_prm_box():
    p = prm("flat.prm", "box length z: 1.0", "box length z: 0")
    ffd_prm(p, r"flat\.prm:\d+: 'box length z' is 0: the box is flat", "flat.prm")
    p = prm("huge.prm", "box length y: 1.0", "box length y: 1e200")
    ffd_prm(p, r"huge\.prm:\d+: 'box length y' is 1e\+200, beyond any mesh", "huge.prm")


# ---- an empty handles table ----
@case
def val_handles_empty():
    g = grid_obj("grid.obj")
    for name, text, pattern in [("h_header.csv", "node,dx,dy,dz\n", r"h_header\.csv: no rows after the header"),
                                ("h_blank.csv", "node,dx,dy,dz\n\n  \n", r"h_blank\.csv: no rows after the header"),
                                ("h_zero.csv", "", r"h_zero\.csv:1: expected the header")]:
        h = write(name, text)
        # the check comes before any method's work: shell for all, rbf once
        for method in ["shell"] + (["rbf"] if name == "h_header.csv" else []):
            run(["deform", "--mesh", g, "--handles", h, "--method", method, "-o", path("e.obj")], 2, pattern, [name])
            absent("e.obj")


# ---- the shell's surface: a repeated corner, a face without area ----
@case
def val_shell_repeated_corner():
    def repeat(verts, faces):
        a, b, c = faces[7]
        faces[7] = (a, a, c)
    g = grid_obj("rep.obj", repeat)
    h = write("h.csv", "node,dx,dy,dz\n14,0,0,0.1\n")
    run(["deform", "--mesh", g, "--handles", h, "--method", "shell", "-o", path("r.obj")], 2,
        r"rep\.obj: cell 7 \(0-based, tri3\): corners 1 and 2 are the same node \d+", ["rep.obj"])
    absent("r.obj")


@case
def val_shell_zero_area():
    def flatten(verts, faces):
        # the three corners of face 7 on one line: the middle one moved onto the others' segment
        a, b, c = faces[7]
        pa, pc = verts[a - 1], verts[c - 1]
        verts.append(tuple((x + y) / 2 for x, y in zip(pa, pc)))
        faces[7] = (a, len(verts), c)
    g = grid_obj("flat.obj", flatten)
    h = write("h.csv", "node,dx,dy,dz\n14,0,0,0.1\n")
    run(["deform", "--mesh", g, "--handles", h, "--method", "shell", "-o", path("z.obj")], 2,
        r"flat\.obj: cell 7 \(0-based, tri3, nodes .*\): the face has no area", ["flat.obj"])
    absent("z.obj")


# ---- every non-zero exit says why ----
@case
def val_optimize_rejected():
    # an inverted tet whose nodes are all on the boundary: nothing may move, it stays inverted
    m = tet_msh("inv.msh", ["0 0 0", "0 1 0", "1 0 0", "0 0 1"])
    run(["optimize", m, "-o", path("o.vtu")], 3,
        r"^cadmorph optimize: 1 inverted cell remains \(the worst: cell 0, 0-based, tet4, scaled Jacobian -?[0-9.]+\)",
        ["o.vtu"])


# ---- a path of thousands of characters: the reason stays ----
def long_line(p):
    line = p.stderr.strip()
    if len(line) >= MESSAGE_MAX:
        fail(f"a line of {len(line)} characters")


@case
def val_long_output_path():
    # 4,204 characters: a directory of one long component, then the file
    out = path("d" * (4204 - len(path("")) - len("/out.vtu")) + "/out.vtu")
    if len(out) != 4204:
        fail(f"path of {len(out)} characters")
    p = run(["ffd", "--mesh", tet_msh(), "--lattice", PRM, "-o", out], 2,
            r"/\.\.\./out\.vtu: cannot create a temporary file beside it: File name too long", ["out.vtu"])
    long_line(p)
    # one component of 4,200 characters: shortened in its middle, the end kept
    out = path("e" * (4200 - len(path(""))) + "_out.vtu")
    p = run(["ffd", "--mesh", tet_msh(), "--lattice", PRM, "-o", out], 2,
            r"e+\.\.\.e+_out\.vtu: .*File name too long", ["_out.vtu"])
    long_line(p)


@case
def val_long_input_path():
    # many ordinary components: the head and the file name, the reason after them
    deep = "/".join(["component%03d" % i for i in range(200)])
    m = path(deep + "/missing.msh")
    p = run(["quality", m], 2, r"/\.\.\./missing\.msh: cannot open: No such file or directory", ["missing.msh"])
    long_line(p)


if __name__ == "__main__":
    hostile.main()
