"""Markdown tables of the sweep section of RESULTS.md from the sweep.csv files of run_sweeps.sh.

Table 1, per model x mesh x mode x method: the first step with an inverted cell (of 20), min
scaled Jacobian at 50 and 100 %, worst boundary distance to G(t) over the sweep (x diagonal),
face nodes that left their trimmed face. Table 2, per model x mesh: the stages of the absolute
RBF-S sweep with node counts and threads: the one-time stages (classification of M(0), warp
factorisation) and the per-step ones (writing and sampling G(t), surface morph, warp
evaluation, quality, distance), each the median over steps 2..N.
Usage: summarize.py WORK_DIR   (reads WORK_DIR/*/sweep.csv)
"""
import csv
import glob
import os
import statistics
import sys


def load(work):
    runs = []
    for path in sorted(glob.glob(os.path.join(work, "*", "sweep.csv"))):
        with open(path, newline="") as f:
            rows = list(csv.DictReader(f))
        if rows:
            runs.append(rows)
    order = {"bore": 0, "pipe": 1, "bracket": 2}
    runs.sort(key=lambda rows: (order.get(rows[0]["model"], 9), rows[0]["mesh"] != "tet"))
    return runs


def main():
    runs = load(sys.argv[1])
    print("| model | mesh | mode | method | first inverted step | min SJ 50 % | min SJ 100 % "
          "| inverted at 100 % | max dist / diag | outside nodes (max) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for rows in runs:
        for mode in ("absolute", "relative"):
            for method in ("rbf-s", "project", "rbf-s-biharmonic"):
                s = [r for r in rows if r["mode"] == mode and r["method"] == method]
                if not s:
                    continue
                n = max(int(r["step"]) for r in rows)  # a stopped series has fewer rows
                inv = [int(r["step"]) for r in s if int(r["inverted"]) > 0]
                first = f"{inv[0]} ({100 * inv[0] / n:.0f} %)" if inv else "none"
                if len(s) < n:
                    first += f", stopped after step {len(s)}"
                half = [r for r in s if abs(float(r["percent"]) - 50) < 1e-6]
                last = s[-1]
                mid = f"{float(half[0]['min_scaled_jacobian']):.3f}" if half else "-"
                end = (f"{float(last['min_scaled_jacobian']):.3f} | {last['inverted']}"
                       if len(s) == n else "- | -")
                print(f"| {rows[0]['model']} | {rows[0]['mesh']} | {mode} | {method} | {first} "
                      f"| {mid} | {end} "
                      f"| {max(float(r['max_distance_rel']) for r in s):.1e} "
                      f"| {max(int(r['outside']) for r in s)} |")
    print()
    print("| model | mesh | nodes | boundary nodes | cells | threads | classify M(0) s "
          "| factorise s | sample G(t) s | surface s | evaluate s | quality s | distance s "
          "| step total s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for rows in runs:
        s = [r for r in rows if r["mode"] == "absolute" and r["method"] == "rbf-s"]
        if len(s) < 2:
            continue
        one = s[0]
        per = ["t_sample", "t_surface", "t_evaluation", "t_quality", "t_distance"]
        # a step without the one-time costs: the median of each stage over steps 2..N (the
        # machine is shared and noisy)
        two = {k: statistics.median(float(r[k]) for r in s[1:]) for k in per}
        total = sum(two[k] for k in per)
        print(f"| {one['model']} | {one['mesh']} | {one['nodes']} | {one['boundary_nodes']} "
              f"| {one['cells']} | {one['threads']} | {float(one['t_classify']):.3f} "
              f"| {float(one['t_volume_solve']):.3f} | "
              + " | ".join(f"{two[k]:.3f}" for k in per) + f" | {total:.3f} |")


if __name__ == "__main__":
    main()
