#!/bin/bash
# Output formats (-of): each format doc/cli.md names either holds the
# product's values, nodata and bands (read back by GDAL equal to the GTiff
# output's, value for value) or is refused before any work with one line
# that names formats that can, exit 2 and nothing left in the folder.
# Three products cover the kinds of output: svf (one Float32 band), horizon
# (four Float32 bands) and hillshade (one Byte band, nodata 0).
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-formats.XXXXXX")
trap 'rm -rf "$work"' EXIT
dem=$work/dem.tif
# A corner of the sample: the volcano's flank and the ocean's nodata.
gdal_translate -q -ot Float32 -srcwin 180 530 48 40 \
    "${TOP_SRCDIR:-.}/samples/kilauea_summit_30m.tif" "$dem"

# raw FILE OUT: the raster's values as raw bytes (ENVI), for cmp.
raw() { gdal_translate -q -of ENVI -co INTERLEAVE=BSQ "$1" "$2" >/dev/null 2>&1; }

# check PRODUCT_ARGS FORMAT EXT EXPECT(written|refused)
check() {
    local args=$1 format=$2 ext=$3 expect=$4
    rm -rf "$work/out" && mkdir -p "$work/out"
    # shellcheck disable=SC2086
    "$SKYSWEEP" $args -q -of GTiff "$dem" "$work/ref.tif" 2>/dev/null
    # shellcheck disable=SC2086
    "$SKYSWEEP" $args -q -of "$format" "$dem" "$work/out/out$ext" >"$work/stdout" 2>"$work/stderr"
    local rc=$? lines left
    lines=$(wc -l <"$work/stderr")
    left=$(ls -A "$work/out" | grep -c '^\.')
    if [ "$expect" = written ]; then
        raw "$work/ref.tif" "$work/ref.raw" && raw "$work/out/out$ext" "$work/out.raw" &&
            cmp -s "$work/ref.raw" "$work/out.raw"
        local same=$?
        nodata=$(gdalinfo "$work/out/out$ext" 2>/dev/null | grep -c 'NoData Value=')
        [ "$rc" -eq 0 ] && [ "$same" -eq 0 ] && [ "$left" -eq 0 ] && [ "$nodata" -ge 1 ]
        tap_ok $? "${args%% *} -of $format: written, exit $rc, values equal the GTiff's ($same), nodata kept ($nodata), $left temporaries left: $(head -c 200 "$work/stderr")"
    else
        [ "$rc" -eq 2 ] && [ "$lines" -eq 1 ] && [ -z "$(ls -A "$work/out")" ] &&
            grep -q -- '-of GTiff' "$work/stderr"
        tap_ok $? "${args%% *} -of $format: refused, exit $rc (want 2), $lines line(s), nothing left: $(head -c 200 "$work/stderr")"
    fi
}

svf="svf --directions 8 --device reference"
horizon="horizon --directions 4 --device reference"
hillshade="hillshade"
# Float32 with nodata, any band count.
for f in "GTiff .tif" "COG .tif" "HFA .img" "ENVI .bin" "EHdr .bil" "PCIDSK .pix"; do
    set -- $f
    check "$svf" "$1" "$2" written
    check "$horizon" "$1" "$2" written
done
# One band only (netCDF writes more bands as separate variables, which GDAL
# reads back as subdatasets): the SVF fits, four horizon bands do not.
for f in "AAIGrid .asc" "netCDF .nc" "SAGA .sdat" "RST .rst"; do
    set -- $f
    check "$svf" "$1" "$2" written
    check "$horizon" "$1" "$2" refused
done
# No Float32, no nodata, or nothing on disk.
for f in "PNG .png" "JPEG .jpg" "GIF .gif" "BMP .bmp" "XYZ .xyz" "VRT .vrt" "MEM .mem" \
    "GS7BG .grd"; do
    set -- $f
    check "$svf" "$1" "$2" refused
done
# GPKG holds one Float32 band (a probe without georeferencing once refused it
# for "missing call to SetGeoTransform"), not four, and a Byte band it makes
# reads back as four (RGBA).
check "$svf" GPKG .gpkg written
check "$horizon" GPKG .gpkg refused
check "$hillshade" GPKG .gpkg refused
# Bytes: PNG holds a hillshade (nodata 0 as its transparent value); JPEG
# is lossy and GIF has no nodata of its own.
check "$hillshade" GTiff .tif written
check "$hillshade" PNG .png written
check "$hillshade" JPEG .jpg refused
# Side-car formats need an extension to name their side-cars after.
rm -rf "$work/out" && mkdir -p "$work/out"
"$SKYSWEEP" $svf -q -of ENVI "$dem" "$work/out/noext" 2>"$work/stderr"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$work/stderr")" -eq 1 ] && [ -z "$(ls -A "$work/out")" ] &&
    grep -q 'extension' "$work/stderr"
tap_ok $? "ENVI to a name without an extension: refused, exit $rc: $(head -c 200 "$work/stderr")"
# A folder's other files are not the output's: GDAL lists any NAME.txt
# beside a GeoTIFF among its files (as satellite metadata), and a rename or
# clean-up of GDAL's file set would move or delete it.
for format in "GTiff .tif" "ENVI .env"; do
    set -- $format
    rm -rf "$work/out" && mkdir -p "$work/out" && echo "the user's notes" >"$work/out/notes.txt"
    "$SKYSWEEP" $svf -q -of "$1" "$dem" "$work/out/svf$2" 2>"$work/stderr"
    rc=$?
    [ "$rc" -eq 0 ] && [ "$(cat "$work/out/notes.txt")" = "the user's notes" ] &&
        [ -z "$(ls -A "$work/out" | grep -v -e "^notes.txt$" -e "^svf")" ]
    tap_ok $? "-of $1 beside notes.txt: exit $rc, notes.txt kept, nothing else left: $(ls -A "$work/out" | tr '\n' ' ') $(head -c 200 "$work/stderr")"
done
# A hidden name without an extension (.hs) is a name, not an extension.
rm -rf "$work/out" && mkdir -p "$work/out"
"$SKYSWEEP" $svf -q "$dem" "$work/out/.hs" 2>"$work/stderr"
rc=$?
[ "$rc" -eq 0 ] && [ "$(ls -A "$work/out")" = .hs ] && gdalinfo "$work/out/.hs" >/dev/null 2>&1
tap_ok $? "an output named .hs is written as .hs: exit $rc, $(ls -A "$work/out" | tr '\n' ' ')"
# -co TFW=YES: the world file lands beside the output, named after it (it
# was once written beside the temporary and removed with it); an output
# without an extension has no name to give it, and is refused.
rm -rf "$work/out" && mkdir -p "$work/out"
"$SKYSWEEP" $svf -q -co TFW=YES "$dem" "$work/out/svf.tif" 2>"$work/stderr"
rc=$?
origin_x=$(sed -n 5p "$work/out/svf.tfw" 2>/dev/null)
want_x=$(gdalinfo "$work/out/svf.tif" | sed -n 's/^Origin = (\([0-9.]*\),.*/\1/p')
[ "$rc" -eq 0 ] && [ "$(ls -A "$work/out" | tr '\n' ' ')" = "svf.tfw svf.tif " ] &&
    awk -v a="$origin_x" -v b="$want_x" 'BEGIN { exit !(a - b == 15) }'
tap_ok $? "-co TFW=YES: exit $rc, $(ls -A "$work/out" | tr '\n' ' '), the world file's first cell centre $origin_x = origin $want_x + 15: $(head -c 200 "$work/stderr")"
rm -rf "$work/out" && mkdir -p "$work/out"
"$SKYSWEEP" $svf -q -co TFW=YES "$dem" "$work/out/svf" 2>"$work/stderr"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$work/stderr")" -eq 1 ] && [ -z "$(ls -A "$work/out")" ]
tap_ok $? "-co TFW=YES to a name without an extension: refused, exit $rc, nothing left: $(head -c 200 "$work/stderr")"
# A creation option's value GDAL refuses only once the defaults join it
# (tiles 7 wide, TILED=YES): exit 2 with GDAL's reason, before any work,
# not 4 at the write.
rm -rf "$work/out" && mkdir -p "$work/out"
"$SKYSWEEP" $svf -q -co BLOCKXSIZE=7 "$dem" "$work/out/svf.tif" 2>"$work/stderr"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$work/stderr")" -eq 1 ] && [ -z "$(ls -A "$work/out")" ] &&
    grep -q 'TileWidth' "$work/stderr"
tap_ok $? "-co BLOCKXSIZE=7: exit $rc (want 2), GDAL's reason, nothing left: $(head -c 200 "$work/stderr")"
tap_done
