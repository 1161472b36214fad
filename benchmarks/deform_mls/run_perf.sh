#!/usr/bin/env bash
# Figure 4 of the MLS paper (issue 15): time against the number of centres / samples, global
# dense RBF (bench_rbf: fit + evaluation at 10 m points; the triharmonic kernel, whose dense
# Cholesky costs the same as the biharmonic one) next to the MLS deformation (cadmorph deform
# on the sphere mesh of make_cases.py: sampling, shape functions, CHOLMOD factorisation, one
# apply), run alternately in one session.
# usage: run_perf.sh BUILD_DIR WORK_DIR [K...]
set -euo pipefail
build=$1 work=$2; shift 2
ks=${*:-1000 2000 4000 8000}
here=$(cd "$(dirname "$0")" && pwd)
C=$build/cli/cadmorph
mkdir -p "$work" && cd "$work"
[ -f sphere.msh ] || /usr/bin/python3 "$here/make_cases.py" . 0.165 > /dev/null
awk -F, 'NR==1{print;next}{printf "%s,0.5,0,0\n",$1}' sphere_H.csv > perf_H.csv
echo "# $(date -u '+%F %H:%M UTC')  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)"
echo "| k | rbf fit s | rbf eval s | rbf total s | mls sample s | mls basis s | mls factor s | mls apply s | mls total s | factor entries |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for k in $ks; do
    r=$("$build/benchmarks/bench_rbf" "$k" "$work" 2 1)
    fit=$(echo "$r" | tr ' ' '\n' | sed -n 's/^fit_s=//p')
    ev=$(echo "$r" | tr ' ' '\n' | sed -n 's/^eval_s=//p')
    d=$($C deform --mesh sphere.msh --handles perf_H.csv --fixed sphere_F.csv --method mls \
        --samples "$k" -o perf.vtu --verbose 2>&1 | grep 'deform mls:')
    s=$(echo "$d" | sed 's/.*sample \([^ ]*\) s.*/\1/')
    b=$(echo "$d" | sed 's/.*basis \([^ ]*\) s.*/\1/')
    f=$(echo "$d" | sed 's/.*factor \([^ ]*\) s.*/\1/')
    e=$(echo "$d" | sed 's/.*(\([0-9]*\) entries).*/\1/')
    a=$(echo "$d" | sed 's/.*apply \([^ ]*\) s.*/\1/')
    printf "| %s | %s | %s | %.3f | %s | %s | %s | %s | %.3f | %s |\n" "$k" "$fit" "$ev" \
        "$(echo "$fit + $ev" | bc)" "$s" "$b" "$f" "$a" "$(echo "$s + $b + $f + $a" | bc)" "$e"
done
