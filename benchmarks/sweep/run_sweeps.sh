#!/bin/sh
# The sweeps [SKM11] of benchmarks/RESULTS.md: bore tet + hex, pipe tet + hex, bracket
# tet; absolute and relative, the three methods, 20 steps. Outputs in WORK/<model>_<mesh>/.
# usage: run_sweeps.sh BUILD_DIR [WORK_DIR] [THREADS]
set -u
build=${1:?usage: run_sweeps.sh BUILD_DIR [WORK_DIR] [THREADS]}
work=${2:-$build/sweeps}
threads=${3:-2}
cadmorph=${CADMORPH:-$build/cli/cadmorph}  # CADMORPH: a copy, to rebuild meanwhile
for run in "bore tet 0.25" "bore hex 0.15" "pipe tet 0.2" "pipe hex 0.1" "bracket tet 0.25"; do
    set -- $run
    echo "== $1 $2 --size $3"
    /usr/bin/time -f "wall_s=%e rss_kb=%M" "$cadmorph" sweep "$1" --mesh "$2" --size "$3" \
        --mode both --steps 20 -o "$work/$1_$2" --threads "$threads" || echo "FAILED: $1 $2"
done
