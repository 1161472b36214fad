#!/usr/bin/python3
"""Turns the key=value lines of bench_rbf.sh into the markdown table of RESULTS.md (RBF solvers).
usage: bench_rbf.sh ... | tee raw.txt; bench_rbf_table.py raw.txt"""
import shlex
import sys


def parse(line):
    return dict(kv.split("=", 1) for kv in shlex.split(line) if "=" in kv)


def main():
    ours, scipy = {}, {}
    for line in open(sys.argv[1]):
        if line.startswith("m="):
            r = parse(line)
            ours[int(r["m"])] = r
        elif line.startswith("scipy "):
            r = parse(line[6:])
            scipy[int(r["m"])] = r
    print("| m | n | fit s | fit / Cholesky bound | dgemm GF/s | eval s | pairs/s | peak RSS MB "
          "| scipy fit s | scipy eval s | scipy RSS MB | speed-up (fit+eval) | max diff / range |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for m in sorted(ours):
        o, s = ours[m], scipy.get(m)
        fit, ev = float(o["fit_s"]), float(o["eval_s"])
        row = [m, o["n"], f"{fit:.3f}", f"{float(o['fit_over_bound']):.2f}", o["dgemm_gflops"],
               f"{ev:.3f}", f"{float(o['eval_pairs_per_s']):.2e}", o["maxrss_mb"]]
        if s:
            sf, se = float(s["fit_s"]), float(s["eval_s"])
            row += [f"{sf:.2f}", f"{se:.2f}", s["maxrss_mb"], f"{(sf + se) / (fit + ev):.1f}x",
                    s["maxdiff_over_range"]]
        else:
            row += ["—", "—", "—", "—", "—"]
        print("| " + " | ".join(str(x) for x in row) + " |")
    print()
    for m in sorted(ours):
        print(f"- m={m}: {ours[m].get('phases', '')}; solve {ours[m]['solve_s']} s; "
              f"residual at centres {ours[m]['residual_rel']}")


if __name__ == "__main__":
    main()
