#!/bin/sh
# An absolute `cadmorph study` on one rank and over 2 ranks (mpirun, -DCADMORPH_WITH_PETSC=ON
# builds), one after the other: wall and CPU seconds (user + sys of all ranks), and whether
# the rows agree (tests/study/same_study.py). usage: bench_study_mpi.sh BUILD G0.step MESH
# 'VARIANTS_GLOB' [WORK]
set -eu
build=$1 g0=$2 mesh=$3 variants=$4 work=${5:-$1/bench/study_mpi}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
echo "# $(date -u '+%Y-%m-%d %H:%M UTC')  nproc=$(nproc)  load=$(cut -d' ' -f1-3 /proc/loadavg)  OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:--}"
echo "| ranks x threads | wall s | CPU s | rows agree |"
echo "|---|---|---|---|"
for run in "1 2" "2 1"; do
    set -- $run
    launch=""
    [ "$1" -gt 1 ] && launch="mpirun -n $1 --oversubscribe"
    /usr/bin/time -f "%e %U %S" -o "$work/time.txt" $launch "$build/cli/cadmorph" study --from "$g0" \
        --mesh "$mesh" --variants "$variants" -o "$work/r$1" --mode absolute --methods rbf-s \
        --threads "$2" >"$work/out_r$1.txt" 2>&1
    same=-
    [ "$1" -gt 1 ] && same=$(/usr/bin/python3 "$here/../../tests/study/same_study.py" "$work/r1/study.csv" "$work/r$1/study.csv" 1e-9 2>&1 || true)
    read wall user sys < "$work/time.txt"
    echo "| $1 x $2 | $wall | $(echo "$user + $sys" | bc) | $same |"
done
