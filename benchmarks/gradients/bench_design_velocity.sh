#!/bin/sh
# Design velocities of P parameters against one morph, on the built-in models (README.md).
# usage: sh benchmarks/gradients/bench_design_velocity.sh BUILD_DIR [WORK_DIR] [THREADS] [MODELS] [PS] [REPEATS]
#   MODELS: "bore:0.15 pipe:0.1 bracket:0.18" by default (model:tet size of `cadmorph mesh`)
#   PS: the parameter counts, "1 2 4" by default; REPEATS: runs of each timing (default 3)
# The models have one parameter t; a table of P parameters repeats it under P names, each
# with its own rows G(0.5 +- 0.01) (the same STEP files, read and morphed once per row), so
# the work is that of P independent parameters. M0 is the mesh of G(0.5).
set -e
BUILD=$(cd "$1" && pwd)
WORK=${2:-/tmp/bench_design_velocity}
THREADS=${3:-2}
MODELS=${4:-"bore:0.15 pipe:0.1 bracket:0.18"}
PS=${5:-"1 2 4"}
REPEATS=${6:-3}
MESH_OPTIONS=${MESH_OPTIONS:-}   # e.g. "--no-optimize --force" for the largest mesh
C=$BUILD/cli/cadmorph
B=$BUILD/benchmarks/gradients/bench_design_velocity
mkdir -p "$WORK"
cd "$WORK"
for ms in $MODELS; do
  m=${ms%%:*}; h=${ms#*:}
  for t in 0.5 0.49 0.51 0.6; do "$C" model "$m" $t ${m}_$t.step; done
  # a mesh beyond cadmorph mesh's default tet limit (the 10^5-boundary-node bracket) needs
  # --force; --no-optimize as in RESULTS.md "Scale"
  [ -f ${m}_$h.vtu ] || "$C" mesh ${m}_0.5.step -o ${m}_$h.vtu --size $h --mesher tetgen \
      $MESH_OPTIONS > /dev/null
  for P in $PS; do
    names=""; base=""
    for k in $(seq 1 $P); do names="$names,p$k"; base="$base,0.5"; done
    {
      echo "step$names"
      echo "${m}_0.5.step$base"
      for k in $(seq 1 $P); do
        for t in 0.51 0.49; do
          row=""; for j in $(seq 1 $P); do [ $j = $k ] && row="$row,$t" || row="$row,0.5"; done
          echo "${m}_$t.step$row"
        done
      done
    } > ${m}_P$P.csv
    printf "model=%s size=%s " $m $h
    "$B" ${m}_0.5.step ${m}_$h.vtu ${m}_P$P.csv ${m}_0.6.step $THREADS $REPEATS
  done
done
