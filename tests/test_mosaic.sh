#!/bin/bash
# Seamless tiles: the Kilauea sample cut into 4 tiles of unequal size (as
# files, and as a VRT of them) gives exactly the SVF of the whole file,
# with no seam: the tiles are mosaicked on their common grid before the
# sweep, so horizons cross tile edges as on the merged DEM.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
dem=${TOP_SRCDIR:-.}/samples/kilauea_summit_30m.tif
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-mosaic.XXXXXX")
trap 'rm -rf "$work"' EXIT

# 512 x 643 cut at column 200 and row 300: 200x300, 312x300, 200x343, 312x343.
gdal_translate -q -srcwin 0 0 200 300 "$dem" "$work/nw.tif"
gdal_translate -q -srcwin 200 0 312 300 "$dem" "$work/ne.tif"
gdal_translate -q -srcwin 0 300 200 343 "$dem" "$work/sw.tif"
gdal_translate -q -srcwin 200 300 312 343 "$dem" "$work/se.tif"
gdalbuildvrt -q "$work/tiles.vrt" "$work"/{nw,ne,sw,se}.tif

"$SKYSWEEP" svf -q --directions 16 "$dem" "$work/whole.tif"
tap_ok $? "svf of the whole DEM"
"$SKYSWEEP" svf -q --directions 16 "$work"/{se,nw,sw,ne}.tif "$work/tiles.tif"
tap_ok $? "svf of the 4 tiles given as files (in any order)"
"$SKYSWEEP" svf -q --directions 16 "$work/tiles.vrt" "$work/vrt.tif"
tap_ok $? "svf of the VRT of the tiles"

# Identical pixels: compare the raw bytes of the bands.
raw() { gdal_translate -q -of ENVI "$1" "$2" && cmp -s "$2" "$3"; }
gdal_translate -q -of ENVI "$work/whole.tif" "$work/whole.raw"
raw "$work/tiles.tif" "$work/tiles.raw" "$work/whole.raw"
tap_ok $? "4 tiles == the merged DEM, bit for bit"
raw "$work/vrt.tif" "$work/vrt.raw" "$work/whole.raw"
tap_ok $? "the VRT of the tiles == the merged DEM, bit for bit"
info=$(gdalinfo "$work/tiles.tif")
echo "$info" | grep -q 'Size is 512, 643' &&
    echo "$info" | grep -q "$(gdalinfo "$dem" | grep '^Origin')"
tap_ok $? "the mosaic's output has the merged DEM's size and origin"
tap_done
