#!/bin/sh
# ~1M cells (make_case.py car1m --base 28: 974,704 cells, 1,033,220 points): the Table-2 rows
# of [SMB14] at 1M cells, one job at a time (benchmarks/foam/table_row.py: GNU time,
# the real checkMesh and `quality --foam` on each written case), and read / morph / write of
# the polyMesh against the same mesh as .vtu.
# usage (in the directory holding CASE): nice -n 10 sh perf_1m.sh CADMORPH CASE
set -x
export WM_PROJECT_DIR=/usr/share/openfoam OPENBLAS_VERBOSE=2
CM=$1; C=$2; D=$(dirname $0); W=${C}_runs
T="/usr/bin/time -f TIME_%U_%S_%M_%e"
R="/usr/bin/python3 $D/table_row.py $CM $C $W"
/usr/bin/python3 $D/morph_table.py $CM $C $W --handles-only
H=$W/handles.csv; F=$W/fixed.csv
printf "node,dx,dy,dz\n0,0,0,0\n" > $W/zero.csv
# the .vtu twin: the polyMesh read and written as .vtu (a one-node zero displacement: a copy)
$T $CM warp --method mls --mesh $C --displacements $W/zero.csv -o $W/input.vtu | tail -1
$T $CM quality $C | tail -1
$T $CM quality $W/input.vtu | tail -1
$R input
# MLS, body free: the default samples (uniform by volume and area) and --graded 1
$R mls
$R mls_graded1 -- deform --method mls --mesh $C --handles $H --fixed $F --graded 1
$T $CM deform --method mls --mesh $W/input.vtu --handles $H --fixed $F --graded 1 -o $W/mls_graded1.vtu | tail -1
# DM-FFD (all boundary nodes constrained), RBF (iterative solver: 62,215 centres)
$R dmffd10
$R dmffd15
$R dmffd25
$R rbf --verbose
# the CAD-driven morph onto the 5%-higher roof, the RBF's default tolerance and 1e-6
$R cad --verbose --report $W/cad_report.csv
$R cad_tol6 -- morph --from $C/constant/body.step --to $W/body_h.step --mesh $C --off-cad fixed \
  --cad-tol 0.5 --keep-offset --rbf-tol 1e-6 --verbose --report $W/cad_tol6_report.csv
$R cad_tol6_vtu -- morph --from $C/constant/body.step --to $W/body_h.step --mesh $W/input.vtu \
  --off-cad fixed --cad-tol 0.5 --keep-offset --rbf-tol 1e-6 --report $W/cad_tol6_vtu_report.csv
cat $W/rows.md
