#!/usr/bin/python3
"""`cadmorph deform` end to end: a quad plate (surface) and a hex box (volume) written here,
MLS and RBF, the mean_curvature field and summary, the quality line, the shell of eq. 10
against scipy (1e-10), and the error paths.
usage: deform_cli.py CADMORPH DATA_DIR WORK_DIR"""
import os, re, subprocess, sys
import numpy as np
import meshio

from cli_case import CliCase

case = CliCase("deform_cli", "deform")
cad, work, check, run = case.cad, case.work, case.check, case.run

# plate: 21 x 21 vertices, quads; handle: the centre 3 x 3, lifted 0.1; the border fixed
n = 21
g = np.linspace(0, 1, n)
X, Y = np.meshgrid(g, g)
pts = np.c_[X.ravel(), Y.ravel(), np.zeros(n * n)]
quads = [[j * n + i, j * n + i + 1, (j + 1) * n + i + 1, (j + 1) * n + i]
         for j in range(n - 1) for i in range(n - 1)]
meshio.write("plate.vtk", meshio.Mesh(pts, [("quad", np.array(quads))]), binary=False)
centre = [j * n + i for j in range(9, 12) for i in range(9, 12)]
with open("plate_H.csv", "w") as f:
    f.write("node,dx,dy,dz\n" + "".join("%d,0,0,0.1\n" % v for v in centre))

rc, out, err = run("--mesh", "plate.vtk", "--handles", "plate_H.csv", "--fix-unlisted-boundary",
                   "--method", "mls", "--samples", "200", "-o", "plate_out.vtu")
check(rc == 0, "plate mls: exit %d %s" % (rc, err))
check(re.search(r"mean_curvature \(interior vertices\): before min=0 .* after min=\S+ mean=\S+ max=\S+", out),
      "plate: curvature summary: " + out)
if rc == 0:
    m = meshio.read("plate_out.vtu")
    H = np.ravel(m.point_data["mean_curvature"])
    d = m.point_data["displacement"]
    check(np.all(np.isfinite(H)) and H.max() > 0, "plate: mean_curvature field")
    check(abs(d[n * 10 + 10, 2] - 0.1) < 5e-3, "plate: centre lifted %g" % d[n * 10 + 10, 2])
    check(np.abs(d[0]).max() < 5e-3, "plate: corner fixed %s" % d[0])
    res = float(re.search(r"residual (\S+)", out).group(1))
    check(0 < res < 5e-3, "plate: residual %g" % res)

# the shell of eq. 10 (--method shell) against an independent scipy solve of the same system
import scipy.sparse as sp, scipy.sparse.linalg as spl
pz = pts.copy()
pz[:, 2] = 0.05 * np.sin(3 * pz[:, 0]) * np.cos(2 * pz[:, 1])  # not flat: a general surface
meshio.write("wavy.vtk", meshio.Mesh(pz, [("quad", np.array(quads))]), binary=False)
gs, gb, gf = 0.5, 1.0, 1e4
rc, out, err = run("--mesh", "wavy.vtk", "--handles", "plate_H.csv", "--fix-unlisted-boundary",
                   "--method", "shell", "--stretch", str(gs), "--bend", str(gb), "--fix", str(gf),
                   "-o", "wavy_shell.vtu")
check(rc == 0, "shell: exit %d %s" % (rc, err))
if rc == 0:
    tri = np.array([[q[0], q[f], q[f + 1]] for q in quads for f in (1, 2)])
    N = len(pz)
    K = sp.lil_matrix((N, N)); A = np.zeros(N)
    for t in tri:
        P = pz[t]
        nrm = np.cross(P[1] - P[0], P[2] - P[0]); a = np.linalg.norm(nrm) / 2; u = nrm / (2 * a)
        g = [np.cross(u, P[(q + 2) % 3] - P[(q + 1) % 3]) / (2 * a) for q in range(3)]
        for i in range(3):
            A[t[i]] += a / 3
            for j in range(3):
                K[t[i], t[j]] += a * g[i] @ g[j]
    K = K.tocsr()
    bnd = (np.min(pz[:, :2], axis=1) < 1e-9) | (np.max(pz[:, :2], axis=1) > 1 - 1e-9)
    con = bnd.copy(); con[centre] = True
    dbar = np.zeros((N, 3)); dbar[centre, 2] = 0.1
    F = sp.diags(np.where(con, A, 0))
    S = gs * K + gb * K @ sp.diags(1 / A) @ K + gf * F
    ref = spl.spsolve(S.tocsc(), gf * (F @ dbar))
    d = meshio.read("wavy_shell.vtu").point_data["displacement"]
    err_rel = np.abs(d - ref).max() / np.abs(ref).max()
    check(err_rel < 1e-10, "shell vs scipy: %g" % err_rel)
    print("shell vs scipy: relative %.2e" % err_rel)

# hex box 6^3 cells; handle: the face x = 1 moved by 0.1 in x, the rest of the boundary fixed
k = 7
g = np.linspace(0, 1, k)
Z, Y, X = np.meshgrid(g, g, g, indexing="ij")
pts = np.c_[X.ravel(), Y.ravel(), Z.ravel()]
idx = lambda i, j, l: (l * k + j) * k + i
hexes = [[idx(i, j, l), idx(i + 1, j, l), idx(i + 1, j + 1, l), idx(i, j + 1, l),
          idx(i, j, l + 1), idx(i + 1, j, l + 1), idx(i + 1, j + 1, l + 1), idx(i, j + 1, l + 1)]
         for l in range(k - 1) for j in range(k - 1) for i in range(k - 1)]
meshio.write("box.vtk", meshio.Mesh(pts, [("hexahedron", np.array(hexes))]), binary=False)
face = np.nonzero(pts[:, 0] > 1 - 1e-9)[0]
with open("box_H.csv", "w") as f:
    f.write("node,dx,dy,dz\n" + "".join("%d,0.1,0,0\n" % v for v in face))
for method in ("mls", "rbf"):
    rc, out, err = run("--mesh", "box.vtk", "--handles", "box_H.csv", "--fix-unlisted-boundary",
                       "--method", method, "-o", "box_%s.vtu" % method)
    check(rc == 0, "box %s: exit %d %s" % (method, rc, err))
    check(re.search(r"min_scaled_jacobian=(\S+) mean_scaled_jacobian=\S+ inverted=0 cells=216\n$", out),
          "box %s: quality line: %s" % (method, out))
    if rc == 0:
        d = meshio.read("box_%s.vtu" % method).point_data["displacement"]
        mid = np.nonzero((np.abs(pts[:, 0] - 0.5) < 1e-9) & (np.abs(pts[:, 1] - 0.5) < 1e-9) &
                         (np.abs(pts[:, 2] - 0.5) < 1e-9))[0][0]
        if method == "mls":
            check(0.01 < d[mid, 0] < 0.09, "box mls: interior node follows: %g" % d[mid, 0])
        else:
            # the same triharmonic interpolant as `cadmorph warp` of the same table (unlisted
            # boundary nodes stay there too); r^3 overshoots this step data at the centre
            w = subprocess.run([cad, "warp", "--mesh", "box.vtk", "--displacements", "box_H.csv",
                                "-o", "box_warp.vtu"], capture_output=True)
            dw = meshio.read("box_warp.vtu").point_data["displacement"]
            check(w.returncode == 0 and np.abs(d - dw).max() < 1e-12,
                  "box rbf vs warp: %g" % np.abs(d - dw).max())

# --method dmffd on the box: the handle face keeps its motion, the interior follows, valid
rc, out, err = run("--mesh", "box.vtk", "--handles", "box_H.csv", "--fix-unlisted-boundary",
                   "--method", "dmffd", "--lattice", "6", "-o", "box_dmffd.vtu")
check(rc == 0 and out.startswith("deform: dmffd, %d handle nodes" % len(face)), "box dmffd: exit %d %s %s" % (rc, out, err))
check(re.search(r"inverted=0 cells=216\n$", out), "box dmffd: quality line: " + out)
if rc == 0:
    d = meshio.read("box_dmffd.vtu").point_data["displacement"]
    check(np.abs(d[face, 0] - 0.1).max() == 0, "box dmffd: handles keep their motion")
    # least norm: the lattice moves the centre less than the RBF's 0.05 (0.008 here)
    check(0.004 < d[mid, 0] < 0.09, "box dmffd: interior node follows: %g" % d[mid, 0])
    res = float(re.search(r"residual (\S+)", out).group(1))
    check(0 < res < 0.1, "box dmffd: residual (the lattice's miss) %g" % res)
# a coarser clamp changes the least-squares solution
rc2, out2, _ = run("--mesh", "box.vtk", "--handles", "box_H.csv", "--fix-unlisted-boundary",
                   "--method", "dmffd", "--lattice", "6", "--clamp", "0.5", "-o", "box_dmffd2.vtu")
check(rc2 == 0 and re.search(r"residual (\S+)", out2).group(1) != re.search(r"residual (\S+)", out).group(1),
      "box dmffd --clamp 0.5 changes the residual: %s / %s" % (out, out2))

# the MLS options reach the deformation: cubature, coverage and weights change the result
base = None
for extra in ([], ["--cubature", "900"], ["--cover", "8"], ["--stretch", "0"], ["--bend", "0"]):
    rc, out, err = run("--mesh", "plate.vtk", "--handles", "plate_H.csv", "--fix-unlisted-boundary",
                       "--samples", "200", *extra, "-o", "plate_opt.vtu")
    check(rc == 0, "plate mls %s: exit %d %s" % (extra, rc, err))
    if rc:
        continue
    d = meshio.read("plate_opt.vtu").point_data["displacement"]
    if base is None:
        base = d
    else:
        check(np.abs(d - base).max() > 1e-6, "plate mls %s: same field as the defaults" % extra)

# a gmsh surface mesh (.msh: a spherical cap of triangles) in, the surface formats out
import gmsh
gmsh.initialize()
gmsh.option.setNumber("General.Verbosity", 0)
gmsh.model.add("cap")
gmsh.model.occ.addSphere(0, 0, 0, 1, 1, -np.pi / 2, 0.2, 2 * np.pi)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.12)
gmsh.model.mesh.generate(2)
gmsh.write("cap.msh")
gmsh.finalize()
cap = meshio.read("cap.msh")
top = np.nonzero(cap.points[:, 2] > 0.1)[0]
with open("cap_H.csv", "w") as f:
    f.write("node,dx,dy,dz\n" + "".join("%d,0,0,0.1\n" % v for v in top))
low = np.nonzero(cap.points[:, 2] < -0.9)[0]
with open("cap_F.csv", "w") as f:
    f.write("node\n" + "".join("%d\n" % v for v in low))
outs = {}
for method, fmt in (("mls", "obj"), ("rbf", "stl"), ("dmffd", "off"), ("mls", "vtu")):
    name = "cap_%s.%s" % (method, fmt)
    rc, out, err = run("--mesh", "cap.msh", "--handles", "cap_H.csv", "--fixed", "cap_F.csv",
                       "--method", method, "--samples", "300", "-o", name)
    check(rc == 0 and "mean_curvature (interior vertices)" in out, "gmsh cap %s -> %s: exit %d %s %s" % (method, fmt, rc, out, err))
    if rc == 0:
        m = meshio.read(name)
        outs[name] = m
        moved = m.points[top] - cap.points[top] if fmt != "stl" else None
        if moved is not None:
            check(np.abs(moved[:, 2] - 0.1).max() < 1e-2, "%s: handles lifted (%g)" % (name, np.abs(moved[:, 2] - 0.1).max()))
# the .obj written by mls reads back through cadmorph (a surface mesh in .obj in, .stl out)
if "cap_mls.obj" in outs:
    with open("capobj_H.csv", "w") as f:
        f.write("node,dx,dy,dz\n" + "".join("%d,0.05,0,0\n" % v for v in top))
    rc, out, err = run("--mesh", "cap_mls.obj", "--handles", "capobj_H.csv", "--fix-unlisted-boundary",
                       "--method", "rbf", "-o", "cap_again.stl")
    check(rc == 0, "obj in: exit %d %s" % (rc, err))

# a gmsh volume mesh (.msh of tets) through deform
vol = os.path.join(sys.argv[2], "msh", "box_hole_41.msh")
vm = meshio.read(vol)
vh = np.nonzero(vm.points[:, 0] > vm.points[:, 0].max() - 1e-9)[0]
with open("vol_H.csv", "w") as f:
    f.write("node,dx,dy,dz\n" + "".join("%d,%g,0,0\n" % (v, 0.02 * np.ptp(vm.points[:, 0])) for v in vh))
for method in ("mls", "dmffd"):
    rc, out, err = run("--mesh", vol, "--handles", "vol_H.csv", "--fix-unlisted-boundary",
                       "--method", method, "-o", "vol_%s.vtu" % method)
    check(rc == 0 and re.search(r"inverted=0 cells=\d+\n$", out), "gmsh volume %s: exit %d %s %s" % (method, rc, out, err))

# the MLS options of `cadmorph warp` (cm_warp_options.mls) and their place in morph's help
fields = []
for extra in ([], ["--samples", "120", "--cubature", "600", "--cover", "6", "--stretch", "0", "--bend", "2"]):
    w = subprocess.run([cad, "warp", "--mesh", "box.vtk", "--displacements", "box_H.csv", "--method", "mls",
                        *extra, "-o", "box_wmls.vtu"], capture_output=True, text=True)
    check(w.returncode == 0 and "inverted=0" in w.stdout, "warp mls %s: %s %s" % (extra, w.stdout, w.stderr))
    if w.returncode == 0:
        fields.append(meshio.read("box_wmls.vtu").point_data["displacement"])
check(len(fields) == 2 and np.abs(fields[0] - fields[1]).max() > 1e-4, "warp mls: options change the field")
w = subprocess.run([cad, "warp", "--mesh", "box.vtk", "--displacements", "box_H.csv", "--method", "mls",
                    "--cubature", "0", "-o", "box_wmls.vtu"], capture_output=True, text=True)
check(w.returncode == 1 and "--cubature: expected an integer in 1..1e8, got '0'" in w.stderr, "warp --cubature 0: " + w.stderr)
h = subprocess.run([cad, "morph", "--help"], capture_output=True, text=True)
check(all(o in h.stdout for o in ("--samples K", "--cubature N", "--cover S", "--stretch GS", "--bend GB")),
      "morph --help lists the MLS options")

# error paths
with open("bad_F.csv", "w") as f:
    f.write("node\n99999\n")
with open("clash_F.csv", "w") as f:
    f.write("node\n%d\n" % centre[0])
for args, code, msg in (
        (["--mesh", "plate.vtk", "-o", "x.vtu"], 1, "--handles is required"),
        (["--mesh", "plate.vtk", "--handles", "plate_H.csv", "--fixed", "bad_F.csv",
          "--fix-unlisted-boundary", "-o", "x.vtu"], 1, "exclude each other"),
        (["--mesh", "plate.vtk", "--handles", "plate_H.csv", "--fixed", "bad_F.csv", "-o", "x.vtu"],
         2, r"bad_F.csv:2: node 99999 out of range"),
        (["--mesh", "plate.vtk", "--handles", "plate_H.csv", "--fixed", "clash_F.csv", "-o", "x.vtu"],
         2, "both a handle and fixed"),
        (["--mesh", "plate.vtk", "--handles", "plate_H.csv", "--method", "ffd", "-o", "x.vtu"], 1,
         "unknown method"),
        (["--mesh", "plate.vtk", "--handles", "plate_H.csv", "--stretch", "-1", "-o", "x.vtu"], 1,
         "not a number"),
        (["--mesh", "plate.vtk", "--handles", "plate_H.csv", "--method", "dmffd", "--lattice", "3", "-o", "x.vtu"], 1,
         "--lattice: '3' is not an integer in 4..200"),
        (["--mesh", "plate.vtk", "--handles", "plate_H.csv", "--cover", "0", "-o", "x.vtu"], 1,
         "--cover: expected 1..64 samples covering every point, got .0."),
        (["--mesh", "plate.vtk", "--handles", "plate_H.csv", "-o", "x.ply"], 1, "unknown mesh extension"),
        (["--mesh", "plate.vtk", "--handles", "plate_H.csv", "-o", "plate.vtk"], 1, "is an input")):
    rc, out, err = run(*args)
    check(rc == code and re.search(msg, err), "%s: exit %d (want %d), %s" % (args, rc, code, err))
rc, out, err = run("--help")
check(rc == 0 and "usage: cadmorph deform" in out, "--help")
case.finish()
