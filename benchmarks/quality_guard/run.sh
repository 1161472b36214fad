#!/bin/sh
# Adaptive steps and interior optimisation, side by side in one run.
#   sh benchmarks/quality_guard/run.sh BUILD OUT_DIR
# 1. bracket tet mesh (TetGen as before: --min-dihedral 0 --no-optimize), G(0) -> G(1): plain / --steps auto /
#    --optimize / both, absolute and relative (--relative --via G(0.1) .. G(0.9));
# 2. bore, pipe, bracket tets: min scaled Jacobian at 100 % with and without --optimize for
#    rbf-s (rbf surface + triharmonic), project (closest point + triharmonic), biharmonic;
# 3. cadmorph mesh with and without optimisation on the three models and two parts written
#    by gmsh's OpenCASCADE kernel (make_parts.py): min / 1st percentile and time.
# Prints one CSV table per block on stdout; user+sys CPU seconds from /usr/bin/time.
set -eu
B=$1
O=$2
mkdir -p "$O"
C=$B/cli/cadmorph
here=$(dirname "$0")
# run OUT cmd...: the command's stdout into OUT; prints "wall,cpu" seconds
run() { out=$1; shift; /usr/bin/time -f "%e %U %S" -o "$O/time" "$@" > "$out" 2> "$out.err" || true
        tail -1 "$O/time" | awk '{printf "%.2f,%.2f", $1, $2 + $3}'; }
summary() { tail -1 "$1" | sed 's/min_scaled_jacobian=\([^ ]*\) mean_scaled_jacobian=[^ ]* inverted=\([^ ]*\) cells=.*/\1,\2/'; }

for m in bore pipe bracket; do
  for t in 0 0.1 0.2 0.3 0.4 0.5 0.6 0.7 0.8 0.9 1; do $C model $m $t "$O/${m}_$t.step" > /dev/null; done
done
via() { echo "$O/$1_0.1.step,$O/$1_0.2.step,$O/$1_0.3.step,$O/$1_0.4.step,$O/$1_0.5.step,$O/$1_0.6.step,$O/$1_0.7.step,$O/$1_0.8.step,$O/$1_0.9.step"; }

echo "# block 1: bracket tet, G(0) -> G(1)"
echo "mode,variant,min_sj,inverted,no_valid_step,steps_accepted,steps_tried,wall_s,cpu_s"
$C mesh "$O/bracket_0.step" -o "$O/bracket_0.vtu" --size 0.2 --min-dihedral 0 --no-optimize > /dev/null
for mode in absolute relative; do
  extra=""
  [ $mode = relative ] && extra="--relative --via $(via bracket)"
  for v in plain auto optimize both; do
    # plain and optimize: one step, its inverted cells kept as measured (--allow-inverted)
    flags="--steps 1 --allow-inverted"
    case $v in auto) flags="--steps auto";; optimize) flags="--steps 1 --allow-inverted --optimize";; both) flags="--steps auto --optimize";; esac
    keep=""
    case $v in auto|both) keep="--keep-partial";; esac
    t=$(run "$O/b1_${mode}_$v.out" $C morph --from "$O/bracket_0.step" --to "$O/bracket_1.step" \
        --mesh "$O/bracket_0.vtu" -o "$O/b1_${mode}_$v.vtu" --report "$O/b1_${mode}_$v.csv" \
        $flags $extra $keep)
    acc=$(awk -F, 'NR > 1 && $14 == 1' "$O/b1_${mode}_$v.csv" | wc -l)
    tried=$(($(wc -l < "$O/b1_${mode}_$v.csv") - 1))
    rejected=$(grep -c "no valid step" "$O/b1_${mode}_$v.out.err" || true)
    echo "$mode,$v,$(summary "$O/b1_${mode}_$v.out"),$rejected,$acc,$tried,$t"
  done
done

echo "# block 2: min scaled Jacobian at 100 % (absolute), with and without --optimize"
echo "model,method,min_sj,inverted,min_sj_optimized,inverted_optimized,cpu_s,cpu_s_optimized"
for m in bore pipe bracket; do
  [ -f "$O/${m}_0.vtu" ] || $C mesh "$O/${m}_0.step" -o "$O/${m}_0.vtu" --size 0.2 --min-dihedral 0 --no-optimize > /dev/null
  for meth in rbf-s project biharmonic; do
    case $meth in rbf-s) f="";; project) f="--surface project";; biharmonic) f="--method rbf-biharmonic";; esac
    f="$f --steps 1 --allow-inverted"  # the one-step morph, its inverted cells measured
    t0=$(run "$O/q.out" $C morph --from "$O/${m}_0.step" --to "$O/${m}_1.step" --mesh "$O/${m}_0.vtu" -o "$O/q.vtu" $f)
    t1=$(run "$O/qo.out" $C morph --from "$O/${m}_0.step" --to "$O/${m}_1.step" --mesh "$O/${m}_0.vtu" -o "$O/q.vtu" $f --optimize)
    echo "$m,$meth,$(summary "$O/q.out"),$(summary "$O/qo.out"),${t0#*,},${t1#*,}"
  done
done

echo "# block 3: cadmorph mesh with and without interior optimisation"
echo "# (TetGen as before: --min-dihedral 0 --no-optimize; the default now: dihedral bound 12 degrees + optimisation)"
echo "part,cells,min_sj,p01_sj,cells_default,min_sj_default,p01_sj_default,cpu_s,cpu_s_default"
/usr/bin/python3 "$here/make_parts.py" "$O" > /dev/null 2>&1
for p in bore_0 pipe_0 bracket_0 gmsh_flange gmsh_bracket; do
  t0=$(run "$O/m.out" $C mesh "$O/$p.step" -o "$O/m.vtu" --min-dihedral 0 --no-optimize)
  t1=$(run "$O/mo.out" $C mesh "$O/$p.step" -o "$O/m.vtu" --mesher tetgen)
  r0=$(grep '^tet4' "$O/m.out" | awk '{print $2","$3","$5}')
  r1=$(grep '^tet4' "$O/mo.out" | awk '{print $2","$3","$5}')
  echo "$p,$r0,$r1,${t0#*,},${t1#*,}"
done
