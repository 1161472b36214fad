#!/usr/bin/python3
"""SVG plot of bench_kernel_columns: bench_kernel_columns_plot.py OUTPUT.txt PLOT.svg

CPU seconds per column per 1e10 pairs against the number of columns, per sum, beside the
FMA bound of the same run (one FMA per pair and column). Debian's python3-matplotlib.
"""
import sys

import matplotlib

matplotlib.use("svg")
import matplotlib.pyplot as plt  # noqa: E402

series, bound = {}, None
for line in open(sys.argv[1]):
    kv = dict(f.split("=", 1) for f in line.split() if "=" in f)
    if line.startswith("fma_bound"):
        bound = 1e10 / float(kv["pair_columns_per_cpu_s"])
    elif line.startswith("sum=") and kv["sum"] != "tree_eval":  # tree: not direct pairs
        s = series.setdefault(kv["sum"], ([], []))
        s[0].append(int(kv["nc"]))
        s[1].append(float(kv["cpu_s_per_col_per_1e10_pairs"]))
fig, ax = plt.subplots(figsize=(6, 4))
for name, (nc, cost) in series.items():
    ax.plot(nc, cost, marker="o", label=name)
if bound:
    ax.axhline(bound, color="k", linestyle="--", label="FMA bound")
ax.set_xscale("log")
ax.set_yscale("log")
ax.set_xlabel("columns (right-hand sides) per pass")
ax.set_ylabel("CPU s per column per 1e10 pairs")
ax.legend()
fig.tight_layout()
fig.savefig(sys.argv[2])
