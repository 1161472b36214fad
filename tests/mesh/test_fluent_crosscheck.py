#!/usr/bin/python3
"""Cross-check of cadmorph's Fluent support against OpenFOAM v1912's own Fluent tools
(Debian's openfoam: foamMeshToFluent writes Fluent meshes, fluent3DMeshToFoam reads them):

  * the fixtures of tests/data/fluent: fluent3DMeshToFoam reads the same points as cadmorph;
  * an affine motion of every node written back (ASCII to .cas and .msh, binary double and
    single precision): fluent3DMeshToFoam (ASCII) or a reader of the binary layout here
    (to_binary.py's) finds the affine image to the file's precision, checkMesh passes, and
    every byte outside the node coordinates is the input's;
  * the CLI on a Fluent mesh of the bore model (its hex mesh through foamMeshToFluent):
    quality (as on the OpenFOAM case), morph onto G(1), warp, deform (a zone as a
    constraint set), optimize; every output is Fluent again, read by fluent3DMeshToFoam;
  * a mesh not read from Fluent written to .cas: exit 2, the refusal named.
Exit 77 (ctest SKIP) only when OpenFOAM's tools are not installed.
usage: test_fluent_crosscheck.py CADMORPH TESTS_DATA WORKDIR"""
import os
import re
import shutil
import struct
import subprocess
import sys

import numpy as np

CADMORPH, DATA, WORK = sys.argv[1], sys.argv[2], os.path.join(sys.argv[3], "fluent_cross")
TOOLS = ["foamMeshToFluent", "fluent3DMeshToFoam", "checkMesh"]
if any(shutil.which(t) is None for t in TOOLS):
    print("SKIP: OpenFOAM (Debian package openfoam: foamMeshToFluent, fluent3DMeshToFoam, checkMesh) is not installed")
    sys.exit(77)
FIX = os.path.join(DATA, "fluent")
sys.path.insert(0, FIX)
import to_binary  # noqa: E402  (the binary layout: the fixtures' own converter)
import cadmorph  # noqa: E402

ENV = dict(os.environ)
ENV.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")  # Debian keeps OpenFOAM's etc/ there
HEADER = "FoamFile { version 2.0; format ascii; class dictionary; object %s; }\n"
failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL:", msg)


def run(cmd, **kw):
    return subprocess.run(cmd, env=ENV, capture_output=True, text=True, **kw)


def foam_case(name):
    case = os.path.join(WORK, name)
    shutil.rmtree(case, ignore_errors=True)
    os.makedirs(os.path.join(case, "system"))
    os.makedirs(os.path.join(case, "constant"))
    with open(os.path.join(case, "system", "controlDict"), "w") as f:
        f.write(HEADER % "controlDict" +
                "application none; startFrom startTime; startTime 0; stopAt endTime; endTime 1; deltaT 1;\n"
                "writeControl timeStep; writeInterval 1; writeFormat ascii; writePrecision 17;\n"
                "writeCompression off; timeFormat general; timePrecision 6;\n")
    with open(os.path.join(case, "system", "fvSchemes"), "w") as f:
        f.write(HEADER % "fvSchemes" +
                "ddtSchemes { default steadyState; } gradSchemes { default Gauss linear; }\n"
                "divSchemes { default none; } laplacianSchemes { default Gauss linear corrected; }\n"
                "interpolationSchemes { default linear; } snGradSchemes { default corrected; }\n")
    with open(os.path.join(case, "system", "fvSolution"), "w") as f:
        f.write(HEADER % "fvSolution")
    return case


def foam_points(msh, name):
    """The points fluent3DMeshToFoam reads from msh (written with 17 digits), and whether
    checkMesh passes the converted mesh."""
    case = foam_case(name)
    p = run(["fluent3DMeshToFoam", "-case", case, msh])
    check(p.returncode == 0, "%s: fluent3DMeshToFoam exit %d: %s" % (name, p.returncode, p.stdout[-1500:]))
    with open(os.path.join(case, "constant", "polyMesh", "points")) as f:
        text = f.read()
    body = text[text.index("(", text.index("}")) + 1:]
    pts = np.array([[float(v) for v in t.split()] for t in re.findall(r"\(([^()]*)\)", body)])
    ok = "Mesh OK." in run(["checkMesh", "-case", case]).stdout
    return pts, ok


def without_nodes(data):
    """The file with the data of every node section removed (ASCII or binary)."""
    out, at = [], 0
    for m in re.finditer(rb"\((|20|30)10\s*\(\s*([0-9a-fA-F]+)\s+([0-9a-fA-F]+)\s+([0-9a-fA-F]+)[^)]*\)\s*\(", data):
        if int(m.group(2), 16) == 0:
            continue
        n = int(m.group(4), 16) - int(m.group(3), 16) + 1
        size = {b"": 0, b"20": 4, b"30": 8}[m.group(1)]
        end = m.end() + 3 * n * size if size else data.index(b")", m.end())
        out.append(data[at:m.end()])
        at = end
    out.append(data[at:])
    return b"".join(out)


def binary_points(data):
    """The node coordinates of a file with binary node sections, by the documented layout."""
    pts = []
    for m in re.finditer(rb"\((20|30)10\s*\(\s*([0-9a-fA-F]+)\s+([0-9a-fA-F]+)\s+([0-9a-fA-F]+)[^)]*\)\s*\(", data):
        n = int(m.group(4), 16) - int(m.group(3), 16) + 1
        fmt, size = ("<%dd", 8) if m.group(1) == b"30" else ("<%df", 4)
        pts += struct.unpack(fmt % (3 * n), data[m.end():m.end() + 3 * n * size])
    return np.array(pts).reshape(-1, 3)


def read(path):
    with open(path, "rb") as f:
        return f.read()


A = np.array([[1.1, 0.2, -0.05], [0.03, 0.95, 0.1], [-0.02, 0.07, 1.3]])
T = np.array([0.5, -1.25, 3e-3])

os.makedirs(WORK, exist_ok=True)

# 1. the fixtures: fluent3DMeshToFoam reads what cadmorph reads; an affine motion written back
for name in ["box", "mixed", "poly"]:
    src = os.path.join(FIX, name + ".msh")
    ref, ok = foam_points(src, name + "_in")
    with cadmorph.read_mesh(src) as m:
        check(np.array_equal(ref, m.points), "%s: fluent3DMeshToFoam reads other points than cadmorph" % name)
        moved = m.points @ A.T + T
        m.points = moved
        for ext in ["cas", "msh"] if name == "box" else ["cas"]:
            out = os.path.join(WORK, "%s_moved.%s" % (name, ext))
            cadmorph.write_mesh(out, m)
            got, ok = foam_points(out, "%s_moved_%s" % (name, ext))
            check(np.array_equal(got, moved), "%s.%s: the affine image does not read back exactly" % (name, ext))
            check(ok, "%s.%s: checkMesh fails on the moved mesh" % (name, ext))
            check(without_nodes(read(out)) == without_nodes(read(src)),
                  "%s.%s: bytes outside the node coordinates changed" % (name, ext))
for name, dtype in [("box_double", np.float64), ("poly_double", np.float64), ("mixed_single", np.float32)]:
    src = os.path.join(FIX, name + ".msh")
    with cadmorph.read_mesh(src) as m:
        check(np.array_equal(binary_points(read(src)), m.points), "%s: binary nodes read differently" % name)
        moved = m.points @ A.T + T
        m.points = moved
        out = os.path.join(WORK, name + "_moved.msh")
        cadmorph.write_mesh(out, m)
        data = read(out)
        check(np.array_equal(binary_points(data), moved.astype(dtype).astype(np.float64)),
              "%s: the affine image is not the written %s" % (name, dtype.__name__))
        check(without_nodes(data) == without_nodes(read(src)), "%s: bytes outside the node coordinates changed" % name)
        check(len(data) == len(read(src)), "%s: the file's size changed" % name)

# 2. the CLI on the bore model's hex mesh as a Fluent file
bore_case = os.path.join(WORK, "bore0_case")
shutil.rmtree(bore_case, ignore_errors=True)
g0, g1 = os.path.join(WORK, "bore_0.step"), os.path.join(WORK, "bore_1.step")
p = run([CADMORPH, "model", "bore", "0", g0, "--hex-mesh", bore_case + "/", "--scale", "0.3"])
check(p.returncode == 0, "model bore 0: %s" % p.stderr)
check(run([CADMORPH, "model", "bore", "1", g1]).returncode == 0, "model bore 1")
foam_case("bore0")  # system files for foamMeshToFluent
for f in os.listdir(os.path.join(WORK, "bore0", "system")):
    os.makedirs(os.path.join(bore_case, "system"), exist_ok=True)
    shutil.copy(os.path.join(WORK, "bore0", "system", f), os.path.join(bore_case, "system", f))
p = run(["foamMeshToFluent", "-case", bore_case])
check(p.returncode == 0, "foamMeshToFluent on the bore: %s" % p.stdout[-1000:])
bore = os.path.join(WORK, "bore0.msh")
shutil.copy(os.path.join(bore_case, "fluentInterface", "bore0_case.msh"), bore)


def summary(out):
    return out.strip().splitlines()[-1] if out.strip() else ""


q1, q2 = run([CADMORPH, "quality", bore]), run([CADMORPH, "quality", bore_case])
check(q1.returncode == 0 and summary(q1.stdout) == summary(q2.stdout),
      "quality on the Fluent file differs from the OpenFOAM case: %s | %s" % (summary(q1.stdout), q1.stderr))

morphed = os.path.join(WORK, "bore1.msh")
p = run([CADMORPH, "morph", "--from", g0, "--to", g1, "--mesh", bore, "-o", morphed])
check(p.returncode == 0 and "inverted=0" in summary(p.stdout), "morph: %s %s" % (p.stdout[-300:], p.stderr))
p2 = run([CADMORPH, "morph", "--from", g0, "--to", g1, "--mesh", bore, "-o", os.path.join(WORK, "bore1.vtu")])
check(p2.returncode == 0, "morph to .vtu: %s" % p2.stderr)
if p.returncode == 0 and p2.returncode == 0:
    check(read(morphed).startswith(b"(0 "), "morph: the output is not the Fluent file")
    got, ok = foam_points(morphed, "bore1")
    with cadmorph.read_mesh(os.path.join(WORK, "bore1.vtu")) as v:
        check(np.array_equal(got, v.points), "morph: the Fluent output's points differ from the .vtu output's")
    check(ok, "morph: checkMesh fails on the morphed Fluent mesh")
    check(without_nodes(read(morphed)) == without_nodes(read(bore)), "morph: bytes outside the node coordinates changed")

    opt = os.path.join(WORK, "bore1_opt.cas")
    p = run([CADMORPH, "optimize", morphed, "-o", opt])
    check(p.returncode == 0 and read(opt).startswith(b"(0 "), "optimize: %s" % p.stderr)

# warp: some boundary nodes of the inlet-side (x = min) moved; the rest follows
with cadmorph.read_mesh(bore) as m:
    x = m.points
    side = np.where(np.isclose(x[:, 0], x[:, 0].min()))[0]
    groups = {name: (dim, tag) for dim, tag, name in m.groups}
disp = os.path.join(WORK, "disp.csv")
with open(disp, "w") as f:
    f.write("node,dx,dy,dz\n" + "".join("%d,-0.1,0,0\n" % i for i in side))
warped = os.path.join(WORK, "bore_warped.msh")
p = run([CADMORPH, "warp", "--mesh", bore, "--displacements", disp, "-o", warped])
check(p.returncode == 0 and "inverted=0" in summary(p.stdout), "warp: %s %s" % (p.stdout[-300:], p.stderr))
if p.returncode == 0:
    got, ok = foam_points(warped, "bore_warped")
    check(np.allclose(got[side, 0], x[side, 0] - 0.1, rtol=0, atol=1e-12), "warp: the listed nodes did not move")
    check(ok, "warp: checkMesh fails")

# deform with a zone as constraint set: the bore's patches are Fluent face zones here
walls = [n for n in groups if groups[n][0] == 2]
check(len(walls) >= 1, "bore: face zones as groups: %s" % groups)
if walls:
    zone = walls[0]
    handles = os.path.join(WORK, "handles.csv")
    with open(handles, "w") as f:
        f.write("node,dx,dy,dz\n" + "".join("%d,0,0,0.05\n" % i for i in side[:20]))
    deformed = os.path.join(WORK, "bore_deformed.msh")
    p = run([CADMORPH, "deform", "--mesh", bore, "--handles", handles, "--fix-unlisted-boundary", "--method", "mls",
             "--constraint", "rigid:" + zone, "-o", deformed])
    check(p.returncode == 0 and read(deformed).startswith(b"(0 "), "deform --constraint rigid:%s: %s" % (zone, p.stderr))

# a mesh that was not read from Fluent cannot become a .cas
p = run([CADMORPH, "warp", "--mesh", os.path.join(WORK, "bore1.vtu"), "--displacements", disp,
         "-o", os.path.join(WORK, "new.cas")])
check(p.returncode == 2 and "Fluent" in p.stderr and len(p.stderr.strip().splitlines()) == 1,
      "a new .cas: exit %d: %s" % (p.returncode, p.stderr))
check(not os.path.exists(os.path.join(WORK, "new.cas")), "a refused .cas was written")

print("%d failures" % len(failures))
sys.exit(1 if failures else 0)
