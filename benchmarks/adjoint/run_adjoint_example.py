#!/usr/bin/python3
"""OpenFOAM's continuous adjoint against a finite difference, through cadmorph's design
velocities: dJ/dp of the total pressure loss of a laminar duct flow for the two CAD parameters
of a bump on the duct's floor (bump_duct.py).

  1. G0 = the duct at (h, w), its structured hex mesh (gmsh) as the OpenFOAM case M0
     (gmshToFoam); G(h +- dh, w) and G(h, w +- dw) as STEP, and the design table listing them.
  2. adjointOptimisationFoam on M0: primal, adjoint, and the surface sensitivity map
     S = dJ/dx of every point of the wall patches (surfacePoints, E-SI, includeSurfaceArea),
     written as dJdXs.csv (`node,gx,gy,gz`, node = OpenFOAM point label = cadmorph node).
  3. `cadmorph morph` of M0 onto each perturbed STEP (a polyMesh in, its points out); the
     design velocity of parameter p_i is V_i = (X(p_i + d) - X(p_i - d)) / 2d per point.
  4. adjoint dJ/dp_i = sum over the wall points of S . V_i, and `cadmorph sensitivity
     --dJdXs` on the design table: its velocities and gradient must equal those of the two
     morphs (a one-step morph is linear in the boundary motion);
  5. finite difference: simpleFoam on both morphed meshes, (J+ - J-) / 2d.
Prints the table and writes it to WORK/results.csv; exits 1 when an adjoint gradient and its
finite difference differ by more than --tol (relative) or cadmorph sensitivity disagrees with
the morphs, 2 when a tool is missing or fails.

usage: run_adjoint_example.py CADMORPH WORK [--h 0.3 --w 0.8 --dh 0.01 --dw 0.02]
CADMORPH is the `cadmorph` program or a build directory holding cli/cadmorph."""
import argparse
import csv
import os
import shutil
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import foam_case  # noqa: E402

ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
ap.add_argument("cadmorph")
ap.add_argument("work")
ap.add_argument("--h", type=float, default=0.3, help="bump control-point height (default 0.3)")
ap.add_argument("--w", type=float, default=0.8, help="bump half-spread (default 0.8)")
ap.add_argument("--dh", type=float, default=0.01, help="finite-difference step of h")
ap.add_argument("--dw", type=float, default=0.02, help="finite-difference step of w")
ap.add_argument("--nx", type=int, default=60)
ap.add_argument("--ny", type=int, default=16)
ap.add_argument("--nz", type=int, default=16)
ap.add_argument("--nu", type=float, default=0.01, help="kinematic viscosity (Re = 1/nu)")
ap.add_argument("--iters", type=int, default=3000, help="SIMPLE iteration limit")
ap.add_argument("--res", type=float, default=1e-9, help="SIMPLE residual target")
ap.add_argument("--threads", default="2")
ap.add_argument("--tol", type=float, default=0.1,
                help="largest relative difference adjoint vs finite difference (default 0.1)")
a = ap.parse_args()

cli = a.cadmorph
if os.path.isdir(cli):
    cli = os.path.join(cli, "cli", "cadmorph")
cli = os.path.abspath(cli)
work = os.path.abspath(a.work)
ENV = dict(os.environ)
ENV.setdefault("WM_PROJECT_DIR", "/usr/share/openfoam")
for tool in ("gmshToFoam", "simpleFoam", "adjointOptimisationFoam", "checkMesh"):
    if not shutil.which(tool):
        sys.exit(print("run_adjoint_example: %s not found (Debian package openfoam)" % tool,
                       file=sys.stderr) or 2)
if not os.access(cli, os.X_OK):
    sys.exit(print("run_adjoint_example: no cadmorph at %s" % cli, file=sys.stderr) or 2)
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
seconds = {}


def run(cmd: list, cwd: str = work, log: str = None, what: str = None) -> str:
    """Runs cmd in cwd, its output to the file log there (or returned); adds its wall seconds
    to seconds[what]; exits 2 with the output's tail on failure."""
    t0 = time.time()
    out = open(os.path.join(cwd, log), "w") if log else subprocess.PIPE
    p = subprocess.run(cmd, cwd=cwd, env=ENV, stdout=out, stderr=subprocess.STDOUT, text=True)
    if log:
        out.close()
    seconds[what or cmd[0]] = seconds.get(what or cmd[0], 0.0) + time.time() - t0
    if p.returncode:
        text = open(os.path.join(cwd, log)).read() if log else p.stdout
        print("run_adjoint_example: %s failed (exit %d):\n%s" % (" ".join(cmd), p.returncode,
              text[-3000:]), file=sys.stderr)
        sys.exit(2)
    return p.stdout if not log else None


def geometry(h: float, w: float, name: str) -> str:
    """Writes the duct at (h, w) as the STEP file name in work; returns name."""
    run([sys.executable, os.path.join(HERE, "bump_duct.py"), "step", repr(h), repr(w), name],
        what="gmsh")
    return name


def case_dicts(case: str) -> None:
    """The dictionaries and initial fields of every case of this run."""
    foam_case.write_dicts(case, a.nu, 1.0, a.iters, a.res)


# 1. geometries, design table, M0
params = {"h": (a.h, a.dh), "w": (a.w, a.dw)}
g0 = geometry(a.h, a.w, "G0.step")
rows = [("G0.step", a.h, a.w)]
perturbed = {}
for name, (val, d) in params.items():
    for sign, tag in ((1, "p"), (-1, "m")):
        h = a.h + sign * d if name == "h" else a.h
        w = a.w + sign * d if name == "w" else a.w
        step = geometry(h, w, "G_%s%s.step" % (name, tag))
        rows.append((step, h, w))
        perturbed[(name, sign)] = step
with open(os.path.join(work, "design_table.csv"), "w", newline="") as f:
    csv.writer(f).writerows([("step", "h", "w")] + [(s, repr(h), repr(w)) for s, h, w in rows])
run([sys.executable, os.path.join(HERE, "bump_duct.py"), "mesh", g0, "M0.msh", "--nx",
     str(a.nx), "--ny", str(a.ny), "--nz", str(a.nz)], what="gmsh")
base = os.path.join(work, "M0")
case_dicts(base)
run(["gmshToFoam", "../M0.msh"], cwd=base, log="log.gmshToFoam")
foam_case.set_wall_patches(base)
run(["checkMesh"], cwd=base, log="log.checkMesh")
x0 = foam_case.read_points(base)
walls = foam_case.patch_points(base, foam_case.WALLS)
ends = foam_case.patch_points(base, ("inlet", "outlet"))
n_cells = int(open(os.path.join(base, "log.checkMesh")).read().split("cells:")[1].split()[0])
# dJdXs.csv numbers nodes by OpenFOAM point label: cadmorph must read a polyMesh's nodes in
# the order of its points file. Checked with the build's Python package when it is there.
pkg = os.path.join(os.path.dirname(os.path.dirname(cli)), "python")
node_order = "not checked (no Python package beside the CLI)"
if os.path.isfile(os.path.join(pkg, "cadmorph", "__init__.py")):
    sys.path.insert(0, pkg)
    import cadmorph  # noqa: E402

    if not np.array_equal(np.asarray(cadmorph.read_mesh(base).points), x0):
        sys.exit(print("run_adjoint_example: cadmorph's nodes are not the polyMesh's points in "
                       "file order", file=sys.stderr) or 2)
    node_order = "cadmorph's node i is OpenFOAM's point i (checked)"

# 2. the adjoint on M0 (its own primal first)
run(["adjointOptimisationFoam"], cwd=base, log="log.adjointOptimisationFoam")
adj_its, adj_res = foam_case.final_residuals(os.path.join(base, "log.adjointOptimisationFoam"),
                                             ("Ux", "p", "Uax", "pa"))
last = sorted((d for d in os.listdir(base) if d.replace(".", "").isdigit() and d != "0"),
              key=float)[-1]
sens = foam_case.read_point_vectors(os.path.join(base, last, "pointSensVecas1ESI"))
sens_n = foam_case.read_point_vectors(os.path.join(base, last, "pointSensNormalVecas1ESI"))
j0_adjoint = foam_case.last_row(os.path.join(base, "optimisation", "objective", "0",
                                             "lossesas1"))[1]
off_wall = np.setdiff1d(np.arange(len(x0)), walls)
if np.abs(sens[off_wall]).max() != 0:
    sys.exit(print("run_adjoint_example: sensitivity off the wall patches", file=sys.stderr) or 2)
with open(os.path.join(work, "dJdXs.csv"), "w", newline="") as f:
    wr = csv.writer(f)
    wr.writerow(("node", "gx", "gy", "gz"))
    for i in walls:
        wr.writerow((int(i),) + tuple("%.17g" % v for v in sens[i]))

# the primal alone on M0: its J must be the adjoint run's (same definition, same mesh)
prim0 = os.path.join(work, "M0_primal")
case_dicts(prim0)
shutil.copytree(os.path.join(base, "constant", "polyMesh"),
                os.path.join(prim0, "constant", "polyMesh"))
run(["simpleFoam"], cwd=prim0, log="log.simpleFoam")
j0 = foam_case.primal_objective(prim0)

# 3.-5. morphs, velocities, primal runs
velocity, jpm, primal_info, morph_sj = {}, {}, {}, {}
for name, (val, d) in params.items():
    xs = {}
    for sign in (1, -1):
        case = os.path.join(work, "M_%s%s" % (name, "p" if sign > 0 else "m"))
        out = run([cli, "morph", "--from", g0, "--to", perturbed[(name, sign)], "--mesh", base,
                   "-o", case, "--steps", "1", "--threads", a.threads], what="cadmorph morph")
        morph_sj[(name, sign)] = out.strip().splitlines()[-1]
        case_dicts(case)
        run(["checkMesh"], cwd=case, log="log.checkMesh")
        run(["simpleFoam"], cwd=case, log="log.simpleFoam")
        jpm[(name, sign)] = foam_case.primal_objective(case)
        primal_info[(name, sign)] = foam_case.final_residuals(os.path.join(case, "log.simpleFoam"),
                                                              ("Ux", "p"))
        xs[sign] = foam_case.read_points(case)
    v = (xs[1] - xs[-1]) / (2 * d)
    if np.abs(v[ends]).max() > 1e-9:
        sys.exit(print("run_adjoint_example: inlet/outlet points moved", file=sys.stderr) or 2)
    velocity[name] = v
with open(os.path.join(work, "velocity_fd.csv"), "w", newline="") as f:
    wr = csv.writer(f)
    wr.writerow(["node"] + ["dX_d%s_%s" % (p, c) for p in params for c in "xyz"])
    for i in range(len(x0)):
        wr.writerow([i] + ["%.17g" % velocity[p][i, k] for p in params for k in range(3)])

# `cadmorph sensitivity` on the same table: its boundary velocities are the same differences
# of surface morphs as the morphs' boundary positions, and a one-step morph is linear in the
# boundary motion, so its velocities equal the finite differences of the two morphs (to the
# warp's solve tolerance) and its gradient from the boundary sensitivity equals S.V
run([cli, "sensitivity", "--from", g0, "--mesh", base, "--design-table", "design_table.csv",
     "-o", "sensitivity", "--dJdXs", "dJdXs.csv", "--threads", a.threads],
    what="cadmorph sensitivity")
cm_grad = {}
with open(os.path.join(work, "sensitivity", "gradient.csv")) as f:
    for r in csv.DictReader(f):
        cm_grad[r["parameter"]] = float(r["dJdp"])
cm_vel = np.loadtxt(os.path.join(work, "sensitivity", "velocity.csv"), delimiter=",",
                    skiprows=1)
vel_gap = {}
for k, name in enumerate(params):
    v = cm_vel[:, 4 + 3 * k:7 + 3 * k]
    vel_gap[name] = float(np.abs(v - velocity[name]).max() / np.abs(velocity[name]).max())

# the table
print("case: duct 6 x 1 x 1 with a B-spline bump (h=%g, w=%g), %d hexes, %d points (%d on the "
      "wall patches), laminar nu=%g (Re=%g on the height), PtLosses on inlet+outlet"
      % (a.h, a.w, n_cells, len(x0), len(walls), a.nu, 1 / a.nu))
print("adjointOptimisationFoam: converged in %s iterations (primal, adjoint); last initial "
      "residuals Ux %.1e p %.1e Uax %.1e pa %.1e" % (adj_its, adj_res["Ux"], adj_res["p"],
                                                    adj_res["Uax"], adj_res["pa"]))
print("J(M0): adjointOptimisationFoam %.12g, simpleFoam %.12g (rel. diff %.1e)"
      % (j0_adjoint, j0, abs(j0 - j0_adjoint) / abs(j0)))
print("node numbering: " + node_order)
hdr = ("parameter", "delta", "J(p-d)", "J(p+d)", "FD dJ/dp", "adjoint S.V", "adjoint Sn.V",
       "cadmorph sensitivity", "rel.diff S.V vs FD")
print(" | ".join(hdr))
worst = 0.0
table = []
for name, (val, d) in params.items():
    fd = (jpm[(name, 1)] - jpm[(name, -1)]) / (2 * d)
    g = float(np.sum(sens[walls] * velocity[name][walls]))
    gn = float(np.sum(sens_n[walls] * velocity[name][walls]))
    rel = abs(g - fd) / abs(fd)
    worst = max(worst, rel)
    cmg = cm_grad[name]
    if abs(cmg - g) > 1e-8 * abs(g) or vel_gap[name] > 1e-6:
        sys.exit(print("run_adjoint_example: cadmorph sensitivity's %s differs from the morphs' "
                       "differences: gradient %.12g against %.12g, velocity %.1e of its largest"
                       % (name, cmg, g, vel_gap[name]), file=sys.stderr) or 1)
    row = (name, d, jpm[(name, -1)], jpm[(name, 1)], fd, g, gn, cmg, rel)
    table.append(row)
    print("%s | %g | %.10g | %.10g | %.6g | %.6g | %.6g | %.6g | %.2f%%"
          % (row[:-1] + (100 * rel,)))
for (name, sign), (its, res) in sorted(primal_info.items()):
    print("simpleFoam %s%+g: converged in %s iterations, last initial residuals Ux %.1e p %.1e;"
          " morph: %s" % (name, sign * params[name][1], its, res["Ux"], res["p"],
                          morph_sj[(name, sign)]))
print("seconds: " + ", ".join("%s %.1f" % kv for kv in seconds.items()))
with open(os.path.join(work, "results.csv"), "w", newline="") as f:
    wr = csv.writer(f)
    wr.writerow(("parameter", "delta", "J_minus", "J_plus", "dJdp_fd", "dJdp_adjoint",
                 "dJdp_adjoint_normal", "dJdp_cadmorph", "rel_diff"))
    wr.writerows(table)
print("cadmorph sensitivity against the morphs' central differences: velocities within "
      + ", ".join("%s %.1e" % kv for kv in vel_gap.items()) + " of the largest")
if worst > a.tol:
    print("run_adjoint_example: adjoint and finite difference differ by %.1f%% > %.1f%%"
          % (100 * worst, 100 * a.tol), file=sys.stderr)
    sys.exit(1)
