#!/bin/sh
# Benchmark of `cadmorph quality` on a ~1M-tet gmsh mesh of the unit box.
# usage: benchmarks/quality/bench_quality.sh [BUILD_DIR]   (default: build)
# Generates BUILD_DIR/bench/box_1m.msh once (gmsh, binary msh 4.1; not committed), then times
# the whole command with /usr/bin/time -v (wall time, peak memory) at 1 and 2 threads, and
# the stages alone with bench_quality (built with -DCADMORPH_BUILD_BENCHMARKS=ON).
set -eu
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
BUILD=$(cd "${1:-$ROOT/build}" && pwd)
OUT=$BUILD/bench
MESH=$OUT/box_1m.msh
mkdir -p "$OUT"
if [ ! -f "$MESH" ]; then
  /usr/bin/python3 - "$MESH" <<'PY'
import sys, gmsh
gmsh.initialize()
gmsh.option.setNumber("General.Terminal", 0)
gmsh.model.add("box")
gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
gmsh.model.occ.synchronize()
gmsh.option.setNumber("Mesh.MeshSizeMax", 0.016)    # ~1M tets
gmsh.option.setNumber("Mesh.Algorithm3D", 10)       # HXT: parallel Delaunay
gmsh.option.setNumber("General.NumThreads", 2)
gmsh.model.mesh.generate(3)
gmsh.option.setNumber("Mesh.Binary", 1)
gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
gmsh.write(sys.argv[1])
gmsh.finalize()
PY
fi
echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p')"
ls -l "$MESH"
for t in 1 2; do
  echo "== cadmorph quality --threads $t"
  /usr/bin/time -v "$BUILD/cli/cadmorph" quality "$MESH" --threads $t 2> "$OUT/time_$t.txt"
  grep -E "Elapsed \(wall|Maximum resident|User time|System time" "$OUT/time_$t.txt"
  echo "== stages, $t threads"
  "$BUILD/benchmarks/quality/bench_quality" "$MESH" $t
done
