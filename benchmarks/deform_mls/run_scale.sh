#!/usr/bin/env bash
# Scale block of [CMLS §7.1, §7.3] at the sizes this machine meshes in
# minutes: the sphere case of make_cases.py at size S (0.075: 115k nodes, 650k tets), cavity
# moved by 0.5; MLS at the default and at 5,000 samples, then the dense RBF (all H and F
# nodes as centres). Peak memory from /usr/bin/time.
# usage: run_scale.sh BUILD_DIR WORK_DIR [S]
set -u
C=$1/cli/cadmorph
mkdir -p "$2" && cd "$2"
[ -f sphere.msh ] || /usr/bin/python3 "$(dirname "$0")/make_cases.py" . "${3:-0.075}" > /dev/null
echo "# $(date -u '+%F %H:%M UTC') load=$(cut -d' ' -f1-3 /proc/loadavg)"
awk -F, 'NR==1{print;next}{printf "%s,0.5,0,0\n",$1}' sphere_H.csv > H05.csv
$C quality sphere.msh | tail -1
for k in 0 5000; do
  a=""; [ $k -gt 0 ] && a="--samples $k"
  /usr/bin/time -f "wall %e s peak %M KB" $C deform --mesh sphere.msh --handles H05.csv --fixed sphere_F.csv --method mls $a -o out_mls.vtu --verbose 2>&1 | grep -v "^type\|^tet4\|^cm_rbf"
done
/usr/bin/time -f "wall %e s peak %M KB" $C deform --mesh sphere.msh --handles H05.csv --fixed sphere_F.csv --method rbf -o out_rbf.vtu 2>&1 | grep -v "^type\|^tet4\|^cm_rbf"
