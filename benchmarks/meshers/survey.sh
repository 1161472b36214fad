#!/bin/sh
# `cadmorph mesh` with its defaults on every STEP file of a directory (e.g. the OpenCASCADE
# repository's data/step files and its data/occ shapes written as STEP): one table row per
# file with its faces and solids, the exit code, the wall time, the tets and the minimum
# scaled Jacobian, and the last line of stderr (why not, or the fallback's warning).
# usage: sh benchmarks/meshers/survey.sh STEP_DIR [CADMORPH [OUT_DIR]]
set -u
dir=${1:?usage: survey.sh STEP_DIR [CADMORPH [OUT_DIR]]}
cm=${2:-build/cli/cadmorph}
out=${3:-${TMPDIR:-/tmp}/cadmorph_mesher_survey}
mkdir -p "$out"
echo "| part | faces | solids | exit | s | tets | min SJ | stderr (last line) |"
echo "|---|---:|---:|---:|---:|---:|---:|---|"
for f in "$dir"/*.step; do
  b=$(basename "$f" .step)
  info=$("$cm" info "$f" 2>/dev/null | grep '^solids')
  faces=$(echo "$info" | sed -n 's/.*faces \([0-9]*\).*/\1/p')
  solids=$(echo "$info" | sed -n 's/^solids \([0-9]*\).*/\1/p')
  s=$(date +%s.%N)
  "$cm" mesh "$f" -o "$out/$b.vtu" > "$out/$b.out" 2> "$out/$b.err"
  rc=$?
  e=$(date +%s.%N)
  tets=$(sed -n 's/.* tets=\([0-9]*\) .*/\1/p' "$out/$b.out")
  sj=$(sed -n 's/^min_scaled_jacobian=\([^ ]*\) .*/\1/p' "$out/$b.out")
  err=$(tail -n 1 "$out/$b.err" | sed "s|$dir/||g; s/|/\\\\|/g" | cut -c1-300)
  printf "| %s | %s | %s | %d | %.1f | %s | %s | %s |\n" "$b" "${faces:--}" "${solids:--}" "$rc" \
    "$(echo "$e - $s" | bc)" "${tets:--}" "${sj:--}" "$err"
done
