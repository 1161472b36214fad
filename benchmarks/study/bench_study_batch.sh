#!/bin/sh
# Absolute studies in batches (`cadmorph study --batch K`, docs/DESIGN.md "Studies in
# batches"): a study of 20 variants against a study of one, with batches of several sizes.
#   bracket: `cadmorph model bracket 0` meshed by TetGen at --size 0.0528 --no-optimize (about
#            3.3M tets, 10^5 boundary nodes: the iterative RBF solver), variants
#            `cadmorph model bracket k/20`, k = 1..20; the study of the last variant alone,
#            then of all 20 with --batch 1, 5, 10, 20 (heavy: about 2.5 GB and 40 s per
#            variant one at a time on 2 cores).
#   bore:    `cadmorph model bore` meshed by TetGen at sizes 0.25 0.15 0.12 (as bench_study.sh),
#            the last variant alone and all 20 with --batch 1 and auto; with SOLVERS="auto dense
#            iterative" instead the last variant alone and all 20 (batch auto) with each
#            --solver, side by side (the solver AUTO took is in the table's solver column);
#            with TOLS="default 1e-6" the studies of each size once per warp tolerance
#            (--rbf-tol; default: none given), side by side (the bracket's too).
# One table row per study: wall and CPU seconds (/usr/bin/time), their ratios to the one-variant
# study, and from study.csv (seconds of wall time, per variant the median over the variants):
# the factorisation (t_volume_solve, once), the warp apply (t_evaluation: the iterative solve
# and the evaluation at the interior nodes, a batch's shared apply divided over its variants,
# plus the quality), the surface morph (t_surface) and the distance check (t_distance); from the
# study's --verbose log (log_TAG.txt), the warp's solves and evaluations at the interior nodes
# (wall s, every warp apply of the study summed, per variant).
# usage: bench_study_batch.sh BUILD_DIR WORK_DIR [THREADS] [bracket|bore|all]
# environment: BRACKET_MESH=M.vtu reuses a TetGen mesh of bracket 0 at that size (meshing it
# takes minutes); BATCHES="1 5 10 20" and NVAR=20 (the bracket's batch sizes and variants);
# SOLVERS and TOLS (bore, above); CADMORPH=path of the CLI; REPS=3 runs each study 3 times
# and keeps the fastest (its time, log and study.csv): noise on shared cores only adds time.
set -eu
usage="usage: bench_study_batch.sh BUILD_DIR WORK_DIR [THREADS] [bracket|bore|all]"
build=${1:?$usage}
work=${2:?$usage}
threads=${3:-2}
part=${4:-all}
case $part in bracket|bore|all) ;; *) echo "$usage" >&2; exit 1 ;; esac
cadmorph=${CADMORPH:-$build/cli/cadmorph}
nvar=${NVAR:-20}
reps=${REPS:-1}
mkdir -p "$work"

# G0 and the variants k/nvar of MODEL into DIR: vN/ all of them, v1/ the last alone
variants() { # MODEL DIR
    mkdir -p "$2/vN" "$2/v1"
    "$cadmorph" model "$1" 0 "$2/G0.step" >/dev/null
    for k in $(seq 1 "$nvar"); do
        "$cadmorph" model "$1" "$(awk -v k="$k" -v n="$nvar" 'BEGIN { print k / n }')" \
            "$2/vN/$1_$(printf %02d "$k").step" >/dev/null
    done
    cp "$2/vN/$1_$(printf %02d "$nvar").step" "$2/v1/"
}

# The wall seconds of a /usr/bin/time file
wall() { sed 's/.*wall_s=\([0-9.]*\).*/\1/' "$1"; }

# One study: DIR MESH LIST TAG BATCH [SOLVER [TOL]] (its debug log in DIR/log_TAG.txt)
study() {
    tolopt=
    [ "${7:-default}" = default ] || tolopt="--rbf-tol $7"
    for rep in $(seq "$reps"); do
        # shellcheck disable=SC2086
        /usr/bin/time -f "wall_s=%e user_s=%U sys_s=%S max_kb=%M" -o "$1/time_$4.try" \
            "$cadmorph" study --from "$1/G0.step" --mesh "$2" --variants "$3" -o "$1/out_$4.try" \
            --mode absolute --methods rbf-s --write-meshes none --batch "$5" \
            --solver "${6:-auto}" $tolopt --threads "$threads" --verbose >/dev/null \
            2>"$1/log_$4.try" || [ $? -eq 3 ]
        # the fastest run's
        if [ "$rep" -eq 1 ] || awk -v a="$(wall "$1/time_$4.try")" -v b="$(wall "$1/time_$4.txt")" \
            'BEGIN { exit !(a < b) }'; then
            mv "$1/time_$4.try" "$1/time_$4.txt"
            mv "$1/log_$4.try" "$1/log_$4.txt"
            rm -rf "$1/out_$4"
            mv "$1/out_$4.try" "$1/out_$4"
        fi
    done
    rm -rf "$1/time_$4.try" "$1/log_$4.try" "$1/out_$4.try"
}

# The table rows of DIR's studies TAG... (the first: the one-variant study)
table() {
    /usr/bin/python3 - "$@" <<'PY'
import csv, re, statistics, sys
work, label, tags = sys.argv[1], sys.argv[2], sys.argv[3:]
def times(tag):
    kv = dict(f.split("=") for f in open(f"{work}/time_{tag}.txt").read().split())
    return float(kv["wall_s"]), float(kv["user_s"]) + float(kv["sys_s"]), float(kv["max_kb"])
w1, c1, _ = times(tags[0])
for tag in tags:
    rows = list(csv.DictReader(open(f"{work}/out_{tag}/study.csv")))
    med = lambda k: statistics.median(float(r[k]) for r in rows)
    w, c, kb = times(tag)
    n, batch = tag.split("_")[:2]
    # the RBF solver the warp was created with (its debug line)
    solver = next((ln.split(", ")[1].split(" ")[0] for ln in open(f"{work}/log_{tag}.txt")
                   if ln.startswith("cm_warp_create: component 0:")), "?")
    applies = re.findall(r"solve ([0-9.]+) s \(.*evaluation at [0-9]+ nodes ([0-9.]+) s",
                         open(f"{work}/log_{tag}.txt").read())
    solve = sum(float(a) for a, _ in applies) / len(rows)
    ev = sum(float(b) for _, b in applies) / len(rows)
    print(f"| {label} | {solver} | {rows[0]['nodes']} | {rows[0]['boundary_nodes']} | {len(rows)} | {batch} "
          f"| {w:.1f} | {c:.1f} | {w / w1:.2f} | {c / c1:.2f} | {kb / 1048576:.1f} "
          f"| {sum(float(r['t_volume_solve']) for r in rows):.2f} | {med('t_evaluation'):.3f} "
          f"| {solve:.3f} | {ev:.3f} | {med('t_surface'):.3f} | {med('t_distance'):.3f} |")
PY
}

echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "BLAS: OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-unset}, threads $threads"
echo "| case | solver | nodes | boundary nodes | variants | batch | wall s | CPU s | wall ratio | CPU ratio | max GB | factorisation s | apply s/variant | solve s/variant | evaluation s/variant | surface s/variant | distance s/variant |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"

if [ "$part" = bracket ] || [ "$part" = all ]; then
    d=$work/bracket
    variants bracket "$d"
    mesh=${BRACKET_MESH:-$d/M0_0.0528.vtu}
    [ -e "$mesh" ] || "$cadmorph" mesh "$d/G0.step" -o "$mesh" --size 0.0528 --mesher tetgen \
        --no-optimize >/dev/null
    for tol in ${TOLS:-default}; do
        study "$d" "$mesh" "$d/v1/*.step" "1_1_$tol" 1 auto "$tol"
        tags=1_1_$tol
        for b in ${BATCHES:-1 5 10 20}; do
            study "$d" "$mesh" "$d/vN/*.step" "${nvar}_${b}_$tol" "$b" auto "$tol"
            tags="$tags ${nvar}_${b}_$tol"
        done
        # shellcheck disable=SC2086
        table "$d" "bracket 0.0528, --rbf-tol $tol" $tags
    done
fi

if [ "$part" = bore ] || [ "$part" = all ]; then
    d=$work/bore
    variants bore "$d"
    for size in 0.25 0.15 0.12; do
        mesh=$d/M0_$size.vtu
        [ -e "$mesh" ] || "$cadmorph" mesh "$d/G0.step" -o "$mesh" --size "$size" \
            --mesher tetgen >/dev/null
        if [ -z "${SOLVERS:-}" ]; then
            for tol in ${TOLS:-default}; do
                study "$d" "$mesh" "$d/v1/*.step" "1_1_$tol" 1 auto "$tol"
                study "$d" "$mesh" "$d/vN/*.step" "${nvar}_1_$tol" 1 auto "$tol"
                study "$d" "$mesh" "$d/vN/*.step" "${nvar}_auto_$tol" auto auto "$tol"
                table "$d" "bore $size, --rbf-tol $tol" "1_1_$tol" "${nvar}_1_$tol" \
                    "${nvar}_auto_$tol"
            done
            continue
        fi
        for sv in $SOLVERS; do
            study "$d" "$mesh" "$d/v1/*.step" "1_1_$sv" 1 "$sv"
            study "$d" "$mesh" "$d/vN/*.step" "${nvar}_auto_$sv" auto "$sv"
            table "$d" "bore $size, --solver $sv" "1_1_$sv" "${nvar}_auto_$sv"
        done
    done
fi
