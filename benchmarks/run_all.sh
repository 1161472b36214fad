#!/bin/sh
# Runs every benchmark whose figures are in RESULTS.md, one after the other (they compete for
# the same cores otherwise). The build directory must be configured with
# -DCADMORPH_BUILD_BENCHMARKS=ON (`make bench` does that, then runs this script).
# usage: benchmarks/run_all.sh [BUILD_DIR]   (default: build)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
work=$build/bench
if [ ! -x "$build/benchmarks/mesh_io/bench_mesh_io" ]; then
    echo "run_all.sh: no benchmark programs in $build: configure it with -DCADMORPH_BUILD_BENCHMARKS=ON" >&2
    exit 1
fi
rbf=$here/rbf
mkdir -p "$work"
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "== mesh I/O";            "$build/benchmarks/mesh_io/bench_mesh_io" "$work"
echo "== quality";             sh "$here/quality/bench_quality.sh" "$build"
echo "== RBF vs scipy";        sh "$rbf/bench_rbf.sh" "$build" 2
echo "== CAD layer";           "$build/benchmarks/cad/bench_cad" "$root/tests/data/cad/bore_a.step" 1e6 1e5 2
echo "== models, tet meshes";  sh "$here/models/bench_models.sh" "$build" "$work/models"
echo "== sweeps (20 steps, all models)"; sh "$here/sweep/run_sweeps.sh" "$build" "$work/sweeps" 2
echo "== study: 20 bore variants vs one"; sh "$here/study/bench_study.sh" "$build" "$work/study" 2
echo "== the guarded morph against --steps 1"; sh "$here/morph_guard/run.sh" "$build" "$work/morph_guard" 5
echo "== warp methods side by side"; sh "$here/warp/bench_warp.sh" "$build" "$work/warp" 2
echo "== gradients: the warps' reverse product against one apply"; sh "$here/gradients/bench_warp_vjp.sh" "$build" "$work/gradients" 2
echo "== warp methods in the sweeps"; sh "$here/warp/bench_warp_sweep.sh" "$build" "$work/wsweep" 2
echo "== Python binding";      /usr/bin/python3 "$here/python/bench_binding.py" "$build" "$work/python"
echo "== mesh formats against .vtu (1M tets)"; sh "$here/formats/bench_formats.sh" "$build/cli/cadmorph" "$work/formats"
echo "== CFD meshes: body motions judged by checkMesh and simpleFoam"; sh "$here/cfd/run.sh" "$build" "$work/cfd"
