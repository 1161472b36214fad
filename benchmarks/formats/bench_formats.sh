#!/bin/sh
# Mesh formats against .vtu (benchmarks/formats/README.md; benchmarks/RESULTS.md, "Mesh
# formats"): a ~1M-cell hex mesh of the bore model (`cadmorph model --hex-mesh`, from the
# repository alone) as .vtu and in the solvers' formats -- .cgns, .su2, .bdf by cadmorph's
# new-file writers, .inp and .exo by meshio's -- then `cadmorph quality` (read) and
# `cadmorph warp` (read + warp + write back into the same format) on each, with GNU time's
# elapsed seconds and peak memory. The warp's D.csv moves every node by one affine map (every
# node listed: no solve, the figures are the formats' reading and writing). A format this
# build cannot read is skipped with a message.
# usage: sh bench_formats.sh CADMORPH WORK_DIR [SCALE]   (SCALE: --scale of the hex mesh, 3.2)
set -eu
CM=$1; W=$2; S=${3:-3.2}
mkdir -p "$W"
T="/usr/bin/time -f %e_%M"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1-3 /proc/loadavg), OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-unset}"
[ -f "$W/bore.vtu" ] || "$CM" model bore 0 --hex-mesh "$W/bore.vtu" --scale "$S" | head -1
# the same mesh in the other formats: cadmorph's writers (a warp by zero: a copy), meshio's
printf 'node,dx,dy,dz\n0,0,0,0\n' > "$W/zero.csv"
for f in cgns su2 bdf; do
    [ -f "$W/bore.$f" ] || "$CM" warp --mesh "$W/bore.vtu" --displacements "$W/zero.csv" -o "$W/bore.$f" > /dev/null
done
for f in inp exo; do
    [ -f "$W/bore.$f" ] || /usr/bin/python3 -c "import meshio, sys; m = meshio.read(sys.argv[1]); meshio.write(sys.argv[2], meshio.Mesh(m.points, [c for c in m.cells if c.type == 'hexahedron']))" "$W/bore.vtu" "$W/bore.$f"
done
# the affine motion of every node
/usr/bin/python3 - "$W/bore.vtu" "$W/affine.csv" <<'PY'
import sys, meshio, numpy as np
x = meshio.read(sys.argv[1]).points
A = np.array([[1.01, 0.02, 0.0], [0.0, 0.99, 0.01], [0.005, 0.0, 1.02]])
np.savetxt(sys.argv[2], np.column_stack([np.arange(len(x)), x @ A.T + [0.1, 0.0, -0.2] - x]),
           fmt=["%d", "%.17g", "%.17g", "%.17g"], delimiter=",", header="node,dx,dy,dz", comments="")
PY
echo "format | size MB | quality s | quality peak MB | warp s | warp peak MB | quality s / vtu | warp s / vtu"
vtu_quality=""; vtu_warp=""
for f in vtu cgns su2 inp bdf exo; do
    if ! "$CM" quality "$W/bore.$f" > "$W/q_$f.log" 2>&1; then
        echo "$f: skipped: $(tail -1 "$W/q_$f.log")"
        continue
    fi
    q=$($T "$CM" quality "$W/bore.$f" 2>&1 >/dev/null | tail -1)
    w=$($T "$CM" warp --mesh "$W/bore.$f" --displacements "$W/affine.csv" -o "$W/warped.$f" 2>&1 >/dev/null | tail -1)
    mb=$(du -m "$W/bore.$f" | cut -f1)
    qs=${q%_*}; [ -n "$vtu_quality" ] || vtu_quality=$qs
    ws=${w%_*}; [ -n "$vtu_warp" ] || vtu_warp=$ws
    echo "$f | $mb | $qs | $(( ${q#*_} / 1024 )) | $ws | $(( ${w#*_} / 1024 )) | $(echo "$qs / $vtu_quality" | bc -l | cut -c1-4) | $(echo "$ws / $vtu_warp" | bc -l | cut -c1-4)"
done
