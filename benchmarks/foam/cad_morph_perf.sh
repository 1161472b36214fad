#!/bin/sh
# The CAD-driven morph of a snappyHexMesh case against the same mesh as .vtu: CPU s and peak RSS
# (GNU time) of read (quality) and read + morph + write, then checkMesh on the input and the
# morphed case. usage (in the directory holding CASE, e.g. make_case.py car300 --base 20):
#   nice -n 10 sh cad_morph_perf.sh CADMORPH CASE
set -x
export WM_PROJECT_DIR=/usr/share/openfoam
CM=$1; C=$2
printf "node,dx,dy,dz\n0,0,0,0\n" > ${C}.zero.csv  # node 0 still: the warp writes a copy
T="/usr/bin/time -f TIME_%U_%S_%M_%e"
$T $CM warp --method mls --mesh $C --displacements ${C}.zero.csv -o ${C}.vtu | tail -1
/usr/bin/python3 $(dirname $0)/make_case.py x --height 0.336 --step-only body_h.step
$T $CM quality $C | tail -1
$T $CM quality ${C}.vtu | tail -1
rm -rf ${C}_cad; mkdir ${C}_cad; cp -r $C/system ${C}_cad/
$T $CM morph --from $C/constant/body.step --to body_h.step --mesh $C -o ${C}_cad --off-cad fixed --cad-tol 0.5 --keep-offset --report ${C}_cad.csv
$T $CM morph --from $C/constant/body.step --to body_h.step --mesh ${C}.vtu -o ${C}_cad.vtu --off-cad fixed --cad-tol 0.5 --keep-offset --report ${C}_vtu.csv
$T checkMesh -case $C | grep -E "cells:|points:|Max aspect|non-orthogonality Max|severely|pyramids|skewness|Failed|Mesh OK"
$T checkMesh -case ${C}_cad | grep -E "Max aspect|non-orthogonality Max|severely|pyramids|skewness|Failed|Mesh OK"
$T $CM quality ${C}_cad --foam | tail -6
