#!/usr/bin/env bash
# [CMLS §7.2] sphere handle: a gmsh box with a spherical cavity (~13k nodes), the
# outer boundary fixed, the cavity's nodes moved by (DX, 0, 0); min scaled Jacobian for the
# triharmonic RBF and the MLS deformation (default, pure bending, pure stretching), and FEMWARP
# (`cadmorph warp --method femwarp`: P1 Laplace per coordinate, i.e. the exact minimiser of
# the stretching energy on the mesh with the same H and F) as the reference of pure stretching.
# Rows also go to WORK_DIR/sphere_rows.csv (dx,method,k,min_sj,mean_sj,inverted,residual,s).
# usage: run_sphere.sh BUILD_DIR WORK_DIR [DX...]
set -euo pipefail
build=$1 work=$2; shift 2
dxs=${*:-0.5 0.8}
here=$(cd "$(dirname "$0")" && pwd)
C=$build/cli/cadmorph
mkdir -p "$work" && cd "$work"
[ -f sphere.msh ] || /usr/bin/python3 "$here/make_cases.py" . 0.165
echo "# $(date -u '+%F %H:%M UTC')  $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)"
$C quality sphere.msh | tail -1 | sed 's/^/input: /'
echo "dx,method,k,min_sj,mean_sj,inverted,residual,s" > sphere_rows.csv
echo "| dx | method | samples | min SJ | mean SJ | inverted | residual | time s |"
echo "|---|---|---|---|---|---|---|---|"
row() { # dx label samples args...
    local dx=$1 label=$2 k=$3; shift 3
    local out
    out=$($C deform --mesh sphere.msh --handles "sphere_H_$dx.csv" --fixed sphere_F.csv "$@" -o out.vtu)
    local q=$(echo "$out" | tail -1) d=$(echo "$out" | grep '^deform:')
    local mn=$(echo "$q" | sed 's/.*min_scaled_jacobian=\([^ ]*\).*/\1/')
    local me=$(echo "$q" | sed 's/.*mean_scaled_jacobian=\([^ ]*\).*/\1/')
    local inv=$(echo "$q" | sed 's/.*inverted=\([^ ]*\).*/\1/')
    local res=$(echo "$d" | sed 's/.*residual \(.*\)$/\1/')
    local t=$(echo "$d" | sed 's/.*free, \([^ ]*\) s,.*/\1/')
    echo "| $dx | $label | $k | $mn | $me | $inv | $res | $t |"
    echo "$dx,$label,$k,$mn,$me,$inv,$res,$t" >> sphere_rows.csv
}
for dx in $dxs; do
    awk -F, -v dx="$dx" 'NR==1{print;next}{printf "%s,%s,0,0\n",$1,dx}' sphere_H.csv > "sphere_H_$dx.csv"
    row "$dx" "rbf (triharmonic)" - --method rbf
    q=$($C warp --mesh sphere.msh --displacements "sphere_H_$dx.csv" --method femwarp -o out.vtu | tail -1)
    mn=$(echo "$q" | sed 's/.*min_scaled_jacobian=\([^ ]*\).*/\1/')
    me=$(echo "$q" | sed 's/.*mean_scaled_jacobian=\([^ ]*\).*/\1/')
    inv=$(echo "$q" | sed 's/.*inverted=\([^ ]*\).*/\1/')
    echo "| $dx | femwarp (exact stretching minimiser) | - | $mn | $me | $inv | 0 | - |"
    echo "$dx,femwarp (exact stretching minimiser),-,$mn,$me,$inv,0,-" >> sphere_rows.csv
    for k in 500 1000 2000; do
        row "$dx" "mls gs=1 gb=1" $k --method mls --samples $k
        row "$dx" "mls bending (gs=0 gb=1)" $k --method mls --stretch 0 --bend 1 --samples $k
        row "$dx" "mls stretching (gs=1 gb=0)" $k --method mls --stretch 1 --bend 0 --samples $k
    done
done
