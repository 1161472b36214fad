#!/bin/sh
# The reverse product of the mesh-based warps against one apply (RESULTS.md, "Gradients"): the
# bore's hex mesh at the sweeps' size and the pipe's hex mesh at ~150k and ~300k nodes (the
# largest that runs in a few minutes: lbwarp's LU of 300k unknowns takes 2 min and 4 GB),
# femwarp and lbwarp on one warp each. usage: bench_warp_transpose_mesh.sh BUILD_DIR [WORK_DIR] [THREADS] [REPS]
set -eu
build=${1:?usage: bench_warp_transpose_mesh.sh BUILD_DIR [WORK_DIR] [THREADS] [REPS]}
work=${2:-$build/bench/gradients}
threads=${3:-2}
reps=${4:-10}
mkdir -p "$work"
cd "$work"
echo "# $(date -u '+%Y-%m-%d %H:%M UTC')  $(lscpu | sed -n 's/^Model name: *//p')  nproc=$(nproc)  threads=$threads  load=$(cut -d' ' -f1-3 /proc/loadavg)"
export OPENBLAS_VERBOSE=2  # OpenBLAS names its core kernel ("Core: ...") once per process
[ -f bore_hex_0.667.msh ] || "$build/cli/cadmorph" model bore 0 --hex-mesh bore_hex_0.667.msh --scale 0.6667 >/dev/null
[ -f pipe_hex_2.msh ] || "$build/cli/cadmorph" model pipe 0 --hex-mesh pipe_hex_2.msh --scale 2 >/dev/null
[ -f pipe_hex_2.5.msh ] || "$build/cli/cadmorph" model pipe 0 --hex-mesh pipe_hex_2.5.msh --scale 2.5 >/dev/null
for f in bore_hex_0.667 pipe_hex_2 pipe_hex_2.5; do
    "$build/benchmarks/bench_warp_transpose_mesh" $f.msh "$reps" "$threads" femwarp,lbwarp
done
