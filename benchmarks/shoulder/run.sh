#!/bin/sh
# The compressed shoulder under one step, 5 steps and --steps auto (benchmarks/RESULTS.md, A compressed shoulder).
#   benchmarks/shoulder/run.sh CADMORPH OUT_DIR
set -u
C=$1; O=$2
/usr/bin/python3 "$(dirname "$0")/make_shoulder.py" "$O" > /dev/null 2>&1 || exit 1
"$C" mesh "$O/shoulder_a.step" -o "$O/shoulder_a.msh" --size 0.25 | tail -1
for r in 1.15 1.2 1.25 1.35; do
  for st in 1 5 auto; do
    printf 'r2 %s steps %s: ' $r $st
    # fixed steps as measured: their inverted cells kept (--allow-inverted)
    keep=--allow-inverted; [ $st = auto ] && keep=
    "$C" morph --from "$O/shoulder_a.step" --to "$O/shoulder_r$r.step" --mesh "$O/shoulder_a.msh" \
      -o "$O/out_${r}_$st.msh" --steps $st $keep --report "$O/report_${r}_$st.csv" 2> "$O/err_${r}_$st.txt" | tail -1
    echo "  exit $? $(cut -c1-160 "$O/err_${r}_$st.txt")"
  done
done
