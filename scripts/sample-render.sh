#!/usr/bin/env bash
# The sample run of the set-up: a real render of the paper's demo scene
# (airfield, MWIR at 12:00 local), written to out/airfield-mwir.{exr,png,json}
# with the georeferenced GeoTIFF beside it (out/airfield-mwir.tif and its
# float64 geolocation out/airfield-mwir_geo.tif).
set -euo pipefail
cd "$(dirname "$0")/.."
mkdir -p out
./target/release/irsig check scenes/airfield/scene.toml
./target/release/irsig render scenes/airfield/scene.toml -o out/airfield-mwir.exr --geotiff --stats
