#!/bin/sh
# Seed corpora for the fuzz drivers from the small fixtures in tests/data (files < 200 kB).
# usage: seeds.sh SOURCE_DIR CORPUS_DIR
set -eu
src=$1/tests/data
out=$2
for d in msh vtu vtk medit inp dcsv step_scan; do mkdir -p "$out/$d"; done
find "$src" -name '*.msh' -size -200k -exec cp {} "$out/msh/" \;
find "$src" -name '*.vtu' -size -200k -exec cp {} "$out/vtu/" \;
find "$src" -name '*.vtk' -size -200k -exec cp {} "$out/vtk/" \;
find "$src" -name '*.mesh' -size -200k -exec cp {} "$out/medit/" \;
find "$src" -name '*.inp' -size -200k -exec cp {} "$out/inp/" \;
printf '*NODE, NSET=N\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4, ELSET=E\n1, 1, 2, 3,\n 4\n*NSET, NSET=G, GENERATE\n1, 4, 1\n*SURFACE, NAME=S\nE, S1\n' > "$out/inp/seed.inp"
find "$src" -name '*.csv' -size -200k -exec cp {} "$out/dcsv/" \;
find "$src" -name '*.step' -size -200k -exec cp {} "$out/step_scan/" \;
printf 'node,dx,dy,dz\n0,1,2,3\n5,-1e-3,0,1.5\n' > "$out/dcsv/seed.csv"
