#!/usr/bin/env bash
# [CMLS §7.2] on the pipe/bore hex meshes, the MLS options against the RBF: one absolute step
# G(0) -> G(1) with `cadmorph morph --method mls` and the MLS options of cm_warp_options
# (samples k, cubature N, coverage s, gamma_s, gamma_b, the residual blend), one row per
# setting, next to rbf. Rows also go to WORK_DIR/hex_rows.csv.
# usage: run_hex_options.sh BUILD_DIR WORK_DIR [MODEL...]
set -euo pipefail
build=$1 work=$2; shift 2
models=${*:-pipe bore}
C=$build/cli/cadmorph
mkdir -p "$work" && cd "$work"
echo "# $(date -u '+%F %H:%M UTC')  $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)"
echo "model,method,options,min_sj,mean_sj,inverted,residual,cpu_s" > hex_rows.csv
echo "| model | method | options | min SJ | mean SJ | inverted | MLS residual | CPU s |"
echo "|---|---|---|---|---|---|---|---|"
variants=(
    ""
    "--blend 0"
    "--samples 1000"
    "--samples 1000 --blend 0"
    "--samples 1500"
    "--samples 1500 --blend 0"
    "--samples 2000"
    "--samples 2000 --blend 0"
    "--samples 3000"
    "--samples 3000 --blend 0"
    "--samples 1000 --cubature 16000"
    "--cover 8"
    "--stretch 0 --bend 1"
    "--stretch 1 --bend 0"
    "--stretch 1 --bend 10"
    "--samples 2000 --stretch 0 --bend 1"
)
for model in $models; do
    [ -f ${model}_0.step ] || $C model $model 0 ${model}_0.step > /dev/null
    [ -f ${model}_1.step ] || $C model $model 1 ${model}_1.step > /dev/null
    [ -f hex_$model.vtu ] || $C model $model 0 --hex-mesh hex_$model.vtu > /dev/null
    row() { # method options...
        local method=$1; shift
        local out cpu
        out=$( { /usr/bin/time -f "CPU %U %S" $C morph --from ${model}_0.step --to ${model}_1.step \
                 --mesh hex_$model.vtu -o ${model}_out.vtu --method $method --steps 1 --allow-inverted \
                 "$@" --verbose; } 2>&1)
        cpu=$(echo "$out" | awk '/^CPU /{printf "%.1f", $2 + $3}')
        local q=$(echo "$out" | grep 'min_scaled_jacobian=' | tail -1)
        local res=$(echo "$out" | grep 'warp mls:' | tail -1 | sed 's/.*residual \([^;]*\);.*/\1/' || true)
        printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n" $model $method "${*:-default}" \
            $(echo "$q" | sed 's/.*min_scaled_jacobian=\([^ ]*\).*/\1/') \
            $(echo "$q" | sed 's/.*mean_scaled_jacobian=\([^ ]*\).*/\1/') \
            $(echo "$q" | sed 's/.*inverted=\([^ ]*\).*/\1/') "${res:--}" "$cpu"
        echo "$model,$method,${*:-default},$(echo "$q" | sed 's/.*min_scaled_jacobian=\([^ ]*\) mean_scaled_jacobian=\([^ ]*\) inverted=\([^ ]*\).*/\1,\2,\3/'),${res:--},$cpu" >> hex_rows.csv
    }
    row rbf
    for v in "${variants[@]}"; do
        # shellcheck disable=SC2086
        row mls $v
    done
done
