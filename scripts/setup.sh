#!/usr/bin/env bash
# irsig set-up: installs what a fresh Debian 12 (or newer) machine needs,
# builds irsig in release mode and renders the sample scene.
# Idempotent; run as root or as a user with sudo.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "$(id -u)" -eq 0 ]; then SUDO=""; else SUDO="sudo"; fi

# Debian packages: Embree (3 on Debian 12, 4 on Debian 13 / Ubuntu 24.04),
# libclang for bindgen, a C compiler for the shim; python3-venv for the
# Python package's virtual environment; libnetcdf for the merged batch stack
# (`irsig batch merge`); Slurm and munge for the batch runner's job arrays
# (scripts/slurm-test.sh starts a throw-away one-node cluster); gdal-bin
# (gdalinfo, gdal_translate, gdaltransform) for the tests that read the
# georeferenced outputs; chromium (headless) for the test that opens
# `irsig report`'s HTML page (tests/report.rs).
PKGS="libembree-dev libclang-dev clang pkg-config build-essential ca-certificates python3 python3-venv libnetcdf-dev slurm-wlm munge gdal-bin chromium"
missing=""
for p in $PKGS; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing="$missing $p"
done
if [ -n "$missing" ]; then
  echo "setup: installing$missing"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q $missing
fi

# Rust toolchain (edition 2024 and std file locks need Rust >= 1.89; Debian 12's rustc is too old).
if ! command -v cargo >/dev/null 2>&1 && [ -x "$HOME/.cargo/bin/cargo" ]; then
  export PATH="$HOME/.cargo/bin:$PATH"
fi
if ! command -v cargo >/dev/null 2>&1; then
  echo "setup: cargo not found; installing the stable toolchain with rustup"
  curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal -c rustfmt,clippy
  export PATH="$HOME/.cargo/bin:$PATH"
fi
ver=$(rustc --version | awk '{print $2}')
if [ "$(printf '%s\n1.89.0\n' "$ver" | sort -V | head -n1)" != "1.89.0" ]; then
  echo "setup: rustc $ver is older than 1.89 (edition 2024, std file locks): run 'rustup update stable'" >&2
  exit 1
fi

cargo build --release --locked

# The Python package: a project virtual environment (.venv) with the
# build backend, numpy/xarray/pandas and the test tools, then the package.
if [ ! -x .venv/bin/python ]; then
  python3 -m venv .venv
fi
.venv/bin/python -m pip install --quiet --upgrade pip
.venv/bin/python -m pip install --quiet -r python/requirements-dev.txt
bash scripts/python-install.sh

# A real render of the sample scene, to prove the whole chain works.
bash scripts/sample-render.sh
