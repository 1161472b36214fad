#!/bin/sh
# The warp's reverse product against one apply (RESULTS.md, "Gradients"), one warp per mesh
# and method:
# - rbf on the bore and pipe tet meshes of "Benchmark models", their hex O-grids, and the
#   bracket at size 0.0528 (102,890 boundary nodes, 3.3M tets: TetGen takes ~3.5 minutes, the
#   warp several more; one round);
# - femwarp and lbwarp on the bore's hex mesh at the sweeps' size and the pipe's hex mesh at
#   ~150k and ~300k nodes (lbwarp's LU of 300k unknowns takes 2 min and 4 GB).
# usage: bench_warp_vjp.sh BUILD_DIR [WORK_DIR] [THREADS] [REPS] [--no-bracket]
set -eu
build=${1:?usage: bench_warp_vjp.sh BUILD_DIR [WORK_DIR] [THREADS] [REPS] [--no-bracket]}
work=${2:-$build/bench/gradients}
threads=${3:-2}
reps=${4:-5}
bracket=${5:-}
build=$(cd "$build" && pwd)
mkdir -p "$work"
cd "$work"
echo "# $(date -u '+%Y-%m-%d %H:%M UTC')  $(lscpu | sed -n 's/^Model name: *//p')  nproc=$(nproc)  threads=$threads  load=$(cut -d' ' -f1-3 /proc/loadavg)"
export OPENBLAS_VERBOSE=2  # OpenBLAS names its core kernel ("Core: ...") once per process
cm="$build/cli/cadmorph"
bench="$build/benchmarks/gradients/bench_warp_vjp"
for m in bore pipe bracket; do
    [ -f $m.step ] || "$cm" model $m 0 $m.step >/dev/null
done
[ -f bore_0.173.vtu ] || "$cm" mesh bore.step -o bore_0.173.vtu --size 0.173 --mesher tetgen >/dev/null
[ -f pipe_0.118.vtu ] || "$cm" mesh pipe.step -o pipe_0.118.vtu --size 0.118 --mesher tetgen >/dev/null
[ -f bore_hex.msh ] || "$cm" model bore 0 --hex-mesh bore_hex.msh >/dev/null
[ -f pipe_hex.msh ] || "$cm" model pipe 0 --hex-mesh pipe_hex.msh >/dev/null
[ -f bore_hex_0.667.msh ] || "$cm" model bore 0 --hex-mesh bore_hex_0.667.msh --scale 0.6667 >/dev/null
[ -f pipe_hex_2.msh ] || "$cm" model pipe 0 --hex-mesh pipe_hex_2.msh --scale 2 >/dev/null
[ -f pipe_hex_2.5.msh ] || "$cm" model pipe 0 --hex-mesh pipe_hex_2.5.msh --scale 2.5 >/dev/null
for f in bore_0.173.vtu pipe_0.118.vtu bore_hex.msh pipe_hex.msh; do
    "$bench" $f "$reps" "$threads" rbf
done
for f in bore_hex_0.667 pipe_hex_2 pipe_hex_2.5; do
    "$bench" $f.msh "$reps" "$threads" femwarp,lbwarp
done
if [ "$bracket" != --no-bracket ]; then
    [ -f bracket_0.0528.vtu ] || "$cm" mesh bracket.step -o bracket_0.0528.vtu --size 0.0528 --mesher tetgen --no-optimize >/dev/null
    "$bench" bracket_0.0528.vtu 1 "$threads" rbf
fi
