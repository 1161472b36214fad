#!/usr/bin/python3
"""Markdown tables from bench_warp.sh's output (RESULTS.md, "Warp methods").
usage: bench_warp_table.py RUN.txt"""
import sys

rows = []
for line in open(sys.argv[1]):
    if line.startswith("mesh="):
        rows.append(dict(kv.split("=", 1) for kv in line.split()))

print("| mesh | nodes | boundary | method | set-up s | apply s (median) | 20-step study / one step | peak RSS MB | min SJ at the test motion | inverted | fallback nodes |")
print("|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|")
for r in rows:
    study = [k for k in r if k.startswith("study_")][0]
    print("| %s | %s | %s | %s | %.3f | %.4f | %s | %s | %s | %s | %s |" % (
        r["mesh"].replace(".msh", ""), r["nodes"], r["boundary"], r["method"],
        float(r["create_s"]), float(r["apply_median_s"]), r[study], r["rss_peak_mb"],
        r["min_sj"], r["inverted"], r["fallback"]))

cols = ["bore_hex_0.667.msh", "bore_tet_0.25.msh", "pipe_hex_1.msh", "pipe_tet_0.2.msh"]
print()
print("| method | Bore Hex | Bore Tet | Pipe Hex | Pipe Tet |")
print("|---|---:|---:|---:|---:|")
methods = []
for r in rows:
    if r["mesh"] in cols and r["method"] not in methods:
        methods.append(r["method"])
for m in methods:
    cells = []
    for c in cols:
        hit = [r for r in rows if r["mesh"] == c and r["method"] == m]
        cells.append("%.3f" % float(hit[0]["one_step_s"]) if hit else "-")
    print("| %s | %s |" % (m, " | ".join(cells)))
