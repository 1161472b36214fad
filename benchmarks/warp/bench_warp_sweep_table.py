#!/usr/bin/python3
"""Per-model tables from bench_warp_sweep output (RESULTS.md, "Warp methods in the sweeps"):
first inverted step, min scaled Jacobian at 50 % and 100 %, median time per step (surface
morph + warp set-up + evaluation).  usage: bench_warp_sweep_table.py OUT.txt..."""
import statistics
import sys

runs = {}
stopped = {}
for path in sys.argv[1:]:
    for line in open(path):
        if not line.startswith("model="):
            continue
        kv = {}
        for part in line.split(" "):
            if "=" in part:
                k, v = part.split("=", 1)
                kv[k] = v.strip()
        key = (kv["model"], kv["mesh"].replace(".msh", "").split("_")[-1], kv["mode"], kv["method"])
        if "stopped" in line:
            stopped[key] = int(kv["step"])
            continue
        runs.setdefault(key, []).append(kv)

order = ["rbf-s", "rbf", "rbf-s-biharmonic", "femwarp", "lbwarp", "simplex"]
models = sorted({k[:2] for k in runs}, key=lambda m: (["bore", "pipe", "bracket"].index(m[0]), m[1]))
for model, mesh in models:
    print("\n**%s %s**\n" % (model, mesh))
    print("| mode | method | steps | first inverted step | min SJ 50 % | min SJ 100 % | inverted at 100 % | time per step s |")
    print("|---|---|---:|---|---:|---:|---:|---:|")
    for mode in ("absolute", "relative"):
        for method in order:
            rows = runs.get((model, mesh, mode, method))
            if not rows:
                continue
            n = len(rows)
            steps = {int(r["step"]): r for r in rows}
            total = max(round(1 / float(rows[0]["t"])), 1) if float(rows[0]["t"]) > 0 else n
            first = next((r for r in rows if int(r["inverted"]) > 0), None)
            fi = "%s (%d %%)" % (first["step"], round(100 * float(first["t"]))) if first else "none"
            if (model, mesh, mode, method) in stopped:
                fi += ", stopped at step %d" % stopped[(model, mesh, mode, method)]
            half = steps.get(total // 2)
            full = steps.get(total)
            t = statistics.median(float(r["surface_s"]) + float(r["solve_s"]) + float(r["evaluate_s"])
                                  for r in rows[1:] or rows)
            print("| %s | %s | %d | %s | %s | %s | %s | %.3f |" % (
                mode, method, total, fi, half["min_sj"] if half else "-",
                full["min_sj"] if full else "-", full["inverted"] if full else "-", t))
