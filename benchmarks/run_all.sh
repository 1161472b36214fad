#!/bin/sh
# Runs every benchmark whose figures are in RESULTS.md, one after the other (they compete for
# the same two cores otherwise). usage: benchmarks/run_all.sh BUILD_DIR
set -eu
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
work=$build/bench
mkdir -p "$work"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "== mesh I/O";            "$build/benchmarks/bench_mesh_io" "$work"
echo "== quality";             sh "$root/benchmarks/bench_quality.sh" "$build"
echo "== RBF vs scipy";        sh "$root/benchmarks/rbf/bench_rbf.sh" "$build" 2
echo "== CAD layer";           "$build/benchmarks/bench_cad" "$root/tests/data/cad/bore_a.step" 1e6 1e5 2
echo "== models, tet meshes";  sh "$root/benchmarks/models/bench_models.sh" "$build" "$work/models"
echo "== sweeps (20 steps, all models)"; sh "$root/benchmarks/sweep/run_sweeps.sh" "$build" "$work/sweeps" 2
echo "== study: 20 bore variants vs one"; sh "$root/benchmarks/bench_study.sh" "$build" "$work/study" 2
echo "== warp methods side by side"; sh "$root/benchmarks/bench_warp.sh" "$build" "$work/warp" 2
echo "== warp methods in the sweeps"; sh "$root/benchmarks/bench_warp_sweep.sh" "$build" "$work/wsweep" 2
