#!/bin/sh
# Regenerates the Exodus II seeds of the fuzz driver (tests/fuzz/seeds.sh): mixed.exo (netCDF
# classic, double) and mixed_float.e (float) are the fixture of tests/mesh/test_exodus.c,
# written by SEACAS's library (Debian libexodusii-dev) through that test's --fixture mode:
# blocks HEX20, WEDGE15, HEX27, WEDGE6, TETRA4, two node sets, a side set, number maps.
# usage: make_fixtures.sh BUILD_DIR
set -eu
here=$(dirname "$0")
"$1/tests/mesh/test_exodus" --fixture "$here/mixed.exo" 8
"$1/tests/mesh/test_exodus" --fixture "$here/mixed_float.e" 4
