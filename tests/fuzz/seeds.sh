#!/bin/sh
# Seed corpora for the fuzz drivers from the small fixtures in tests/data (files < 200 kB).
# usage: seeds.sh SOURCE_DIR CORPUS_DIR
set -eu
src=$1/tests/data
out=$2
for d in msh vtu vtk medit fluent su2 nastran cgns inp exodus dcsv step_scan; do mkdir -p "$out/$d"; done
find "$src" -name '*.msh' -size -200k -exec cp {} "$out/msh/" \;
find "$src" -name '*.vtu' -size -200k -exec cp {} "$out/vtu/" \;
find "$src" -name '*.vtk' -size -200k -exec cp {} "$out/vtk/" \;
find "$src" -name '*.mesh' -size -200k -exec cp {} "$out/medit/" \;
# Fluent: the ASCII and binary fixtures (their .msh content read through the driver's .cas)
find "$src/fluent" -name '*.msh' -size -200k -exec cp {} "$out/fluent/" \;
find "$src" -name '*.su2' -size -200k -exec cp {} "$out/su2/" \;
find "$src" -name '*.cgns' -size -200k -exec cp {} "$out/cgns/" \;
find "$src" -name '*.inp' -size -200k -exec cp {} "$out/inp/" \;
printf '*NODE, NSET=N\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n*ELEMENT, TYPE=C3D4, ELSET=E\n1, 1, 2, 3,\n 4\n*NSET, NSET=G, GENERATE\n1, 4, 1\n*SURFACE, NAME=S\nE, S1\n' > "$out/inp/seed.inp"
find "$src" \( -name '*.exo' -o -name '*.e' \) -size -200k -exec cp {} "$out/exodus/" \;
find "$src" -name '*.csv' -size -200k -exec cp {} "$out/dcsv/" \;
find "$src" -name '*.step' -size -200k -exec cp {} "$out/step_scan/" \;
printf 'node,dx,dy,dz\n0,1,2,3\n5,-1e-3,0,1.5\n' > "$out/dcsv/seed.csv"
printf 'NDIME= 3\nNELEM= 2\n10 0 1 2 3 0\n14 0 1 4 2 3 1\nNPOIN= 5 5\n0 0 0 0\n1 0 0 1\n0 1 0 2\n0 0 1 3\n1 1 -1 4\nNMARK= 1\nMARKER_TAG= wall\nMARKER_ELEMS= 1\n5 0 1 2\n' > "$out/su2/seed.su2"
printf 'NZONE= 2\nIZONE= 1\nNDIME= 2\nNELEM= 1\n5 0 1 2\nNPOIN= 3\n0 0\n1 0\n0 1\nIZONE= 2\nNDIME= 2\nNELEM= 1\n9 0 1 2 3\nNPOIN= 4\n0 0\n1 0\n1 1\n0 1\nFFD_NBOX= 0\n' > "$out/su2/zones.su2"
find "$src" -name '*.bdf' -size -200k -exec cp {} "$out/nastran/" \;
# Nastran: small, large and free field, a system, continuations (no .bdf fixtures in tests/data)
printf 'BEGIN BULK\nGRID    1       2       0.      0.      0.\nGRID*   2                               1.5-1           1.\n*       0.\nGRID,3,,0.,1.,0.\nGRID    4               0.      0.      1.\nCORD2R  2               0.      0.      0.      0.      0.      1.      +\n+       1.      0.      0.\nCTETRA  1       1       1       2       3       4\nCHEXA   2       1       1       2       3       4       1       2       +\n+       3       4\nENDDATA\n' > "$out/nastran/seed.bdf"
