#!/usr/bin/python3
"""The Python package's overhead on a whole morph, side by side in one run: the same morph of
a mesh of G(0) onto G(1) of a built-in model by the CLI (`cadmorph morph`), by the library
from C (bench_morph.c: examples/morph_family.c's calls, each stage timed, compiled here
against BUILD_DIR) and by the package (read_step, read_mesh, Morpher, Morpher.apply,
write_mesh); then the interior warp of that morph's boundary motion by cadmorph.Warp and by
PyGeM's RBF with the same kernel (polyharmonic_spline, k = 3: phi = r^3, plus PyGeM's linear
polynomial, as cadmorph's "rbf"), when a PyGeM checkout is given.

usage: bench_overhead.py BUILD_DIR WORK_DIR [--model bore] [--size H] [--mesher gmsh|tetgen]
           [--no-optimize] [--hex-scale S] [--repeat N] [--rounds R] [--threads T]
           [--pygem PYGEM_DIR] [--pygem-mem GB]

Every program runs in its own process under /usr/bin/time, one at a time, so that each peak
resident set (its maxrss) is that program's alone. End to end (each process reads, makes the
morpher, applies it once, writes): R rounds alternate the CLI, C and Python; the best wall
time of each process and the best time of each stage are kept (Python's first apply includes
the correspondence check of a new target, cm_cad_compare). Then the same morpher is applied
REPEAT more times onto the same G(1): in one Python process Morpher.apply alternates with the
bare cm_morpher_apply through cffi on the same objects (the wrapper's own cost, free of the
noise between processes), and the C driver repeats its call. Ratios are Python / C. Every
child gets OPENBLAS_NUM_THREADS=1 (what the CLI sets for itself before OpenBLAS loads) and
the CLI's OpenBLAS core through OPENBLAS_CORETYPE, so all of them factorise on the same
kernels.

The mesh is WORK_DIR/M0_<model>_<size><g|t>[n].vtu from `cadmorph mesh` (made once, reused), or
with --hex-scale the model's structured hex mesh (`cadmorph model M 0 --hex-mesh --scale S`).
PyGeM's RBF is dense (an (n+4)^2 system, then an (N, n) distance matrix for the N points):
it is skipped, with the memory it would need, above --pygem-mem GB (default 8).
"""
import argparse
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def run_child(cmd, env, cwd=None):
    """Runs cmd; (stdout, stderr, wall s); exits on failure."""
    t = time.monotonic()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env, cwd=cwd,
                         text=True)
    out, err = p.communicate()
    wall = time.monotonic() - t
    if p.returncode != 0:
        sys.exit("failed (%d): %s\n%s%s" % (p.returncode, " ".join(cmd), out, err))
    return out, err, wall


def timed(cmd, env, cwd=None):
    """cmd under /usr/bin/time: (stdout, wall s, CPU s, peak RSS MB)."""
    tf = os.path.join(env["BENCH_WORK"], "time.txt")
    out, err, wall = run_child(["/usr/bin/time", "-o", tf, "-f", "%e %U %S %M"] + cmd, env, cwd)
    e, u, s, m = open(tf).read().split()[-4:]
    return out, float(e), float(u) + float(s), int(m) / 1024.0


# ---------------------------------------------------------------- children (one per process)

def child_python(a):
    """The package's morph: the C driver's stages through cadmorph; then, with inproc > 0,
    Morpher.apply against the bare library call (cffi, the same morpher, context and
    target) alternately in this one process."""
    t0 = time.perf_counter()
    import numpy as np
    import cadmorph
    from cadmorph._capi import ffi, lib
    t_import = time.perf_counter() - t0
    t = time.perf_counter()
    g0 = cadmorph.read_step(a["g0"])
    g1 = cadmorph.read_step(a["g1"])
    t_cad = time.perf_counter() - t
    t = time.perf_counter()
    mesh = cadmorph.read_mesh(a["m0"], threads=a["threads"])
    t_mesh = time.perf_counter() - t
    t = time.perf_counter()
    morpher = cadmorph.Morpher(g0, mesh, threads=a["threads"], progress=False)
    t_create = time.perf_counter() - t
    t = time.perf_counter()
    pts = morpher.apply(g1)
    t_apply = [time.perf_counter() - t]
    t_lib, c_lib, c_apply = [], [], [0.0]
    for _ in range(a["inproc"]):
        out = np.empty((mesh.n_nodes, 3))
        row = ffi.new("cm_morph_step *")
        c, t = time.process_time(), time.perf_counter()
        s = lib.cm_morpher_apply(morpher._ctx.ptr, morpher._mp, g1._ptr,
                                 ffi.from_buffer("double[]", out), row)
        t_lib.append(time.perf_counter() - t)
        c_lib.append(time.process_time() - c)
        if s < 0 or not np.array_equal(out, pts):
            raise SystemExit("the bare call differs from Morpher.apply (status %d)" % s)
        c, t = time.process_time(), time.perf_counter()
        pts = morpher.apply(g1)
        t_apply.append(time.perf_counter() - t)
        c_apply.append(time.process_time() - c)
    t = time.perf_counter()
    out = morpher.mesh
    out.points = pts
    cadmorph.write_mesh(a["m1"], out, threads=a["threads"])
    t_write = time.perf_counter() - t
    row = morpher.steps[-1]
    return dict(import_=t_import, read_cad=t_cad, read_mesh=t_mesh, create=t_create,
                apply=t_apply, lib=t_lib, apply_cpu=c_apply, lib_cpu=c_lib, write=t_write,
                nodes=mesh.n_nodes,
                boundary=morpher.info.boundary_nodes, min_sj=row.min_sj,
                inverted=row.inverted)


def child_warp(a):
    """cadmorph.Warp of the boundary motion M0 -> M1: fit, apply; saves nodes, D and the
    result for the PyGeM child."""
    import numpy as np
    import cadmorph
    m0 = cadmorph.read_mesh(a["m0"])
    x1 = cadmorph.read_mesh(a["m1"]).points
    t = time.perf_counter()
    w = cadmorph.Warp(m0, None, method="rbf", threads=a["threads"], progress=False)
    t_fit = time.perf_counter() - t
    d = x1[w.nodes] - m0.points[w.nodes]
    t = time.perf_counter()
    u = w.apply(d)
    t_apply = time.perf_counter() - t
    np.savez(a["npz"], x0=m0.points, nodes=w.nodes, d=d, u=u)
    return dict(fit=t_fit, apply=t_apply, boundary=len(w.nodes), nodes=m0.n_nodes)


def child_pygem(a):
    """PyGeM's RBF of the same boundary motion, every node evaluated."""
    import numpy as np
    sys.path.insert(0, a["pygem"])
    from pygem import RBF
    z = np.load(a["npz"])
    x0, nodes, d, u = z["x0"], z["nodes"], z["d"], z["u"]
    b0 = x0[nodes]
    t = time.perf_counter()
    rbf = RBF(original_control_points=b0, deformed_control_points=b0 + d,
              func="polyharmonic_spline", radius=1.0, extra_parameter={"k": 3})
    t_fit = time.perf_counter() - t
    t = time.perf_counter()
    x1 = rbf(x0)
    t_apply = time.perf_counter() - t
    diff = float(np.abs((x1 - x0) - u).max())
    return dict(fit=t_fit, apply=t_apply, diff=diff, scale=float(np.abs(u).max()))


def child_main(mode, arg):
    """Runs one child and prints its result as JSON."""
    print(json.dumps({"python": child_python, "warp": child_warp,
                      "pygem": child_pygem}[mode](json.loads(arg))))


# ---------------------------------------------------------------- the parent

def pygem_gb(n, big_n):
    """What PyGeM's dense RBF holds at its peak for n centres and N points, GB: in the fit
    the distances, the kernel matrix, the bordered system and the solver's copy (~5 n^2
    doubles), in the evaluation the (N, n) distances, kernel values and a temporary."""
    return 8.0 * (5.0 * n * n + 3.0 * big_n * n) / 2 ** 30


def machine(cli, env):
    """CPU model, cores, the CLI's BLAS lines."""
    cpu = "?"
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            cpu = line.split(":", 1)[1].strip()
            break
    fam = re.search(r"cpu family\s*:\s*(\d+)", open("/proc/cpuinfo").read())
    version = subprocess.run([cli, "--version"], capture_output=True, text=True,
                             env=env).stdout.strip().splitlines()
    load = open("/proc/loadavg").read().split()[:3]
    return cpu, fam.group(1) if fam else "?", os.cpu_count(), version, load


def main():
    if len(sys.argv) >= 2 and sys.argv[1] == "--child":
        return child_main(sys.argv[2], sys.argv[3])
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("build")
    ap.add_argument("work")
    ap.add_argument("--model", default="bore", choices=["bore", "pipe", "bracket"])
    ap.add_argument("--size", type=float, default=0.3)
    ap.add_argument("--mesher", default="gmsh", choices=["gmsh", "tetgen"])
    ap.add_argument("--no-optimize", action="store_true")
    ap.add_argument("--hex-scale", type=float)
    ap.add_argument("--repeat", type=int, default=5)  # 0: no repeated applies
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--pygem", help="a PyGeM checkout (the directory holding pygem/)")
    ap.add_argument("--pygem-mem", type=float, default=8.0,
                    help="GB PyGeM may need (estimate) before it is skipped (default 8)")
    a = ap.parse_args()
    build, work = os.path.abspath(a.build), os.path.abspath(a.work)
    os.makedirs(work, exist_ok=True)
    cli = os.path.join(build, "cli", "cadmorph")
    env = dict(os.environ, PYTHONPATH=os.path.join(build, "python"), PYTHONDONTWRITEBYTECODE="1",
               OPENBLAS_NUM_THREADS="1", BENCH_WORK=work)
    env.pop("CADMORPH_LIBRARY", None)
    m = re.search(r"^BLAS core: (\w+)", subprocess.run([cli, "--version"], capture_output=True,
                                                       text=True).stdout, re.MULTILINE)
    if m and "OPENBLAS_CORETYPE" not in env:
        env["OPENBLAS_CORETYPE"] = m.group(1)

    g0, g1 = os.path.join(work, a.model + "_0.step"), os.path.join(work, a.model + "_1.step")
    for t, g in ((0, g0), (1, g1)):
        if not os.path.exists(g):
            run_child([cli, "model", a.model, str(t), g], env)
    if a.hex_scale:
        m0 = os.path.join(work, "M0_%s_hex%g.vtu" % (a.model, a.hex_scale))
        make = [cli, "model", a.model, "0", "--hex-mesh", m0, "--scale", str(a.hex_scale)]
    else:
        m0 = os.path.join(work, "M0_%s_%g%s%s.vtu" % (a.model, a.size, a.mesher[0],
                                                     "n" if a.no_optimize else ""))
        make = [cli, "mesh", g0, "-o", m0, "--size", str(a.size), "--mesher", a.mesher] + \
            (["--no-optimize"] if a.no_optimize else [])
    if not os.path.exists(m0):
        print("$ " + " ".join(make), flush=True)
        t = time.monotonic()
        run_child(make, env)
        print("  %.1f s" % (time.monotonic() - t), flush=True)

    exe = os.path.join(work, "bench_morph")
    subprocess.run(["cc", "-O2", "-std=c11", "-Wall", "-Wextra", "-Werror",
                    "-I" + os.path.join(ROOT, "include"),
                    "-I" + os.path.join(build, "include"), os.path.join(HERE, "bench_morph.c"),
                    "-o", exe, "-L" + build, "-lcadmorph", "-Wl,-rpath," + build], check=True)

    cpu, fam, cores, version, load = machine(cli, env)
    import numpy
    print("machine: %s (family %s), %d cores, load %s; Python %s, numpy %s"
          % (cpu, fam, cores, " ".join(load), platform.python_version(), numpy.__version__))
    print("\n".join("  " + v for v in version))
    print("threads %d, OPENBLAS_CORETYPE=%s, OPENBLAS_NUM_THREADS=1; mesh %s"
          % (a.threads, env.get("OPENBLAS_CORETYPE", "-"), os.path.basename(m0)), flush=True)

    me = [sys.executable, os.path.abspath(__file__), "--child"]
    args = dict(g0=g0, g1=g1, m0=m0, threads=a.threads)
    m1_c = os.path.join(work, "m1_c.vtu")
    proc, stage = {}, {"c": {}, "py": {}}

    def keep(key, wall, cpu_s, rss, stages):
        b = proc.get(key)
        if b is None or wall < b[0]:
            proc[key] = (wall, cpu_s, max(rss, b[2] if b else 0))
        else:
            proc[key] = (b[0], b[1], max(rss, b[2]))
        for k, v in stages.items():
            if isinstance(v, float):
                stage[key][k] = min(v, stage[key].get(k, v))

    def c_run(repeat):
        out, wall, cpu_s, rss = timed([exe, g0, g1, m0, m1_c, str(repeat), str(a.threads)], env)
        w = out.split()
        c = {k: (v if k == "blas" else [float(x) for x in v.split(",")]
                 if k.startswith("apply") else float(v)) for k, v in zip(w[0::2], w[1::2])}
        return c, wall, cpu_s, rss

    # end to end: one apply per process, the best of R rounds
    for r in range(a.rounds):
        walls = []
        out, wall, cpu_s, rss = timed([cli, "morph", "--from", g0, "--to", g1, "--mesh", m0,
                                       "-o", os.path.join(work, "m1_cli.vtu"), "--threads",
                                       str(a.threads)], env)
        keep("cli", wall, cpu_s, rss, {})
        walls.append(wall)
        c, wall, cpu_s, rss = c_run(1)
        keep("c", wall, cpu_s, rss, dict(c, apply=c["apply"][0], apply_cpu=None))
        walls.append(wall)
        out, wall, cpu_s, rss = timed(me + ["python", json.dumps(
            dict(args, inproc=0, m1=os.path.join(work, "m1_py.vtu")))], env)
        py = json.loads(out.strip().splitlines()[-1])
        keep("py", wall, cpu_s, rss, dict(py, apply=py["apply"][0], apply_cpu=None))
        walls.append(wall)
        print("round %d: CLI %.2f s, C %.2f s, Python %.2f s" % tuple([r + 1] + walls),
              flush=True)

    c, p = stage["c"], stage["py"]
    print("\nmesh: %d nodes, %d boundary nodes; morph: min scaled Jacobian %.4f, %d inverted"
          % (py["nodes"], py["boundary"], py["min_sj"], py["inverted"]))
    print("\nEnd to end, one apply per process, best of %d rounds per stage:" % a.rounds)
    print("\n| stage | C (library) s | Python s | Python / C |")
    print("|---|---:|---:|---:|")
    for name, k in (("read G0, G1", "read_cad"), ("read M0", "read_mesh"),
                    ("Morpher() / cm_morpher_create", "create"),
                    ("Morpher.apply / cm_morpher_apply (first)", "apply"),
                    ("write M1", "write")):
        print("| %s | %.3f | %.3f | %.3f |" % (name, c[k], p[k], p[k] / c[k]))
    print("| import cadmorph | – | %.3f | |" % p["import_"])
    print("\n| process | wall s | CPU s | peak RSS MB | / CLI: wall, RSS |")
    print("|---|---:|---:|---:|---:|")
    for key, name in (("cli", "cadmorph morph"), ("c", "C (bench_morph.c)"),
                      ("py", "Python (cadmorph)")):
        wall, cpu_s, rss = proc[key]
        print("| %s | %.2f | %.2f | %.0f | %.3f, %.3f |" % (
            name, wall, cpu_s, rss, wall / proc["cli"][0], rss / proc["cli"][2]))

    # the same morpher applied again: the wrapper against the bare call in one process, and
    # the C driver's repeated calls
    if a.repeat > 0:
        out, wall, cpu_s, rss = timed(me + ["python", json.dumps(
            dict(args, inproc=a.repeat, m1=os.path.join(work, "m1_py.vtu")))], env)
        py = json.loads(out.strip().splitlines()[-1])
        c, wall, cpu_s, rss = c_run(a.repeat + 1)
        import numpy as np
        print("\nApplied again onto the same G(1), %d times (in the Python process the bare "
              "call and Morpher.apply alternate); wall and the process's CPU seconds:"
              % a.repeat)
        print("\n| call | wall best s | wall median s | CPU median s | / bare call: wall "
              "best, wall median, CPU median |")
        print("|---|---:|---:|---:|---:|")
        ref = (min(py["lib"]), np.median(py["lib"]), np.median(py["lib_cpu"]))
        for name, t, u in (("Morpher.apply (Python)", py["apply"][1:], py["apply_cpu"][1:]),
                           ("cm_morpher_apply through cffi, same process", py["lib"],
                            py["lib_cpu"]),
                           ("cm_morpher_apply from C (bench_morph.c)", c["apply"][1:],
                            c["apply_cpu"][1:])):
            v = (min(t), np.median(t), np.median(u))
            print("| %s | %.4f | %.4f | %.4f | %.3f, %.3f, %.3f |" % (
                (name,) + v + tuple(x / r for x, r in zip(v, ref))))

    # the warp of the same boundary motion: cadmorph.Warp against PyGeM's RBF
    npz = os.path.join(work, "warp_motion.npz")
    wa = dict(m0=m0, m1=m1_c, threads=a.threads, npz=npz)
    out, wall, cpu_s, rss = timed(me + ["warp", json.dumps(wa)], env)
    cw = json.loads(out.strip().splitlines()[-1])
    print("\nwarp of the morph's boundary motion (%d boundary nodes, %d nodes):"
          % (cw["boundary"], cw["nodes"]))
    print("\n| | fit s | evaluation s | process wall s | CPU s | peak RSS MB |")
    print("|---|---:|---:|---:|---:|---:|")
    print("| cadmorph.Warp (rbf) | %.3f | %.3f | %.2f | %.2f | %.0f |"
          % (cw["fit"], cw["apply"], wall, cpu_s, rss))
    if not a.pygem:
        print("| PyGeM RBF | (no --pygem) | | | | |")
    elif pygem_gb(cw["boundary"], cw["nodes"]) > a.pygem_mem:
        n, big_n = cw["boundary"], cw["nodes"]
        print("| PyGeM RBF | skipped: ~%.0f GB (an (n+4)^2 system of %.1f GB, (N, n) distances "
              "of %.1f GB, and their copies) | | | | |" % (
                  pygem_gb(n, big_n), 8.0 * (n + 4) ** 2 / 2 ** 30, 8.0 * n * big_n / 2 ** 30))
    else:
        pa = dict(npz=npz, pygem=os.path.abspath(a.pygem))
        out, wall, cpu_s, rss = timed(me + ["pygem", json.dumps(pa)], env)
        pg = json.loads(out.strip().splitlines()[-1])
        print("| PyGeM RBF (polyharmonic_spline k=3) | %.3f | %.3f | %.2f | %.2f | %.0f |"
              % (pg["fit"], pg["apply"], wall, cpu_s, rss))
        print("\nPyGeM / cadmorph: fit %.1fx, evaluation %.1fx; largest difference of the "
              "displacements %.2e (largest displacement %.3g)"
              % (pg["fit"] / cw["fit"], pg["apply"] / cw["apply"], pg["diff"], pg["scale"]))
    shutil.rmtree(os.path.join(work, "__pycache__"), ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
