#!/usr/bin/env bash
# The sample run of the set-up: a real render of the paper's demo scene
# (airfield, MWIR at 12:00 local), written to out/airfield-mwir.{exr,png,json}.
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p out
./target/release/irsig check scenes/airfield/scene.toml
./target/release/irsig render scenes/airfield/scene.toml -o out/airfield-mwir.exr --stats
