#!/bin/sh
# TetGen against gmsh in `cadmorph mesh` on the built-in models at t = 0 (bore, pipe,
# bracket, written by `cadmorph model`): CPU seconds of the whole command (the mesher's child included:
# /usr/bin/time counts waited-for children), tets, min and 1st-percentile scaled Jacobian,
# with the interior optimisation (default) and without (--no-optimize: the mesher's own).
# usage: benchmarks/meshers/bench_meshers.sh [BUILD_DIR]   (default: build)
# Sizes: the default (bbox diagonal / 20) and diagonal / 30 for both meshers, and / 45, / 60 for
# gmsh: TetGen's tets at one --size are 3-10x gmsh's (its volume bound, the surface's chord
# deflection), so rows of similar tet counts compare the meshers at equal cost downstream.
set -eu
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=$(cd "${1:-$ROOT/build}" && pwd)
OUT=$BUILD/bench/meshers
mkdir -p "$OUT"
CM=$BUILD/cli/cadmorph
for model in bore pipe bracket; do
  OPENBLAS_VERBOSE=0 "$CM" model $model 0 "$OUT/$model.step"
done
# and two parts made by another CAD kernel than ours (gmsh's OpenCASCADE, quality_guard/make_parts.py)
/usr/bin/python3 "$ROOT/benchmarks/quality_guard/make_parts.py" "$OUT" > /dev/null 2>&1
# the bbox diagonal, from `cadmorph info`'s "bbox: [a, b] x [c, d] x [e, f]"
diag() {
  OPENBLAS_VERBOSE=0 "$CM" info "$OUT/$1.step" | awk -F'[][, ]+' '/^bbox:/ {
    printf "%.4g", sqrt(($3-$2)^2 + ($6-$5)^2 + ($9-$8)^2) }'
}
printf "%-8s %-7s %6s %-12s %8s %8s %9s %9s\n" model mesher size optimize cpu_s tets min_sj p01_sj
for model in bore pipe bracket gmsh_flange gmsh_bracket; do
  d=$(diag $model)
  for div in 20 30 45 60; do
    size=$(awk "BEGIN{printf \"%.4g\", $d/$div}")
    for mesher in tetgen gmsh; do
      [ $mesher = tetgen ] && [ $div -gt 30 ] && continue
      for opt in on off; do
        flag=""; [ $opt = off ] && flag=--no-optimize
        log=$OUT/$model-$mesher-$div-$opt.log
        /usr/bin/time -f "cpu %U %S" "$CM" mesh "$OUT/$model.step" -o "$OUT/$model-$mesher-$div-$opt.vtu" \
          --size "$size" --mesher $mesher $flag --threads 1 > "$log" 2>&1 || { echo "$model $mesher failed: $(tail -1 "$log")"; continue; }
        awk -v m=$model -v me=$mesher -v s=$size -v o=$opt '
          /^tet4 /{tets=$2; mn=$3; p01=$5}
          /^cpu /{cpu=$2+$3}
          END{printf "%-8s %-7s %6s %-12s %8.2f %8d %9.4f %9.4f\n", m, me, s, o, cpu, tets, mn, p01}' "$log"
      done
    done
  done
done
