#!/usr/bin/env bash
# [CMLS §7.2] on the pipe hex: the structured O-grid hex meshes of the pipe and bore models
# (`cadmorph model --hex-mesh`), one absolute step G(0) -> G(1) with the triharmonic RBF and the MLS
# warp (`cadmorph morph --method mls`, default weights and samples) as interior method.
# usage: run_hex.sh BUILD_DIR WORK_DIR
set -euo pipefail
build=$1 work=$2
C=$build/cli/cadmorph
mkdir -p "$work" && cd "$work"
echo "# $(date -u '+%F %H:%M UTC')  $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)"
echo "| model | nodes | M(0) min SJ | method | min SJ | mean SJ | inverted | MLS residual | time s |"
echo "|---|---|---|---|---|---|---|---|---|"
for model in pipe bore; do
    [ -f ${model}_0.step ] || $C model $model 0 ${model}_0.step > /dev/null
    [ -f ${model}_1.step ] || $C model $model 1 ${model}_1.step > /dev/null
    [ -f hex_$model.vtu ] || $C model $model 0 --hex-mesh hex_$model.vtu > /dev/null
    q0=$($C quality hex_$model.vtu | tail -1 | sed 's/.*min_scaled_jacobian=\([^ ]*\).*/\1/')
    nodes=$($C info --help > /dev/null 2>&1; /usr/bin/python3 -c "import meshio; print(len(meshio.read('hex_$model.vtu').points))")
    for method in rbf mls; do
        t0=$(date +%s.%N)
        out=$($C morph --from ${model}_0.step --to ${model}_1.step --mesh hex_$model.vtu \
              -o ${model}_$method.vtu --method $method --steps 1 --allow-inverted --verbose 2>&1)
        t1=$(date +%s.%N)
        q=$(echo "$out" | tail -1)
        res=$(echo "$out" | grep 'warp mls:' | sed 's/.*residual \([^;]*\);.*/\1/' || true)
        printf "| %s | %s | %s | %s | %s | %s | %s | %s | %.1f |\n" $model $nodes $q0 $method \
            $(echo "$q" | sed 's/.*min_scaled_jacobian=\([^ ]*\).*/\1/') \
            $(echo "$q" | sed 's/.*mean_scaled_jacobian=\([^ ]*\).*/\1/') \
            $(echo "$q" | sed 's/.*inverted=\([^ ]*\).*/\1/') "${res:--}" "$(echo "$t1 - $t0" | bc)"
    done
done
