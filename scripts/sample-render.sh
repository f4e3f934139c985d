#!/usr/bin/env bash
# The sample run of the set-up: exercises the built binary on the sample
# geometry. (Extended to a full `irsig render` of scenes/airfield as the
# render lands.)
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p out
./target/release/irsig crosscheck scenes/meshes/mixed.obj --width 256 --height 256
