#!/bin/sh
# FreeCAD-made parts through cadmorph (benchmarks/RESULTS.md, FreeCAD-made parts):
# info --compare of every edit and re-export, mesh by gmsh and TetGen, morph of each mesh onto
# the edits (--steps auto when one step inverts) and onto the re-export, detect on a gmsh surface
# mesh scored against the CAD face types.
#   benchmarks/freecad/run.sh CADMORPH DIR   (DIR holds the STEP files of
#   tests/data/freecad/make_parts.py: CM_FREECAD_OUT=DIR freecadcmd tests/data/freecad/make_parts.py)
set -u
C=$1; D=$2; H=$(dirname "$0")
export OPENBLAS_VERBOSE=0
for p in shaft plate bracket; do
  echo "== $p"
  "$C" info "$D/${p}_0.step" | grep -E '^(faces|bbox)' | tr '\n' ' '; echo
  for g in "$D/${p}"_[1-9].step "$D/${p}_re.step"; do
    b=$(basename "$g" .step)
    "$C" info "$D/${p}_0.step" --compare "$g" --map "$D/map_$b.csv" --verbose > "$D/cmp_$b.txt" 2>&1
    echo "compare ${p}_0 $b: exit $? | $(grep -v '^ ' "$D/cmp_$b.txt" | tail -3 | tr '\n' '|' | cut -c1-300)"
    echo "  map rows with another index or orientation: $(awk -F, 'NR>1 && ($2!=$3 || $4!="same") ' "$D/map_$b.csv" | wc -l), type changes: $(awk -F, 'NR>1 && $5!=$6' "$D/map_$b.csv" | wc -l)"
  done
  for m in gmsh tetgen; do
    /usr/bin/time -f "cpu %U %S wall %e" timeout 900 "$C" mesh "$D/${p}_0.step" -o "$D/${p}_$m.msh" --mesher $m --threads 1 -v > "$D/mesh_${p}_$m.txt" 2>&1
    echo "mesh $p $m: exit $? | $(grep -E '^tet4 |^cpu |min_scaled|tried|retry|fail|abort|signal|crash' "$D/mesh_${p}_$m.txt" | tr '\n' '|' | cut -c1-400)"
    [ -f "$D/${p}_$m.msh" ] || continue
    for g in "$D/${p}"_[1-9].step "$D/${p}_re.step"; do
      b=$(basename "$g" .step)
      "$C" morph --from "$D/${p}_0.step" --to "$g" --mesh "$D/${p}_$m.msh" -o "$D/out_${b}_$m.vtu" --steps 1 --allow-inverted --report "$D/rep_${b}_$m.csv" --threads 1 > "$D/morph_${b}_$m.txt" 2>&1
      rc=$?
      echo "morph $b $m steps 1: exit $rc | $(tail -2 "$D/morph_${b}_$m.txt" | tr '\n' '|' | cut -c1-300)"
      if grep -q 'inverted=[1-9]' "$D/morph_${b}_$m.txt"; then
        "$C" morph --from "$D/${p}_0.step" --to "$g" --mesh "$D/${p}_$m.msh" -o "$D/outa_${b}_$m.vtu" --steps auto --report "$D/repa_${b}_$m.csv" --threads 1 > "$D/morpha_${b}_$m.txt" 2>&1
        echo "morph $b $m steps auto: exit $? | $(tail -2 "$D/morpha_${b}_$m.txt" | tr '\n' '|' | cut -c1-300)"
      fi
    done
    /usr/bin/python3 "$H/node_motion.py" "$D/${p}_$m.msh" "$D/out_${p}_re_$m.vtu" 2>&1 | sed "s/^/re-export $p $m: /"
  done
  /usr/bin/python3 "$H/detect_score.py" "$C" "$D/${p}_0.step" "$D/det_$p" 2>&1 | sed "s/^/detect $p: /"
done
