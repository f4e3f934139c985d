#!/usr/bin/env bash
# irsig tests: formatting, lints, the whole test suite (release build,
# shared with the set-up's build) and the Python package's tests.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v cargo >/dev/null 2>&1 && [ -x "$HOME/.cargo/bin/cargo" ]; then
  export PATH="$HOME/.cargo/bin:$PATH"
fi
cargo fmt --all --check
cargo clippy --release --locked --workspace --all-targets -- -D warnings
cargo test --release --locked
# The Python package (python/): rebuilt and reinstalled into .venv (no
# network), then its tests, which compare against the CLI built above.
bash scripts/python-install.sh
.venv/bin/python -m pytest -q python/tests
# The batch runner on a real (throw-away, one-node) Slurm cluster.
bash scripts/slurm-test.sh
