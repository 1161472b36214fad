#!/bin/sh
# Meshes the three benchmark models at t = 0 at two sizes each (about 20k and 150k nodes) with
# `cadmorph mesh -v` and prints one table row per run; results in benchmarks/RESULTS.md.
# usage: bench_models.sh BUILD_DIR [WORK_DIR]
set -eu
build=${1:?usage: bench_models.sh BUILD_DIR [WORK_DIR]}
work=${2:-$build/bench_models}
mkdir -p "$work"
echo "| model | size | nodes | tets | boundary triangles | min SJ | mean SJ | inverted | surface s | TetGen s | projection s | total s | peak RSS MB |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for run in "bore 0.173" "bore 0.084" "pipe 0.118" "pipe 0.052" "bracket 0.18" "bracket 0.0835"; do
    set -- $run
    model=$1 size=$2
    "$build/cli/cadmorph" model "$model" 0 "$work/$model.step"
    /usr/bin/time -f "rss_kb=%M wall_s=%e" "$build/cli/cadmorph" mesh "$work/$model.step" \
        -o "$work/${model}_$size.vtu" --size "$size" --mesher tetgen -v >"$work/out.txt" 2>"$work/err.txt"
    awk -v model="$model" -v size="$size" '
        FNR == 1 && FILENAME ~ /out/ { for (i = 1; i <= NF; ++i) { split($i, kv, "="); v[kv[1]] = kv[2] } }
        /^min_scaled_jacobian/ { for (i = 1; i <= NF; ++i) { split($i, kv, "="); v[kv[1]] = kv[2] } }
        /tetmesh: surface/ { match($0, /\([0-9.]+ s\)/); surf = substr($0, RSTART + 1, RLENGTH - 4) }
        /tetmesh: TetGen/ { match($0, /\([0-9.]+ s\)/); tg = substr($0, RSTART + 1, RLENGTH - 4) }
        /projected/ { match($0, /\([0-9.]+ s\)/); pr = substr($0, RSTART + 1, RLENGTH - 4) }
        /rss_kb/ { for (i = 1; i <= NF; ++i) { split($i, kv, "="); v[kv[1]] = kv[2] } }
        END { printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %.0f |\n", model, size,
              v["nodes"], v["tets"], v["boundary_triangles"], v["min_scaled_jacobian"],
              v["mean_scaled_jacobian"], v["inverted"], surf, tg, pr, v["wall_s"], v["rss_kb"] / 1024 }
    ' "$work/out.txt" "$work/err.txt"
done
