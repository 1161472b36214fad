#!/bin/sh
# Under an address-space limit (ulimit -v) cadmorph must finish in bounded
# time with a clean exit code: 0, or 4 with one "out of memory" line. Before the fix
# `cadmorph --version` printed and then hung at exit joining an OpenBLAS worker that spun in
# its buffer allocation, and `warp` spun in that allocation itself.
# usage: ulimit.sh CADMORPH MESH DISPLACEMENTS WORKDIR
set -u
exe=$1 mesh=$2 disp=$3 work=$4
# ASan reserves terabytes of address space: nothing to learn under ulimit -v there
if ldd "$exe" 2>/dev/null | grep -q libasan; then echo "skip: ASan build"; exit 77; fi
# a PETSc build (-DCADMORPH_WITH_PETSC=ON) loads ~340 libraries (MPI, hypre, MUMPS, ...): they
# alone need more address space than the limits below, so the program cannot even start
if ldd "$exe" 2>/dev/null | grep -q libpetsc; then echo "skip: PETSc build"; exit 77; fi
fail=0
# run LIMIT_KB EXPECT(0|4|0or4) ARGS...: within 30 s, the expected code, stderr as expected
run() {
    limit=$1 expect=$2
    shift 2
    start=$(date +%s)
    ( ulimit -v "$limit" && exec timeout 30 "$exe" "$@" ) >"$work/ulimit.out" 2>"$work/ulimit.err"
    rc=$?
    took=$(( $(date +%s) - start ))
    echo "ulimit -v $limit: cadmorph $* -> exit $rc in ${took}s"
    sed 's/^/  stderr: /' "$work/ulimit.err"
    if [ "$rc" -eq 124 ]; then echo "FAIL: did not exit within 30 s"; fail=1; return; fi
    case "$expect:$rc" in
        0:0 | 4:4 | 0or4:0 | 0or4:4) ;;
        *) echo "FAIL: exit $rc, expected $expect"; fail=1; return ;;
    esac
    if [ "$rc" -eq 4 ]; then
        if [ "$(grep -c . "$work/ulimit.err")" -ne 1 ] || ! grep -q 'out of memory' "$work/ulimit.err"; then
            echo "FAIL: exit 4 needs one stderr line saying out of memory"; fail=1
        fi
    fi
}
for kb in 150000 200000 250000 300000 400000; do
    run $kb 0 --version
    # a count the user set (OpenBLAS would start its workers at load)
    OPENBLAS_NUM_THREADS=2 run $kb 0 --version
done
grep -q '^BLAS core: ' "$work/ulimit.out" || { echo "FAIL: no BLAS core line"; fail=1; }
# the small warp (1,551 constrained nodes): fails cleanly where OpenBLAS's buffer cannot fit,
# works where it can; 2 threads asked for, fewer given when only one buffer fits
run 150000 4 warp --mesh "$mesh" --displacements "$disp" -o "$work/ulimit_150.vtu" --threads 2
run 250000 0or4 warp --mesh "$mesh" --displacements "$disp" -o "$work/ulimit_250.vtu" --threads 2
run 400000 0 warp --mesh "$mesh" --displacements "$disp" -o "$work/ulimit_400.vtu" --threads 2
run 800000 0 warp --mesh "$mesh" --displacements "$disp" -o "$work/ulimit_800.vtu" --threads 2
# the most threads --threads accepts: libgomp aborted (exit 1, its own message) when it could
# not create their stacks; now the count is capped to the address space
most=$((4 * $(nproc)))
for kb in 270000 280000 300000 350000; do
    run $kb 0or4 warp --mesh "$mesh" --displacements "$disp" -o "$work/ulimit_t.vtu" --threads $most
done
[ -f "$work/ulimit_150.vtu" ] && { echo "FAIL: a failed warp left its output"; fail=1; }
exit $fail
