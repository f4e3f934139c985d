#!/bin/sh
# Small GeoTIFF DEMs written by GDAL (gdal_translate, from gdal-bin) for the
# DEM reader's fuzz seeds (tests/fuzz) and tests: tests/data/dem/*.tif.
# Heights are a smooth synthetic field; run from the repository root:
#   sh tools/ref_dem.sh
set -eu
out=tests/data/dem
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# asc NAME COLS ROWS XLL YLL CELL: an ESRI ASCII grid of 150 + 20 sin(i/5) cos(j/7)
# with two no-data (-9999) pixels
asc() {
    python3 - "$@" > "$tmp/$1.asc" <<'PY'
import math, sys
name, cols, rows, xll, yll, cell = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4], sys.argv[5], sys.argv[6]
print(f"ncols {cols}\nnrows {rows}\nxllcorner {xll}\nyllcorner {yll}\ncellsize {cell}\nNODATA_value -9999")
for j in range(rows):
    row = []
    for i in range(cols):
        v = -9999 if (i, j) in ((3, 2), (cols - 1, rows - 1)) else 150 + 20 * math.sin(i / 5) * math.cos(j / 7)
        row.append(f"{v:.2f}")
    print(" ".join(row))
PY
}
asc geo 32 24 -77.62 43.16 0.0002777777777778
gdal_translate -q -a_srs EPSG:4326 -ot Int16 -co COMPRESS=DEFLATE -co PREDICTOR=2 \
    -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 -mo AREA_OR_POINT=Point \
    "$tmp/geo.asc" "$out/geo-i16-point.tif"
asc utm 24 20 287000 4781000 30
gdal_translate -q -a_srs EPSG:32618 -ot Float32 -co COMPRESS=LZW -co PREDICTOR=3 \
    -co BLOCKYSIZE=5 "$tmp/utm.asc" "$out/utm18n-f32-lzw.tif"
