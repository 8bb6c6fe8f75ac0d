#!/bin/sh
# A solar cadastre of Gothenburg's buildings in one command (doc/roofs.md):
# the 1 m DSM, its 137 building footprints, UMEP's canopy (trees by leaf
# season) and UMEP's typical year of hourly weather, from ../shared/data
# (see its README; not bundled here). Writes out/goteborg_roofs.gpkg, with
# the layers buildings, roof_planes and panels, and the planes as CSV; open
# the GeoPackage in QGIS. About 16 s on two cores (2026-12-07). Run it
# after samples/run.sh has built skysweep.
set -eu
cd "$(dirname "$0")/.."
data=../shared/data
if [ ! -r "$data/goteborg_kronenhuset_dsm_1m.tif" ]; then
    echo "samples/goteborg_roofs.sh: the Gothenburg data are not in $data" >&2
    exit 3
fi
mkdir -p out
# UMEP's met file states no zone: its stamps are local standard time, UTC+1.
# Shadows and crowns follow each cell's own ray (exact for the box model);
# 8 box lines a cell serve the sky view (p95 SVF error 0.0063,
# doc/box_lines.md).
./skysweep roofs --buildings "$data/goteborg_buildings/goteborg_kronenhuset_buildings.shp" \
    --weather "$data/weather/goteborg_tmy_1977_umep.txt" --weather-zone +01:00 \
    --canopy "$data/goteborg_kronenhuset_cdsm_1m.tif" --box-lines 8 --directions 32 \
    --panels --csv out/goteborg_roof_planes.csv \
    "$data/goteborg_kronenhuset_dsm_1m.tif" out/goteborg_roofs.gpkg
