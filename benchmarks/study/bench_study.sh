#!/bin/sh
# An absolute study of 20 bore variants against a study of one (the last, t = 1):
# the classification of M0 and the warp factorisation are made once for the family, so the
# 20-variant study should cost at most 2 x the single one. Writes G0 and G(k/20), k = 1..20,
# with `cadmorph model`, a TetGen mesh of G0 with `cadmorph mesh`, then times `cadmorph study
# --mode absolute --methods rbf-s --write-meshes none` on both lists and prints one table row
# per mesh size (wall and CPU seconds from /usr/bin/time; one-time and per-variant stages from
# study.csv: one-time = classify + factorise, per variant = the median over variants of
# sample + surface + evaluation + distance; then the medians of those four stages of the
# 20-variant study, sample = STEP read + cm_cad_match).
# usage: bench_study.sh BUILD_DIR [WORK_DIR] [THREADS] [SIZE...]   (sizes default 0.25 0.15)
set -eu
build=${1:?usage: bench_study.sh BUILD_DIR [WORK_DIR] [THREADS] [SIZE...]}
work=${2:-$build/bench_study}
threads=${3:-2}
[ $# -ge 3 ] && shift 3 || shift $#
sizes=${*:-0.25 0.15}
cadmorph=${CADMORPH:-$build/cli/cadmorph}
mkdir -p "$work/v20" "$work/v1"
"$cadmorph" model bore 0 "$work/G0.step"
for k in $(seq 1 20); do
    "$cadmorph" model bore "$(awk -v k="$k" 'BEGIN { print k / 20 }')" "$work/v20/bore_$(printf %02d "$k").step"
done
cp "$work/v20/bore_20.step" "$work/v1/"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "BLAS: $(OPENBLAS_VERBOSE=2 "$cadmorph" info "$work/G0.step" 2>&1 | grep -m1 '^Core' || echo 'core not reported'), threads $threads"
echo "| mesh size | nodes | boundary nodes | variants | wall s | CPU s | one-time s | per variant s | wall ratio | CPU ratio | sample / surface / evaluation / distance s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for size in $sizes; do
    mesh=$work/M0_$size.vtu
    "$cadmorph" mesh "$work/G0.step" -o "$mesh" --size "$size" --mesher tetgen >/dev/null
    for n in 1 20; do
        /usr/bin/time -f "wall_s=%e user_s=%U sys_s=%S" -o "$work/time_$n.txt" \
            "$cadmorph" study --from "$work/G0.step" --mesh "$mesh" --variants "$work/v$n/*.step" \
            -o "$work/out_${size}_$n" --mode absolute --methods rbf-s --write-meshes none \
            --threads "$threads" >/dev/null
    done
    /usr/bin/python3 - "$work" "$size" <<'PY'
import csv, statistics, sys
work, size = sys.argv[1], sys.argv[2]
def times(n):
    kv = dict(f.split("=") for f in open(f"{work}/time_{n}.txt").read().split())
    return float(kv["wall_s"]), float(kv["user_s"]) + float(kv["sys_s"])
w1, c1 = times(1)
for n in (1, 20):
    rows = list(csv.DictReader(open(f"{work}/out_{size}_{n}/study.csv")))
    once = sum(float(rows[0][k]) for k in ("t_classify", "t_volume_solve"))
    per = statistics.median(sum(float(r[k]) for k in ("t_sample", "t_surface", "t_evaluation",
                                                        "t_distance")) for r in rows)
    w, c = times(n)
    split = " / ".join(f"{statistics.median(float(r['t_' + k]) for r in rows):.3f}"
                       for k in ("sample", "surface", "evaluation", "distance"))
    print(f"| {size} | {rows[0]['nodes']} | {rows[0]['boundary_nodes']} | {len(rows)} | {w:.1f} "
          f"| {c:.1f} | {once:.2f} | {per:.3f} | {w / w1:.2f} | {c / c1:.2f} | {split} |")
PY
done
