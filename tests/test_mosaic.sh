#!/bin/bash
# Seamless tiles and windows: the Kilauea sample cut into 4 tiles of
# unequal size (as files, and as a VRT of them) gives exactly the SVF of
# the whole file, with no seam: the tiles are mosaicked on their common
# grid before the sweep, so horizons cross tile edges as on the merged
# DEM. Each tile keeps its own data type and nodata; tiles that overlap
# must agree there, unless --overlap decides. -projwin writes one window of the outputs, equal to the same window
# cut from the full output (horizons still come from the whole DEM).
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

# A window of 200 x 120 cells from the tiles (GDAL's -projwin words, and
# the joined form), against gdal_translate's cut of the full output.
win="259125 2144655 265125 2141055"
"$SKYSWEEP" svf -q --directions 16 -projwin $win "$work"/{nw,ne,sw,se}.tif "$work/win.tif"
tap_ok $? "svf -projwin $win over the tiles"
gdal_translate -q -projwin $win "$work/whole.tif" "$work/cut.tif"
gdal_translate -q -of ENVI "$work/cut.tif" "$work/cut.raw"
raw "$work/win.tif" "$work/win.raw" "$work/cut.raw"
tap_ok $? "the window == the same window cut from the full output, bit for bit"
gdalinfo "$work/win.tif" | grep -q 'Size is 200, 120' &&
    gdalinfo "$work/win.tif" | grep -q 'Origin = (259125.000000000000000,2144655.000000000000000)'
tap_ok $? "the window's size and origin are gdal_translate's"
"$SKYSWEEP" hillshade -q --projwin 259125,2144655,265125,2141055 "$dem" "$work/hs_win.tif" &&
    "$SKYSWEEP" hillshade -q "$dem" "$work/hs.tif" &&
    gdal_translate -q -projwin $win "$work/hs.tif" "$work/hs_cut.tif" &&
    gdal_translate -q -of ENVI "$work/hs_cut.tif" "$work/hs_cut.raw" &&
    raw "$work/hs_win.tif" "$work/hs_win.raw" "$work/hs_cut.raw"
tap_ok $? "hillshade (Byte) with the joined -projwin form == its cut"
"$SKYSWEEP" svf -q -projwin 0 0 1 1 "$dem" "$work/bad.tif" 2>"$work/err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && [ ! -e "$work/bad.tif" ]
tap_ok $? "a window outside the DEM: exit $rc, $(head -c 100 "$work/err")"
# Each tile as it is: a Float32 tile beside an Int16 one gives the whole
# mosaic (not the first tile alone); a first tile without a nodata value
# leaves a later tile's nodata nodata (not -32768 m pits).
gdal_translate -q -srcwin 0 0 512 300 "$dem" "$work/north.tif"
gdal_translate -q -srcwin 0 300 512 343 "$dem" "$work/south.tif"
gdal_translate -q -ot Float32 "$work/north.tif" "$work/north_f32.tif"
"$SKYSWEEP" svf -q --directions 16 "$work/north_f32.tif" "$work/south.tif" "$work/mixed.tif" &&
    raw "$work/mixed.tif" "$work/mixed.raw" "$work/whole.raw"
tap_ok $? "a Float32 tile beside an Int16 tile == the merged DEM, bit for bit ($(gdalinfo "$work/mixed.tif" 2>/dev/null | grep 'Size is'))"
gdal_translate -q -a_nodata none "$work/north.tif" "$work/north_plain.tif"
"$SKYSWEEP" svf -q --directions 16 "$work/north_plain.tif" "$work/south.tif" "$work/nd.tif" &&
    raw "$work/nd.tif" "$work/nd.raw" "$work/whole.raw"
tap_ok $? "a first tile without nodata: the later tile's nodata stays nodata (== the merged DEM, bit for bit)"

# Overlaps: the north tile reaching 20 rows into the south one. Equal
# heights there are one mosaic; 5 m higher in the south tile (its offset)
# is refused, naming both and the cells, unless --overlap decides.
gdal_translate -q -srcwin 0 0 512 320 "$dem" "$work/north_long.tif"
gdal_translate -q -srcwin 0 0 512 300 "$dem" "$work/north_cut.tif"
gdal_translate -q -a_offset 5 "$work/south.tif" "$work/south_up.tif"
gdal_translate -q -a_offset 5 -srcwin 0 320 512 323 "$dem" "$work/south_up_cut.tif"
shared=$((512 * 20)) # the overlap's rows have no nodata
"$SKYSWEEP" svf -q --directions 16 "$work/north_long.tif" "$work/south.tif" "$work/agree.tif" &&
    raw "$work/agree.tif" "$work/agree.raw" "$work/whole.raw"
tap_ok $? "tiles that agree where they overlap == the merged DEM, bit for bit"
"$SKYSWEEP" svf -q --directions 16 "$work/north_long.tif" "$work/south_up.tif" "$work/bad.tif" \
    2>"$work/err"
rc=$?
[ "$rc" -eq 3 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && [ ! -e "$work/bad.tif" ] &&
    grep -q "north_long.tif' and '.*south_up.tif' overlap and disagree on $shared of the $shared cells" "$work/err"
tap_ok $? "tiles that disagree by 5 m on $shared cells: exit $rc, $(head -c 300 "$work/err")"
"$SKYSWEEP" svf --directions 16 --overlap first "$work/north_long.tif" "$work/south_up.tif" \
    "$work/first.tif" >"$work/out" &&
    "$SKYSWEEP" svf -q --directions 16 "$work/north_long.tif" "$work/south_up_cut.tif" \
        "$work/first_ref.tif" &&
    gdal_translate -q -of ENVI "$work/first_ref.tif" "$work/first_ref.raw" &&
    raw "$work/first.tif" "$work/first.raw" "$work/first_ref.raw" &&
    grep -q "^overlap $shared cells where tiles disagree took the first tile's height" "$work/out"
tap_ok $? "--overlap first: the north tile's heights, said in the summary: $(grep '^overlap' "$work/out")"
"$SKYSWEEP" svf -q --directions 16 --overlap last "$work/north_long.tif" "$work/south_up.tif" \
    "$work/last.tif" &&
    "$SKYSWEEP" svf -q --directions 16 "$work/north_cut.tif" "$work/south_up.tif" \
        "$work/last_ref.tif" &&
    gdal_translate -q -of ENVI "$work/last_ref.tif" "$work/last_ref.raw" &&
    raw "$work/last.tif" "$work/last.raw" "$work/last_ref.raw"
tap_ok $? "--overlap last: the south tile's heights"
"$SKYSWEEP" svf --directions 16 --overlap mean "$work/north_long.tif" "$work/south_up.tif" \
    "$work/mean.tif" >"$work/out" &&
    grep -q "^overlap $shared cells where tiles disagree took the tiles' mean" "$work/out" &&
    ! cmp -s "$work/mean.tif" "$work/first.tif" && ! cmp -s "$work/mean.tif" "$work/last.tif"
tap_ok $? "--overlap mean: neither tile's heights, said in the summary"
tap_done
