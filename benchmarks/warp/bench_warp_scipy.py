#!/usr/bin/python3
"""`cadmorph warp` end to end against scipy's RBFInterpolator(kernel='cubic', degree=1) on the
same problem (benchmarks/RESULTS.md, RBF solvers): the boundary nodes of a tet mesh move by the displacement
field of a real CAD morph (the 'displacement' point data of a `cadmorph morph` output), the
interior follows the r^3 + linear interpolant.

Both sides run as child processes of this script, one after the other, on the same files,
each from reading the input to writing the moved mesh:
  cadmorph: `cadmorph warp --mesh M --displacements D.csv -o OUT.vtu [--solver S]
            --rbf-tol 1e-10` (scipy solves exactly: the comparison is of the interpolant, so
            the iterative solver is held to the RBF's 1e-10, not the mesh's tolerance)
  scipy:    meshio read, boundary nodes (faces of one tet), RBFInterpolator fit on them,
            evaluation at the interior nodes, meshio write
Reported per run: wall and CPU seconds (children's rusage), peak RSS, OpenBLAS's core (each
child runs with OPENBLAS_VERBOSE=2 and prints "Core: ..."), and the largest difference of
the moved nodes to scipy's divided by the range of the displacement data.

usage: bench_warp_scipy.py CADMORPH MESH.vtu MORPHED.vtu WORKDIR [SOLVER ...]
       (SOLVER: auto dense iterative; default auto. The scipy child is this file with
       --scipy.)
       bench_warp_scipy.py --csv MESH.vtu MORPHED.vtu D.csv   (only the displacement table)"""
import os
import resource
import subprocess
import sys
import time

import numpy as np


def boundary_nodes(tets):
    f = np.concatenate([tets[:, [0, 1, 2]], tets[:, [0, 1, 3]], tets[:, [0, 2, 3]],
                        tets[:, [1, 2, 3]]])
    f.sort(axis=1)
    u, c = np.unique(f, axis=0, return_counts=True)
    return np.unique(u[c == 1])


def scipy_child(mesh_path, csv_path, out_path):
    """The scipy side, end to end; prints fit and evaluation seconds."""
    import meshio
    import scipy
    from scipy.interpolate import RBFInterpolator
    t0 = time.perf_counter()
    m = meshio.read(mesh_path)
    tab = np.loadtxt(csv_path, delimiter=",", skiprows=1)
    node = tab[:, 0].astype(np.int64)
    disp = np.zeros_like(m.points)
    disp[node] = tab[:, 1:4]
    # the constrained nodes as cadmorph takes them: all boundary nodes (unlisted ones keep
    # zero displacement) and any listed interior node
    fixed = np.zeros(len(m.points), dtype=bool)
    fixed[boundary_nodes(m.cells_dict["tetra"])] = True
    fixed[node] = True
    t1 = time.perf_counter()
    interp = RBFInterpolator(m.points[fixed], disp[fixed], kernel="cubic", degree=1)
    t2 = time.perf_counter()
    disp[~fixed] = interp(m.points[~fixed])
    t3 = time.perf_counter()
    out = meshio.Mesh(m.points + disp, [("tetra", m.cells_dict["tetra"])],
                      point_data={"displacement": disp})
    out.write(out_path)
    t4 = time.perf_counter()
    print(f"scipy {scipy.__version__}: m={int(fixed.sum())} interior={int((~fixed).sum())} "
          f"read_s={t1 - t0:.2f} fit_s={t2 - t1:.2f} eval_s={t3 - t2:.2f} write_s={t4 - t3:.2f}")


def run(cmd, env):
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    if p.returncode != 0:
        sys.exit(f"{cmd[0]} failed ({p.returncode}): {p.stderr.strip()}")
    core = sorted({l.split(":", 1)[1].strip() for l in p.stderr.splitlines()
                   if l.startswith("Core:")})
    return wall, cpu, r1.ru_maxrss / 1024.0, ",".join(core) or "?", p


def write_csv(mesh_path, morphed_path, csv):
    """D.csv: the boundary nodes of MESH with the displacement the morph gave them."""
    import meshio
    mesh = meshio.read(mesh_path)
    disp = np.asarray(meshio.read(morphed_path).point_data["displacement"])
    b = boundary_nodes(mesh.cells_dict["tetra"])
    with open(csv, "w") as f:
        f.write("node,dx,dy,dz\n")
        for i in b:
            f.write(f"{i},{disp[i, 0]:.17g},{disp[i, 1]:.17g},{disp[i, 2]:.17g}\n")
    return mesh, b, disp[b].max() - disp[b].min()


def main():
    if sys.argv[1] == "--scipy":
        scipy_child(*sys.argv[2:5])
        return
    if sys.argv[1] == "--csv":
        write_csv(*sys.argv[2:5])
        return
    import meshio
    cadmorph, mesh_path, morphed_path, work = sys.argv[1:5]
    solvers = sys.argv[5:] or ["auto"]
    os.makedirs(work, exist_ok=True)
    csv = os.path.join(work, "boundary_disp.csv")
    mesh, b, rng = write_csv(mesh_path, morphed_path, csv)
    env = dict(os.environ, OPENBLAS_VERBOSE="2")
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} nproc={os.cpu_count()} "
          f"OPENBLAS_CORETYPE={os.environ.get('OPENBLAS_CORETYPE', '-')} "
          f"OMP_NUM_THREADS={os.environ.get('OMP_NUM_THREADS', '-')} "
          f"load={open('/proc/loadavg').read().split()[0]}")
    print(f"# {mesh_path}: {len(mesh.points)} nodes, {len(b)} boundary nodes, "
          f"{len(mesh.cells_dict['tetra'])} tets; data range {rng:.4g}")
    sp_out = os.path.join(work, "scipy_out.vtu")
    w, c, rss, core, p = run([sys.executable, __file__, "--scipy", mesh_path, csv, sp_out], env)
    print(f"scipy    wall_s={w:.2f} cpu_s={c:.2f} core={core} | {p.stdout.strip()}")
    ref = meshio.read(sp_out).points
    for s in solvers:
        out = os.path.join(work, f"cadmorph_{s}.vtu")
        cmd = [cadmorph, "warp", "--mesh", mesh_path, "--displacements", csv, "-o", out,
               "--solver", s, "--rbf-tol", "1e-10", "-v"]
        w2, c2, _, core2, p2 = run(cmd, env)
        ours = meshio.read(out).points
        diff = np.abs(ours - ref).max() / rng
        t = [l for l in p2.stderr.splitlines() if "warp: " in l and "create" in l]
        print(f"cadmorph --solver {s:9s} wall_s={w2:.2f} cpu_s={c2:.2f} core={core2} "
              f"speed-up_wall={w / w2:.2f} speed-up_cpu={c / c2:.2f} "
              f"maxdiff_over_range={diff:.2g} | {t[-1].split('warp: ', 1)[1] if t else ''}")


if __name__ == "__main__":
    main()
