#!/usr/bin/env bash
# Builds the Python package (python/, PyO3 + maturin, an abi3 wheel) in
# release mode and installs it into the project's .venv. No network: the
# crates are those of Cargo.lock (already fetched by the cargo build) and
# pip installs the one wheel without dependencies (scripts/setup.sh has
# installed them).
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x .venv/bin/python ] || [ ! -x .venv/bin/maturin ]; then
  echo "python-install: no .venv with maturin: run scripts/setup.sh first" >&2
  exit 1
fi
rm -f target/wheels/irsig-*.whl
.venv/bin/maturin build --release --locked --quiet -i .venv/bin/python -m python/Cargo.toml
wheel=$(ls target/wheels/irsig-*.whl)
.venv/bin/python -m pip install --quiet --no-deps --no-index --force-reinstall "$wheel"
