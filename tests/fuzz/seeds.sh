#!/bin/sh
# Seed corpora for the fuzz drivers from the small fixtures in tests/data (files < 200 kB).
# usage: seeds.sh SOURCE_DIR CORPUS_DIR
set -eu
src=$1/tests/data
out=$2
for d in msh vtu vtk medit exodus dcsv step_scan; do mkdir -p "$out/$d"; done
find "$src" -name '*.msh' -size -200k -exec cp {} "$out/msh/" \;
find "$src" -name '*.vtu' -size -200k -exec cp {} "$out/vtu/" \;
find "$src" -name '*.vtk' -size -200k -exec cp {} "$out/vtk/" \;
find "$src" -name '*.mesh' -size -200k -exec cp {} "$out/medit/" \;
find "$src" \( -name '*.exo' -o -name '*.e' \) -size -200k -exec cp {} "$out/exodus/" \;
find "$src" -name '*.csv' -size -200k -exec cp {} "$out/dcsv/" \;
find "$src" -name '*.step' -size -200k -exec cp {} "$out/step_scan/" \;
printf 'node,dx,dy,dz\n0,1,2,3\n5,-1e-3,0,1.5\n' > "$out/dcsv/seed.csv"
