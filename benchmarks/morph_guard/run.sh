#!/bin/sh
# The guarded morph's cost when one step is valid (benchmarks/RESULTS.md, "The guarded morph
# costs nothing when one step is valid"): `cadmorph morph` with its default (--steps auto)
# against --steps 1, alternated in one run, on the bore of `cadmorph model` (G(0) -> G(1),
# gmsh tets) and on the FreeCAD shaft's first edit (tests/data/freecad, shaft_0 -> shaft_1).
# Prints per case the best CPU (user + sys) and wall seconds of each over ROUNDS rounds, their
# ratio, the number of steps the default tried, and whether the two outputs are the same bytes.
#   sh benchmarks/morph_guard/run.sh BUILD OUT_DIR [ROUNDS]
set -eu
B=$1; O=$2; R=${3:-5}
C=$B/cli/cadmorph
D=$(cd "$(dirname "$0")/../.." && pwd)/tests/data/freecad
mkdir -p "$O"
$C model bore 0 "$O/bore_0.step" > /dev/null
$C model bore 1 "$O/bore_1.step" > /dev/null
$C mesh "$O/bore_0.step" -o "$O/bore_0.msh" --size 0.2 --threads 1 > /dev/null
$C mesh "$D/shaft_0.step" -o "$O/shaft_0.msh" --threads 1 > /dev/null
echo "BLAS core: ${OPENBLAS_CORETYPE:-auto}; threads 1; best of $R rounds"
echo "case,cells,cpu_s_steps1,cpu_s_default,cpu_ratio,wall_s_steps1,wall_s_default,wall_ratio,default_rows,same_bytes"
for case in bore shaft; do
  if [ $case = bore ]; then g0=$O/bore_0.step; g1=$O/bore_1.step; else g0=$D/shaft_0.step; g1=$D/shaft_1.step; fi
  best1=; best2=; wall1=; wall2=
  i=0
  while [ $i -lt "$R" ]; do
    for v in 1 default; do
      extra=; [ $v = 1 ] && extra="--steps 1"
      # shellcheck disable=SC2086
      /usr/bin/time -f "%U %S %e" -o "$O/time" $C morph --from "$g0" --to "$g1" --mesh "$O/${case}_0.msh" \
        -o "$O/${case}_$v.vtu" --report "$O/${case}_$v.csv" --threads 1 $extra > "$O/${case}_$v.out"
      cpu=$(awk '{printf "%.3f", $1 + $2}' "$O/time"); wall=$(awk '{print $3}' "$O/time")
      if [ $v = 1 ]; then
        best1=$(echo "${best1:-$cpu} $cpu" | awk '{print ($1 < $2) ? $1 : $2}')
        wall1=$(echo "${wall1:-$wall} $wall" | awk '{print ($1 < $2) ? $1 : $2}')
      else
        best2=$(echo "${best2:-$cpu} $cpu" | awk '{print ($1 < $2) ? $1 : $2}')
        wall2=$(echo "${wall2:-$wall} $wall" | awk '{print ($1 < $2) ? $1 : $2}')
      fi
    done
    i=$((i + 1))
  done
  cells=$(tail -1 "$O/${case}_1.out" | sed 's/.*cells=//')
  rows=$(($(wc -l < "$O/${case}_default.csv") - 1))
  same=no; cmp -s "$O/${case}_1.vtu" "$O/${case}_default.vtu" && same=yes
  echo "$case,$cells,$best1,$best2,$(echo "$best2 $best1" | awk '{printf "%.3f", $1 / $2}'),$wall1,$wall2,$(echo "$wall2 $wall1" | awk '{printf "%.3f", $1 / $2}'),$rows,$same"
done
