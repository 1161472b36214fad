#!/bin/sh
# RBF core vs scipy on identical data (torus, m centres, n = 10 m points inside).
# usage: benchmarks/rbf/bench_rbf.sh BUILD_DIR [THREADS] [M...]
#   SCIPY_MAX=M  largest m also run through scipy (default 10000)
#   REPS=R       repetitions per m, best times reported (default 3; 1 for m > 10000)
#   SOLVER=S     auto (default: cm_rbf_create's choice, iterative above its crossover), dense
#                or iterative (fit / Cholesky bound is a dense figure: use SOLVER=dense)
#   WARM_GB=G    touch G GB of memory first (default 0 = off). The Firecracker VM we run on
#                backs guest memory on first touch and reclaims freed memory, so fresh memory
#                costs ~1-5 s/GB in every process (ours and scipy's alike); warming did not
#                help here but is kept for machines where it does.
# Each m runs in fresh processes so that getrusage's peak RSS belongs to that m alone.
set -eu
build=${1:?usage: bench_rbf.sh BUILD_DIR [THREADS] [M...]}
threads=${2:-0}
[ $# -ge 2 ] && shift 2 || shift $#
sizes=${*:-1000 2000 5000 10000 20000}
here=$(cd "$(dirname "$0")" && pwd)
bench=$build/benchmarks/rbf/bench_rbf
scipy_max=${SCIPY_MAX:-10000}
scipy_threads=$threads; [ "$threads" -gt 0 ] || scipy_threads=$(nproc)
work=$(mktemp -d /tmp/bench_rbf.XXXXXX)
trap 'rm -rf "$work"' EXIT
echo "# $(date -u '+%Y-%m-%d %H:%M UTC')  $(lscpu | sed -n 's/^Model name: *//p')  nproc=$(nproc)  threads=$threads  load=$(cut -d' ' -f1-3 /proc/loadavg)"
[ "${WARM_GB:-0}" = 0 ] || "$bench" warm "$WARM_GB"
for m in $sizes; do
    reps=${REPS:-3}
    [ -n "${REPS:-}" ] || [ "$m" -le 10000 ] || reps=1
    "$bench" "$m" "$work" "$threads" "$reps" "${SOLVER:-auto}"
    if [ "$m" -le "$scipy_max" ]; then
        OPENBLAS_NUM_THREADS=$scipy_threads /usr/bin/python3 "$here/bench_rbf_scipy.py" "$m" "$work" "$reps"
    fi
done
