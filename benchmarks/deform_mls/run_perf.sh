#!/usr/bin/env bash
# Figure 4 of the MLS paper [CMLS]: time against the number of centres / samples, global
# dense RBF (bench_rbf: fit + evaluation at 10 m points; the triharmonic kernel, whose dense
# Cholesky costs the same as the biharmonic one) next to the MLS deformation (cadmorph deform
# on the sphere mesh of make_cases.py: sampling, shape functions, CHOLMOD factorisation, one
# apply), run alternately in one run, both on one thread: the RBF's best-of-repeats wall
# time, the MLS's CPU seconds (the machine is shared; CPU seconds are what a quiet one shows).
# Rows also go to WORK_DIR/perf_rows.csv.
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
echo "k,rbf_fit,rbf_eval,rbf_total,mls_sample,mls_basis,mls_factor,mls_apply,mls_setup,mls_total" > perf_rows.csv
echo "| k | rbf fit s | rbf eval s | rbf total s | mls sample CPU s | mls basis CPU s | mls factor CPU s | mls apply CPU s | mls total CPU s | factor entries |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for k in $ks; do
    r=$("$build/benchmarks/rbf/bench_rbf" "$k" "$work" 1 2)
    fit=$(echo "$r" | tr ' ' '\n' | sed -n 's/^fit_s=//p')
    ev=$(echo "$r" | tr ' ' '\n' | sed -n 's/^eval_s=//p')
    d=$($C deform --mesh sphere.msh --handles perf_H.csv --fixed sphere_F.csv --method mls \
        --samples "$k" -o perf.vtu --threads 1 --verbose 2>&1 | grep 'deform mls:')
    cpu=$(echo "$d" | sed 's/.*CPU s \(.*\)$/\1/' | tr -d ',')
    read -r s b f a <<< "$cpu"
    e=$(echo "$d" | sed 's/.*(\([0-9]*\) entries).*/\1/')
    printf "| %s | %s | %s | %.3f | %s | %s | %s | %s | %.3f | %s |\n" "$k" "$fit" "$ev" \
        "$(echo "$fit + $ev" | bc)" "$s" "$b" "$f" "$a" "$(echo "$s + $b + $f + $a" | bc)" "$e"
    echo "$k,$fit,$ev,$(echo "$fit + $ev" | bc),$s,$b,$f,$a,$(echo "$s + $b + $f" | bc),$(echo "$s + $b + $f + $a" | bc)" >> perf_rows.csv
done
