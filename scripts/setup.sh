#!/usr/bin/env bash
# Installs, by Debian package name, everything cadmorph needs to build, test and benchmark.
# Idempotent: packages already installed are skipped, and apt-get runs only when needed.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git ca-certificates
  libocct-foundation-dev libocct-modeling-data-dev libocct-modeling-algorithms-dev
  libocct-data-exchange-dev libocct-ocaf-dev
  libflann-dev libtet1.5-dev liblapacke-dev libopenblas-dev zlib1g-dev libsuitesparse-dev
  gmsh libgmsh-dev python3-gmsh python3-numpy python3-scipy python3-vtk9 python3-meshio
  python3-cffi python3-pytest  # the Python package (python/cadmorph) and its tests
  python3-pip python3-venv python3-setuptools  # `pip install ./python` into a venv (install test)
  openfoam  # blockMesh, snappyHexMesh, checkMesh: polyMesh test meshes and the checkMesh cross-check
  openfoam-examples  # OpenFOAM's own tutorial cases, morphed by benchmarks/cfd/tutorials.py
  python3-matplotlib  # examples/python (plots); imported by PyGeM (make_pygem_fixture.py)
  clang libclang-rt-14-dev  # make fuzz (libFuzzer); make check-asan uses gcc's sanitizers
  libcgns-dev  # CGNS meshes (mesh/io/cgns_read.c, cgns_write.c), ADF and HDF5
  cgns-convert calculix-ccx python3-h5py  # cross-checks: cgnscheck, ccx runs a morphed .inp, h5py reads CGNS trees
  # Exodus II meshes (mesh/io/exodus.c), and netCDF4 for its cross-check. Its library links the
  # MPI build of netCDF; the OpenMPI and HDF5-OpenMPI it needs already come with libflann-dev,
  # python3-vtk9 and openfoam above, so it adds no MPI (14 packages: netCDF, serial HDF5 dev)
  libexodusii-dev python3-netcdf4
)
# Optional, needed only for -DCADMORPH_WITH_PETSC=ON (the distributed solver, --solver petsc):
# CADMORPH_WITH_PETSC=1 bash scripts/setup.sh. Not in the default list: with OpenMPI, hypre,
# MUMPS, Trilinos, ScaLAPACK and gfortran it is ~340 packages for one optional solver.
if [ "${CADMORPH_WITH_PETSC:-0}" = 1 ]; then packages+=(libpetsc-real-dev openmpi-bin); fi
# Optional, only to regenerate tests/data/freecad/ and run benchmarks/freecad/ (FreeCAD 0.20
# parts; benchmarks/RESULTS.md, FreeCAD-made parts): CADMORPH_WITH_FREECAD=1 bash
# scripts/setup.sh. Not in the default list: a GUI application (Qt, Coin, PySide2: 43 packages
# on top of this list) for a fixture generator.
if [ "${CADMORPH_WITH_FREECAD:-0}" = 1 ]; then packages+=(freecad); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: run as root or install sudo" >&2; exit 1; }
  sudo=sudo
fi
echo "setup: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
