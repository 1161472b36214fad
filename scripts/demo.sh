#!/bin/sh
# The README's demo until `cadmorph demo` exists (issue 6): the bore benchmark model at t = 0
# and t = 1 written as STEP, their correspondence checked, a tet mesh of G(0) by OpenCASCADE +
# TetGen, and the morph of that mesh onto G(1) with its quality.
# usage: scripts/demo.sh [BUILD_DIR]   (outputs in BUILD_DIR/demo)
set -eu
build=${1:-build}
out=$build/demo
cadmorph=$build/cli/cadmorph
mkdir -p "$out"
"$build/benchmarks/models/cm_model" bore 0 "$out/bore_0.step"
"$build/benchmarks/models/cm_model" bore 1 "$out/bore_1.step"
echo "== G(0) and G(1): bore radius 0.6 -> 1.0, axis tilted 0 -> 25 degrees"
"$cadmorph" info "$out/bore_0.step" --compare "$out/bore_1.step" | tail -n 1
echo "== tet mesh of G(0)"
"$cadmorph" mesh "$out/bore_0.step" -o "$out/bore_0.vtu" --size 0.2
echo "== morph onto G(1)"
"$cadmorph" morph --from "$out/bore_0.step" --to "$out/bore_1.step" --mesh "$out/bore_0.vtu" \
  -o "$out/bore_1.vtu" --report "$out/morph_report.csv"
echo
echo "Written to $out: bore_0.vtu (mesh of G(0)) and bore_1.vtu (morphed onto G(1)) with per-cell"
echo "scaled_jacobian and per-node displacement for ParaView; morph_report.csv (stage times)."
