#!/bin/sh
# The FFD / DM-FFD / RBF benchmark suite of [SMB14] (benchmarks/RESULTS.md): blocks 1, 5, 2,
# 3 with bench_deform, block 6 on the pipe tet and hex meshes (RBF-S morphs by
# `cadmorph morph`, DM-FFD-5/10/15/25 by bench_deform volume), then the SVG plots.
# usage: run_deform.sh BUILD_DIR [WORK_DIR] [THREADS]
set -eu
build=${1:?usage: run_deform.sh BUILD_DIR [WORK_DIR] [THREADS]}
work=${2:-$build/deform}
threads=${3:-2}
here=$(dirname "$0")
bench=$build/benchmarks/deform/bench_deform
cadmorph=$build/cli/cadmorph
mkdir -p "$work/pipe"
echo "# $(date -u '+%Y-%m-%d %H:%M UTC')  $(lscpu | sed -n 's/^Model name: *//p')  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)"
OPENBLAS_VERBOSE=2 "$bench" perf "$work" "$threads"
"$bench" precision "$work"
"$bench" robust "$work"
"$bench" smooth "$work"
"$bench" adapt "$work"

cd "$work/pipe"
steps="0.2 0.4 0.6 0.8 1.0"
for t in 0 $steps; do "$cadmorph" model pipe "$t" "pipe_$t.step"; done
"$cadmorph" mesh pipe_0.step -o pipe_tet.vtu --size 0.2 --mesher tetgen | tail -1
"$cadmorph" model pipe 0 --hex-mesh pipe_hex.vtu | tail -1
for mesh in tet hex; do
    targets=""
    for t in $steps; do
        "$cadmorph" morph --from pipe_0.step --to "pipe_$t.step" --mesh "pipe_$mesh.vtu" \
            -o "rbf_${mesh}_$t.vtu" --steps 1 --allow-inverted --threads "$threads" | tail -1
        targets="$targets $t:rbf_${mesh}_$t.vtu"
    done
    # the library default clamping 1e-10, then the paper's 1e-2 (BENCH_EPS)
    # shellcheck disable=SC2086
    /usr/bin/time -f "wall_s=%e rss_kb=%M" "$bench" volume "$work" "pipe_$mesh" "pipe_$mesh.vtu" $targets
    # shellcheck disable=SC2086
    BENCH_EPS=1e-2 /usr/bin/time -f "wall_s=%e rss_kb=%M" "$bench" volume "$work" "pipe_$mesh" \
        "pipe_$mesh.vtu" $targets
done
# the CLI path: `cadmorph morph --method dmffd` at 100 % (same numbers as the exact-boundary
# column of bench_deform volume)
"$cadmorph" morph --from pipe_0.step --to pipe_1.0.step --mesh pipe_tet.vtu -o dmffd5_tet_1.0.vtu \
    --method dmffd --lattice 5 --clamp 1e-2 --steps 1 --allow-inverted --threads "$threads" | tail -1
/usr/bin/python3 "$here/plots.py" "$work"
