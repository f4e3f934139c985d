#!/usr/bin/env bash
# irsig tests: formatting, lints, and the whole test suite (release build,
# shared with the set-up's build).
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v cargo >/dev/null 2>&1 && [ -x "$HOME/.cargo/bin/cargo" ]; then
  export PATH="$HOME/.cargo/bin:$PATH"
fi
cargo fmt --check
cargo clippy --release --locked --all-targets -- -D warnings
cargo test --release --locked
