#!/bin/sh
# The method comparison of RESULTS.md ("Warp methods in the sweeps"): bore tet + hex, pipe
# tet + hex, bracket tet at the sizes of run_sweeps.sh, 20 steps, absolute and relative,
# through bench_warp_sweep. usage: bench_warp_sweep.sh BUILD_DIR [WORK_DIR] [THREADS] [METHODS]
#   [MODE] [STEPS] [RUNS]: absolute or relative (default both), steps (20), and which of the
#   five model/mesh runs, as "bore_tet pipe_hex ..." (default all)
set -u
build=${1:?usage: bench_warp_sweep.sh BUILD_DIR [WORK_DIR] [THREADS] [METHODS]}
work=${2:-$build/bench/wsweep}
threads=${3:-2}
methods=${4:-rbf-s,femwarp,lbwarp,simplex}
mode=${5:-absolute,relative}
steps=${6:-20}
runs=${7:-bore_tet bore_hex pipe_tet pipe_hex bracket_tet}
bin=${BENCH_BIN:-$build}  # a copy of the binaries, to rebuild meanwhile
mkdir -p "$work"
cd "$work"
echo "# $(date -u '+%Y-%m-%d %H:%M UTC')  $(lscpu | sed -n 's/^Model name: *//p')  nproc=$(nproc)  threads=$threads  load=$(cut -d' ' -f1-3 /proc/loadavg)"
for m in bore pipe bracket; do "$bin/cli/cadmorph" model $m 0 $m.step >/dev/null; done
[ -f bracket_tet.msh ] && [ -f pipe_hex.msh ] || {
"$bin/cli/cadmorph" mesh bore.step -o bore_tet.msh --size 0.25 --mesher tetgen >/dev/null
"$bin/cli/cadmorph" mesh pipe.step -o pipe_tet.msh --size 0.2 --mesher tetgen >/dev/null
"$bin/cli/cadmorph" mesh bracket.step -o bracket_tet.msh --size 0.25 --mesher tetgen >/dev/null
"$bin/cli/cadmorph" model bore 0 --hex-mesh bore_hex.msh --scale 0.6667 >/dev/null
"$bin/cli/cadmorph" model pipe 0 --hex-mesh pipe_hex.msh >/dev/null
}
for run in $runs; do
    model=${run%_*}
    /usr/bin/time -f "# $run $mode: wall_s=%e rss_kb=%M" "$bin/benchmarks/warp/bench_warp_sweep" $model $run.msh "$steps" . "$methods" "$threads" "$mode"
done
