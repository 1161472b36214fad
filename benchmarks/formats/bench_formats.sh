#!/bin/sh
# Mesh formats against .vtu (README.md; benchmarks/RESULTS.md, "Mesh formats"): a ~1M-cell tet
# mesh of the bore model (`cadmorph model` + `cadmorph mesh`, from the repository alone) as
# .vtu, .cgns (cadmorph's new-file writer) and .inp (meshio's writer), then `cadmorph quality`
# (read) and `cadmorph warp` (read + warp + write back into the same format) on each, with
# GNU time's elapsed seconds and peak memory. The warp's D.csv moves every node by one affine
# map (every node listed: no solve, the figures are the formats' reading and writing). A
# format this build cannot read is skipped with a message.
# usage: sh bench_formats.sh CADMORPH WORK_DIR [SIZE]   (SIZE: --size of cadmorph mesh, 0.065)
set -eu
CM=$1; W=$2; H=${3:-0.065}
mkdir -p "$W"
T="/usr/bin/time -f %e_%M"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1-3 /proc/loadavg), OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-unset}"
if [ ! -f "$W/bore.vtu" ]; then
    "$CM" model bore 0 "$W/G0.step" > /dev/null
    "$CM" mesh "$W/G0.step" -o "$W/bore.vtu" --size "$H" --mesher tetgen | head -1
fi
# the same mesh in the other formats: .cgns by cadmorph (a warp by zero: a copy), .inp by meshio
printf 'node,dx,dy,dz\n0,0,0,0\n' > "$W/zero.csv"
[ -f "$W/bore.cgns" ] || "$CM" warp --mesh "$W/bore.vtu" --displacements "$W/zero.csv" -o "$W/bore.cgns" > /dev/null
[ -f "$W/bore.inp" ] || /usr/bin/python3 -c "import meshio, sys; m = meshio.read(sys.argv[1]); meshio.write(sys.argv[2], meshio.Mesh(m.points, [c for c in m.cells if c.type == 'tetra']))" "$W/bore.vtu" "$W/bore.inp"
# the affine motion of every node
/usr/bin/python3 - "$W/bore.vtu" "$W/affine.csv" <<'PY'
import sys, meshio, numpy as np
x = meshio.read(sys.argv[1]).points
A = np.array([[1.01, 0.02, 0.0], [0.0, 0.99, 0.01], [0.005, 0.0, 1.02]])
np.savetxt(sys.argv[2], np.column_stack([np.arange(len(x)), x @ A.T + [0.1, 0.0, -0.2] - x]),
           fmt=["%d", "%.17g", "%.17g", "%.17g"], delimiter=",", header="node,dx,dy,dz", comments="")
PY
echo "format | size MB | quality s | quality peak MB | warp s | warp peak MB | warp s / vtu"
vtu_warp=""
for f in vtu cgns inp; do
    if ! "$CM" quality "$W/bore.$f" > "$W/q_$f.log" 2>&1; then
        echo "$f: skipped: $(tail -1 "$W/q_$f.log")"
        continue
    fi
    q=$($T "$CM" quality "$W/bore.$f" 2>&1 >/dev/null | tail -1)
    w=$($T "$CM" warp --mesh "$W/bore.$f" --displacements "$W/affine.csv" -o "$W/warped.$f" 2>&1 >/dev/null | tail -1)
    mb=$(du -m "$W/bore.$f" | cut -f1)
    ws=${w%_*}; [ -n "$vtu_warp" ] || vtu_warp=$ws
    echo "$f | $mb | ${q%_*} | $(( ${q#*_} / 1024 )) | $ws | $(( ${w#*_} / 1024 )) | $(echo "$ws / $vtu_warp" | bc -l | cut -c1-4)"
done
