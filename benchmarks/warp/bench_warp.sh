#!/bin/sh
# The warp-method comparison of RESULTS.md ("Warp methods"): the bore and pipe tet
# and hex meshes at the sweeps' sizes (all methods) and at ~150k nodes (the mesh-based
# methods; the dense RBF factor of 15-46k boundary nodes is out of reach there), each method
# in its own child process. usage: bench_warp.sh BUILD_DIR [WORK_DIR] [THREADS]
set -eu
build=${1:?usage: bench_warp.sh BUILD_DIR [WORK_DIR] [THREADS]}
work=${2:-$build/bench/warp}
threads=${3:-2}
mkdir -p "$work"
cd "$work"
echo "# $(date -u '+%Y-%m-%d %H:%M UTC')  $(lscpu | sed -n 's/^Model name: *//p')  nproc=$(nproc)  threads=$threads  load=$(cut -d' ' -f1-3 /proc/loadavg)"
export OPENBLAS_VERBOSE=2  # OpenBLAS names its core kernel ("Core: ...") once per process
for m in bore pipe; do
    [ -f $m.step ] || "$build/cli/cadmorph" model $m 0 $m.step >/dev/null
done
[ -f bore_tet_0.25.msh ] || "$build/cli/cadmorph" mesh bore.step -o bore_tet_0.25.msh --size 0.25 >/dev/null
[ -f pipe_tet_0.2.msh ] || "$build/cli/cadmorph" mesh pipe.step -o pipe_tet_0.2.msh --size 0.2 >/dev/null
[ -f bore_tet_0.084.msh ] || "$build/cli/cadmorph" mesh bore.step -o bore_tet_0.084.msh --size 0.084 >/dev/null
[ -f pipe_tet_0.052.msh ] || "$build/cli/cadmorph" mesh pipe.step -o pipe_tet_0.052.msh --size 0.052 >/dev/null
[ -f bore_hex_0.667.msh ] || "$build/cli/cadmorph" model bore 0 --hex-mesh bore_hex_0.667.msh --scale 0.6667 >/dev/null
[ -f pipe_hex_1.msh ] || "$build/cli/cadmorph" model pipe 0 --hex-mesh pipe_hex_1.msh >/dev/null
[ -f bore_hex_1.5.msh ] || "$build/cli/cadmorph" model bore 0 --hex-mesh bore_hex_1.5.msh --scale 1.5 >/dev/null
[ -f pipe_hex_2.msh ] || "$build/cli/cadmorph" model pipe 0 --hex-mesh pipe_hex_2.msh --scale 2 >/dev/null
for f in bore_hex_0.667 bore_tet_0.25 pipe_hex_1 pipe_tet_0.2; do
    "$build/benchmarks/warp/bench_warp" $f.msh 20 "$threads"
done
for f in bore_hex_1.5 bore_tet_0.084 pipe_hex_2 pipe_tet_0.052; do
    "$build/benchmarks/warp/bench_warp" $f.msh 20 "$threads" femwarp,lbwarp,simplex
done
