#!/usr/bin/env bash
# Runs the same commands with two cadmorph programs and compares every file they write, byte
# for byte: a refactoring that must not change behaviour (docs/DESIGN.md, "Changing the
# layout") keeps all of them identical.
#
# usage: scripts/compare_outputs.sh OLD_CADMORPH NEW_CADMORPH WORK_DIR
#
# The inputs (a tet mesh of the bore fixture, a hex mesh of the built-in bore, handle and
# displacement tables) are made once, by OLD, so both programs read the same bytes. Report
# CSVs and study tables carry timings (t_read, t_sample, ...): those columns are dropped before
# the comparison, every other column stays; so are the lines of standard output that give a
# time, and the SVG plots, whose titles carry timings.
# Exit 0 when every output is identical, 1 otherwise (each differing file is named).
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: $0 OLD_CADMORPH NEW_CADMORPH WORK_DIR" >&2; exit 1; }
old=$(realpath "$1"); new=$(realpath "$2"); work=$3
root=$(cd "$(dirname "$0")/.." && pwd)
data=$root/tests/data
rm -rf "$work"; mkdir -p "$work/in"
in=$work/in
export OMP_NUM_THREADS=${OMP_NUM_THREADS:-2}

# ---- inputs, made once by OLD ----
cp "$data/cad/bore_a.step" "$in/G0.step"
cp "$data/cad/bore_b.step" "$in/G1.step"
"$old" mesh "$in/G0.step" -o "$in/tet.vtu" --size 0.4 --mesher tetgen > /dev/null
# a hex mesh on a geometry of the built-in bore: the sweep's O-grid mesh morphed to t = 0.5,
# with G(0.5) and G(1) as STEP
"$old" sweep bore --mesh hex --mode absolute --steps 2 --methods rbf-s --write-step \
  -o "$in/hexsweep" > /dev/null
hex=$in/hexsweep/rbf-s_absolute_050.vtu
/usr/bin/python3 - "$in" <<'PY'
import sys, xml.etree.ElementTree as ET
# handles / fixed nodes / displacements from the tet mesh's points (ASCII or binary: read the
# node count and take the first and last nodes by index only)
import re, os
d = sys.argv[1]
txt = open(os.path.join(d, "tet.vtu"), "rb").read()
n = int(re.search(rb'NumberOfPoints="(\d+)"', txt).group(1))
h = [0, n // 7, n // 3, n // 2]
with open(os.path.join(d, "H.csv"), "w") as f:
    f.write("node,dx,dy,dz\n")
    for k, i in enumerate(h):
        f.write(f"{i},{0.01*(k+1)},{-0.005*k},{0.002}\n")
with open(os.path.join(d, "F.csv"), "w") as f:
    f.write("node\n")
    for i in (n - 1, n - 2, n - 3, n - 5, n - 8):
        f.write(f"{i}\n")
with open(os.path.join(d, "D.csv"), "w") as f:
    f.write("node,dx,dy,dz\n")
    for i in range(0, n, max(1, n // 40)):
        f.write(f"{i},{1e-3*(i%5)},{2e-3*(i%3)},{-1e-3*(i%2)}\n")
with open(os.path.join(d, "variants.txt"), "w") as f:
    f.write("G1.step\nG0.step\n")
PY

# ---- the commands (NAME: arguments, OUT is replaced by each program's output directory) ----
cmds=(
  "morph_tet_1|morph --from $in/G0.step --to $in/G1.step --mesh $in/tet.vtu -o OUT/m.vtu --steps 1 --report OUT/r.csv"
  "morph_tet_3|morph --from $in/G0.step --to $in/G1.step --mesh $in/tet.vtu -o OUT/m.vtu --steps 3 --report OUT/r.csv"
  "study|study --from $in/G0.step --mesh $in/tet.vtu --variants $in/variants.txt -o OUT/s --write-meshes all"
  "sweep_tet|sweep bore --mesh tet --mode both --steps 2 -o OUT/s"
  "sweep_hex|sweep bore --mesh hex --mode absolute --steps 2 -o OUT/s"
  "deform_rbf|deform --mesh $in/tet.vtu --handles $in/H.csv --fixed $in/F.csv --method rbf -o OUT/d.vtu"
  "deform_mls|deform --mesh $in/tet.vtu --handles $in/H.csv --fixed $in/F.csv --method mls -o OUT/d.vtu"
  "deform_dmffd|deform --mesh $in/tet.vtu --handles $in/H.csv --fixed $in/F.csv --method dmffd -o OUT/d.vtu"
  "ffd|ffd --mesh $in/tet.vtu --lattice $data/deform/bern333_rot.prm -o OUT/f.vtu"
  "warp_rbf|warp --mesh $in/tet.vtu --displacements $in/D.csv --method rbf -o OUT/w.vtu"
  "warp_femwarp|warp --mesh $in/tet.vtu --displacements $in/D.csv --method femwarp -o OUT/w.vtu"
  "warp_lbwarp|warp --mesh $in/tet.vtu --displacements $in/D.csv --method lbwarp -o OUT/w.vtu"
  "warp_simplex|warp --mesh $in/tet.vtu --displacements $in/D.csv --method simplex -o OUT/w.vtu"
  "quality|quality $in/tet.vtu --csv OUT/q.csv"
)
if [ -f "$hex" ]; then
  cmds+=(
    "morph_hex_1|morph --from $in/hexsweep/G_0.5000.step --to $in/hexsweep/G_1.0000.step --mesh $hex -o OUT/m.vtu --steps 1 --report OUT/r.csv"
    "morph_hex_3|morph --from $in/hexsweep/G_0.5000.step --to $in/hexsweep/G_1.0000.step --mesh $hex -o OUT/m.vtu --steps 3 --report OUT/r.csv"
  )
else
  echo "compare: no hex mesh from the sweep in $in/hexsweep" >&2; exit 1
fi

# Drop columns whose header names a time (seconds, time, wall, cpu) from a CSV.
strip_times() {
  /usr/bin/python3 - "$1" <<'PY'
import csv, re, sys
p = sys.argv[1]
rows = list(csv.reader(open(p, newline="")))
if not rows: sys.exit(0)
keep = [i for i, h in enumerate(rows[0]) if not re.search(r"^t_|second|time|wall|cpu", h, re.I)]
with open(p, "w", newline="") as f:
    w = csv.writer(f, lineterminator="\n")
    for r in rows: w.writerow([r[i] for i in keep if i < len(r)])
PY
}

fail=0
for entry in "${cmds[@]}"; do
  name=${entry%%|*}; args=${entry#*|}
  for side in old new; do
    out=$work/$side/$name; mkdir -p "$out"
    prog=$old; [ $side = new ] && prog=$new
    # shellcheck disable=SC2086
    set +e; $prog ${args//OUT/$out} > "$out/stdout.txt" 2> "$work/$side/$name.stderr"; rc=$?; set -e
    echo "$rc" > "$out/exit_code.txt"
    grep -v -E '[0-9.]+ ?s\b|seconds|time' "$out/stdout.txt" > "$out/stdout.tmp" || true
    mv "$out/stdout.tmp" "$out/stdout.txt"
    find "$out" -name '*.csv' -print0 | while IFS= read -r -d '' f; do strip_times "$f"; done
    find "$out" -name '*.svg' -delete  # plots carry the timings in their titles
  done
  if diff -r -q "$work/old/$name" "$work/new/$name" > "$work/$name.diff" 2>&1; then
    echo "same    $name"
  else
    echo "DIFFERS $name"; sed 's/^/        /' "$work/$name.diff"; fail=1
  fi
done
[ $fail = 0 ] && echo "compare: every output identical" || echo "compare: outputs differ"
exit $fail
