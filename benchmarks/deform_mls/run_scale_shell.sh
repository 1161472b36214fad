#!/usr/bin/env bash
# Scale of the MLS deformation ([CMLS §7.1, §7.3]): the structured sphere-handle
# meshes of make_cubed_shell.py from ~16k to ~1M nodes, the paper's 7,000 samples (4,900 on
# the boundary) and 28,000 cubature points at every size; bench_mls: set-up once (CPU s per
# phase), 5 deformations of the same handles, peak RSS. Rows to WORK_DIR/scale_rows.csv.
# usage: run_scale_shell.sh BUILD_DIR WORK_DIR ["N M" ...]
set -euo pipefail
build=$1 work=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
sizes=("$@")
[ ${#sizes[@]} -gt 0 ] || sizes=("16 10" "32 20" "48 30" "64 40")
mkdir -p "$work"
echo "# $(date -u '+%F %H:%M UTC')  $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)  OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-unset}"
echo "nodes,sample_cpu,basis_cpu,factor_cpu,setup_cpu,apply_cpu,peak_mb,factor_entries,phi_entries,residual" > "$work/scale_rows.csv"
for nm in "${sizes[@]}"; do
    read -r n m <<< "$nm"
    d="$work/shell_${n}_$m"
    [ -f "$d/shell.vtu" ] || /usr/bin/python3 "$here/make_cubed_shell.py" "$d" "$n" "$m" 0.5 > /dev/null
    out=$("$build/benchmarks/deform_mls/bench_mls" "$d/shell.vtu" "$d/shell_H.csv" "$d/shell_F.csv" 7000 28000 5)
    echo "$out" | sed "s|^|[$n x $m] |"
    nodes=$(echo "$out" | sed -n 's/^nodes \([0-9]*\),.*/\1/p')
    sc=$(echo "$out" | sed -n 's/.*sample [^ ]* s (CPU \([^)]*\)).*/\1/p')
    bc=$(echo "$out" | sed -n 's/.*basis [^ ]* s (CPU \([^)]*\)).*/\1/p')
    fc=$(echo "$out" | sed -n 's/.*factor [^ ]* s (CPU \([^,]*\), \([0-9]*\) entries).*/\1/p')
    fe=$(echo "$out" | sed -n 's/.*factor [^ ]* s (CPU [^,]*, \([0-9]*\) entries).*/\1/p')
    pe=$(echo "$out" | sed -n 's/.*Phi \([0-9]*\) entries.*/\1/p')
    ac=$(echo "$out" | sed -n 's/.*per deformation [^:]*: [^ ]* s (CPU \([^)]*\)).*/\1/p')
    mb=$(echo "$out" | sed -n 's/.*peak RSS \([0-9]*\) MB.*/\1/p')
    rs=$(echo "$out" | sed -n 's/.*residual \([^;]*\);.*/\1/p')
    echo "$nodes,$sc,$bc,$fc,$(echo "$sc + $bc + $fc" | bc),$ac,$mb,$fe,$pe,$rs" >> "$work/scale_rows.csv"
done
