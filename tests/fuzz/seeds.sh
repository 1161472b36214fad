#!/bin/sh
# Seed corpora for the fuzz drivers from the small fixtures in tests/data (files < 200 kB).
# usage: seeds.sh SOURCE_DIR CORPUS_DIR
set -eu
src=$1/tests/data
out=$2
for d in msh vtu vtk medit fluent su2 nastran cgns inp exodus obj off stl foam foam_gz dcsv prm ctrl nodes sens design list step_scan; do mkdir -p "$out/$d"; done
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
# Surfaces (no fixtures in tests/data): OBJ with v/vt/vn and f a/b/c forms, OFF with a
# comment and a polygon, STL in ASCII and binary (80-byte header, count, 50 bytes a facet)
printf '# tet\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\nvn 0 0 1\nf 1 3 2\nf 1/1 2/1 4/1\nf 1//1 4//1 3//1\nf 2/1/1 3/1/1 4/1/1\n' > "$out/obj/tet.obj"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\ng quad\nf -4 -3 -2 -1\n' > "$out/obj/quad.obj"
printf 'OFF\n# tet\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n' > "$out/off/tet.off"
printf 'OFF 5 1 0\n0 0 0\n1 0 0\n1 1 0\n0.5 1.5 0\n0 1 0\n5 0 1 2 3 4\n' > "$out/off/pentagon.off"
printf 'solid t\nfacet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\nfacet normal 0 0 0\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 0 1\n endloop\nendfacet\nendsolid t\n' > "$out/stl/ascii.stl"
/usr/bin/python3 -c '
import struct, sys
tris = [((0,0,0),(0,1,0),(1,0,0)), ((0,0,0),(1,0,0),(0,0,1)), ((0,0,0),(0,0,1),(0,1,0)), ((1,0,0),(0,1,0),(0,0,1))]
b = b"binary seed".ljust(80, b" ") + struct.pack("<I", len(tris))
for t in tris:
    b += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *v) for v in t) + b"\0\0"
open(sys.argv[1], "wb").write(b)' "$out/stl/binary.stl"
# OpenFOAM polyMesh (fuzz_foam): two hex cells, one internal face, two patches, a cell zone;
# the members joined by the driver's separator line "@@"
foam() { printf 'FoamFile\n{\n    version 2.0;\n    format ascii;\n    class %s;\n    object %s;\n}\n' "$1" "$2"; }
{
  foam vectorField points
  printf '12\n(\n(0 0 0)\n(1 0 0)\n(2 0 0)\n(0 1 0)\n(1 1 0)\n(2 1 0)\n(0 0 1)\n(1 0 1)\n(2 0 1)\n(0 1 1)\n(1 1 1)\n(2 1 1)\n)\n'
  printf '@@\n'
  foam faceList faces
  printf '11\n(\n4(1 4 10 7)\n4(0 6 9 3)\n4(0 1 7 6)\n4(3 9 10 4)\n4(0 3 4 1)\n4(6 7 10 9)\n4(2 5 11 8)\n4(1 2 8 7)\n4(4 10 11 5)\n4(1 4 5 2)\n4(7 8 11 10)\n)\n'
  printf '@@\n'
  foam labelList owner
  printf '11\n(\n0\n0\n0\n0\n0\n0\n1\n1\n1\n1\n1\n)\n'
  printf '@@\n'
  foam labelList neighbour
  printf '1\n(\n1\n)\n'
  printf '@@\n'
  foam polyBoundaryMesh boundary
  printf '2\n(\ninlet\n{\n    type patch;\n    nFaces 1;\n    startFace 1;\n}\nwalls\n{\n    type wall;\n    inGroups 1(wall);\n    nFaces 9;\n    startFace 2;\n}\n)\n'
  printf '@@\n'
  foam regIOobject cellZones
  printf '1\n(\nleft\n{\n    type cellZone;\ncellLabels List<label> 1(0);\n}\n)\n'
} > "$out/foam/two_hex"
# the same case with uniform lists and a compact face list
{
  foam vectorField points
  printf '12((0 0 0)(1 0 0)(2 0 0)(0 1 0)(1 1 0)(2 1 0)(0 0 1)(1 0 1)(2 0 1)(0 1 1)(1 1 1)(2 1 1))\n'
  printf '@@\n'
  foam faceCompactList faces
  printf '12(0 4 8 12 16 20 24 28 32 36 40 44)\n44(1 4 10 7 0 6 9 3 0 1 7 6 3 9 10 4 0 3 4 1 6 7 10 9 2 5 11 8 1 2 8 7 4 10 11 5 1 4 5 2 7 8 11 10)\n'
  printf '@@\n'
  foam labelList owner
  printf '11(0 0 0 0 0 0 1 1 1 1 1)\n'
  printf '@@\n'
  foam labelList neighbour
  printf '1{1}\n'
  printf '@@\n'
  foam polyBoundaryMesh boundary
  printf '1(walls { type wall; nFaces 10; startFace 1; })\n'
} > "$out/foam/compact"
cp "$out/foam/"* "$out/foam_gz/"
# tables and lists (tests/fuzz/fuzz_table.c: its directory holds a.step, b.step, sub/c.step)
find "$src/deform" -name '*.prm' -exec cp {} "$out/prm/" \;
printf '[Box info]\nn control points x: 2\nn control points y: 1\nn control points z: 1\nbox length x: 2\nbox length y: 1\nbox length z: 1\nbox origin x: 0\nbox origin y: 0\nbox origin z: 0\nrotation angle x: 0\nrotation angle y: 0\nrotation angle z: 30\n[Parameters weights]\nparameter x: 0 0 0 0.5\n  1 0 0 -1e-3\nparameter y: 1 0 0 2\nparameter z: 0 0 0 0\n' > "$out/prm/small.prm"
printf 'i,j,k,dx,dy,dz\n0,0,0,0.1,0,0\n3,2,1,-1,2.5e-1,3\n1,1,0,0,0,1\n' > "$out/ctrl/seed.csv"
printf 'i,j,k,dx,dy,dz\r\n\r\n2,0,1,1,1,1\r\n' > "$out/ctrl/crlf.csv"
printf 'node\n0\n5\n63 \n\n7\n' > "$out/nodes/seed.csv"
printf 'node\r\n1\r\n2\r\n' > "$out/nodes/crlf.csv"
printf 'node,gx,gy,gz\n0,1,0,0\n63,-1e-3,2,3.5\n\n10,0,0,1\n' > "$out/sens/seed.csv"
printf 'step,lx,r\na.step,1,2\nb.step,1.5,2\nsub/c.step,1,2.5\n' > "$out/design/seed.csv"
printf '\357\273\277Step , "a, b" ,c\r\n\r\n"a.step",1,-2e-3\r\n"b.step","3",4\r\n' > "$out/design/quoted.csv"
printf '# variants\na.step\n  b.step  # the second\n\nsub/c.step\r\n' > "$out/list/seed.txt"
# a compressed member as it is in a case (faces.gz): the driver writes a member that starts
# with the gzip magic bytes as NAME.gz
/usr/bin/python3 -c '
import gzip, sys
m = open(sys.argv[1], "rb").read().split(b"\n@@\n")
m[1] = gzip.compress(m[1] + b"\n", 9)
open(sys.argv[2], "wb").write(b"\n@@\n".join(m))' "$out/foam/two_hex" "$out/foam/faces_gz"
