#!/bin/sh
# The distributed solver (--solver petsc, -DCADMORPH_WITH_PETSC=ON) beside the serial iterative
# one on one mesh, one child process per row, one after the other: `cadmorph warp` with the
# serial solver on THREADS threads, then PETSc on 1 rank x THREADS threads and on 2 ranks x 1
# thread. Rows: wall and CPU seconds (the child's user + sys), warp create (set-up) and apply
# (solve + evaluation) seconds, joint iterations, max node difference to the serial result
# over the displacement range. usage: bench_rbf_petsc.sh BUILD_DIR MESH D.csv [WORK] [THREADS]
# (D.csv: bench_warp_scipy.py --csv MESH MORPHED D.csv, of the warp benchmarks). RUNS (environment) picks
# the rows, "solver ranks threads" separated by ';' (default: the three above); the serial
# reference for "vs serial" is WORK/iterative_1xTHREADS.vtu, from this or an earlier run.
set -eu
build=${1:?usage: bench_rbf_petsc.sh BUILD_DIR MESH D.csv [WORK] [THREADS]}
mesh=${2:?mesh}
csv=${3:?D.csv}
work=${4:-$build/bench/petsc}
threads=${5:-2}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OPENBLAS_VERBOSE=2
echo "# $(date -u '+%Y-%m-%d %H:%M UTC')  $(lscpu | sed -n 's/^Model name: *//p')  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)  OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:--}"
echo "| solver | ranks x threads | wall s | CPU s | create s | apply s | iterations | BLAS core | vs serial |"
echo "|---|---|---|---|---|---|---|---|---|"
runs=${RUNS:-"iterative 1 $threads;petsc 1 $threads;petsc 2 1"}
IFS=';'
for run in $runs; do
    IFS=' '
    set -- $run
    out="$work/${1}_$2x$3.vtu"
    launch=""
    # OpenMPI binds each rank to one core by default, so a rank of 2 threads would run on one
    [ "$1" = petsc ] && launch="mpirun -n $2 --oversubscribe"
    [ "$1" = petsc ] && [ "$3" -gt 1 ] && launch="$launch --bind-to none"
    /usr/bin/time -f "time wall=%e cpu=%U+%S" $launch "$build/cli/cadmorph" warp --mesh "$mesh" \
        --displacements "$csv" -o "$out" --solver "$1" --threads "$3" -v \
        >"$work/out.txt" 2>"$work/err.txt"
    cmp=-
    [ "$1" = petsc ] && cmp=$(OPENBLAS_VERBOSE=0 /usr/bin/python3 "$here/../../tests/cli/compare_moved.py" \
        "$work/iterative_1x$threads.vtu" "$out" 1 | sed 's/max node difference \([^ ]*\).*/\1/')
    awk -v s="$1" -v rt="$2 x $3" -v cmp="$cmp" '
        /^time / { split($2, a, "="); wall = a[2]; split($3, b, "[=+]"); cpu = b[2] + b[3] }
        /warp: rbf/ && !create { match($0, /create [0-9.]+/); create = substr($0, RSTART + 7, RLENGTH - 7)
                     match($0, /apply [0-9.]+/); apply = substr($0, RSTART + 6, RLENGTH - 6) }
        /cycle [1-9]/ && /component/ { match($0, /: [0-9]+ iterations/); v = substr($0, RSTART + 2, RLENGTH - 13) + 0; if (v > it) it = v }
        /PETSc\): components [0-9]: / { match($0, /: [0-9]+ iterations/); v = substr($0, RSTART + 2, RLENGTH - 13) + 0; if (v > it) it = v }
        /^Core:/ { core = $2 }
        END { printf "| %s | %s | %s | %.2f | %s | %s | %s | %s | %s |\n", s, rt, wall, cpu, create, apply, it, core, cmp }
    ' "$work/err.txt"
done
