#!/bin/sh
# ~1M cells (make_case.py car1m --base 28: 974,704 cells, 1,033,220 points): read / morph / write
# of the polyMesh against the same mesh as .vtu, CPU s (user, sys) and peak RSS by GNU time, then
# checkMesh and `quality --foam` on the morphed case. The MLS deform of the three roof handles
# (body free) - the dense RBF warp with every boundary node a centre does not fit the session.
# usage (in the directory holding CASE): nice -n 5 sh perf_1m.sh CADMORPH CASE
set -x
export WM_PROJECT_DIR=/usr/share/openfoam
CM=$1; C=$2; D=$(dirname $0)
T="/usr/bin/time -f TIME_%U_%S_%M_%e"
/usr/bin/python3 $D/morph_table.py $CM $C ${C}_runs --handles-only
H=${C}_runs/handles.csv; F=${C}_runs/fixed.csv
printf "node,dx,dy,dz\n0,0,0,0\n" > ${C}.zero.csv
$T $CM warp --method mls --mesh $C --displacements ${C}.zero.csv -o ${C}.vtu | tail -1
$T $CM quality $C | tail -1
$T $CM quality ${C}.vtu | tail -1
rm -rf ${C}_mls; mkdir ${C}_mls; cp -r $C/system ${C}_mls/
$T $CM deform --method mls --mesh $C --handles $H --fixed $F -o ${C}_mls | tail -1
$T $CM deform --method mls --mesh ${C}.vtu --handles $H --fixed $F -o ${C}_mls.vtu | tail -1
$T checkMesh -case $C | grep -E "cells:|points:|Max aspect|non-orthogonality Max|severely|pyramids|skewness|Failed|Mesh OK"
$T checkMesh -case ${C}_mls | grep -E "Max aspect|non-orthogonality Max|severely|pyramids|skewness|Failed|Mesh OK"
$T $CM quality ${C}_mls --foam | tail -6
