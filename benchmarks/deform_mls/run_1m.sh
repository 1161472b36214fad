#!/usr/bin/env bash
# Sections 7.1/7.3 of [CMLS] at the paper's volume size: a ~1M-node structured hex mesh of the
# sphere-handle case (make_cubed_shell.py: cube [0,4]^3 minus a ball of radius 1, six blocks
# of 64 x 64 x 41 nodes), H = the cavity's nodes moved by (0.5, 0, 0), F = the cube's faces;
# MLS with 7,000 samples (70 % = 4,900 on the boundary, 2,100 inside: the paper's 5k + 2k)
# and 28,000 cubature points. Set-up (sampling, shape functions, factorisation), the time per
# deformation (one CHOLMOD solve + the sparse product at every node) and peak memory.
# usage: run_1m.sh CADMORPH WORK_DIR [N M]
set -euo pipefail
C=$1 work=$2 n=${3:-64} m=${4:-40}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work" && cd "$work"
[ -f shell.vtu ] || /usr/bin/python3 "$here/make_cubed_shell.py" . "$n" "$m" 0.5
echo "# $(date -u '+%F %H:%M UTC')  $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)  OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-unset}"
$C quality shell.vtu | tail -1 | sed 's/^/input: /'
/usr/bin/time -f "time: wall %e s, user %U s, sys %S s, peak %M KB" \
    $C deform --mesh shell.vtu --handles shell_H.csv --fixed shell_F.csv --method mls \
    --samples 7000 --cubature 28000 -o shell_mls.vtu --verbose 2>&1 | grep -E "cm_mls: sampling|deform mls:|^deform:|min_scaled|^time:"
