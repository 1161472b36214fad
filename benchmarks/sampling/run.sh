#!/bin/bash
# Peak memory and time of a morph of a part onto itself, two cadmorph builds side by side
# (benchmarks/RESULTS.md, "Sampling memory and the boundary distance").
#   benchmarks/sampling/run.sh BEFORE AFTER G.step [MESH]
# BEFORE, AFTER: cadmorph executables; G.step: the part; MESH: its volume mesh (default: made
# by AFTER's `cadmorph mesh --mesher tetgen` into a temporary directory, --force for large
# parts). Prints per build: peak RSS, wall time, samples of G, largest distance to G1.
# From the repository alone: benchmarks/sampling/run.sh OLD/cadmorph build/cli/cadmorph
#   tests/data/freecad/shaft_0.step
set -e
before=$1 after=$2 g=$3 mesh=$4
[ -n "$g" ] || { echo "usage: $0 BEFORE AFTER G.step [MESH]" >&2; exit 1; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
if [ -z "$mesh" ]; then
  mesh=$dir/mesh.vtu
  "$after" mesh "$g" -o "$mesh" --mesher tetgen --force --threads 2 > "$dir/mesh.out"
fi
for b in "$before" "$after"; do
  /usr/bin/time -f "%M %e" -o "$dir/time" "$b" morph --from "$g" --to "$g" --mesh "$mesh" \
    -o "$dir/out.vtu" --threads 2 -v > "$dir/out" 2> "$dir/err" || true
  read -r kb s < "$dir/time"
  samples=$(grep -o '^sampling: [0-9]* samples' "$dir/err" | awk '{printf "%s%s", sep, $2; sep="+"}')
  dist=$(grep -o 'largest distance to G1: .*' "$dir/out" | head -1)
  warn=$(grep -c '^warning:' "$dir/err" || true)
  printf "%-40s peak %7.0f MB  %7.1f s  samples %-18s warnings %s  %s\n" "$b" \
    "$(echo "$kb / 1024" | bc -l)" "$s" "$samples" "$warn" "$dist"
done
