#!/bin/sh
# CFD morphs judged by OpenFOAM (benchmarks/cfd/README.md): the 2-D, wedge, symmetry-plane,
# cyclic and snappyHexMesh cases, warp and deform of a body motion on each, checkMesh and 5
# simpleFoam iterations on every written case, one table row per case and morph.
# usage: benchmarks/cfd/run.sh BUILD_DIR [WORK_DIR] [bench_cfd.py options: --size F --cases LIST --morphs LIST]
set -eu
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "${1:?usage: run.sh BUILD_DIR [WORK_DIR] [options]}" && pwd)
shift
work=$build/bench/cfd
case "${1:-}" in
    ""|-*) ;;
    *) work=$1; shift ;;
esac
mkdir -p "$work"
export WM_PROJECT_DIR=${WM_PROJECT_DIR:-/usr/share/openfoam}
echo "# $(date -u '+%Y-%m-%d %H:%M UTC')  $(lscpu | sed -n 's/^Model name: *//p')  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)"
exec /usr/bin/python3 "$here/bench_cfd.py" "$build/cli/cadmorph" "$work" "$@"
