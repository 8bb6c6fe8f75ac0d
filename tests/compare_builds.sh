#!/bin/sh
# Runs every product with two builds of skysweep on the same DEMs and
# compares the outputs value for value (each raster turned into raw float32
# or bytes by gdal_translate, then cmp): the check that a redesign kept
# behaviour. Usage: tests/compare_builds.sh OLD_SKYSWEEP NEW_SKYSWEEP [DEVICE]
# DEVICE is passed to --device (default: reference, the C twin, whose outputs
# must be bit-identical; "default" runs each build's default device). Prints one line per product and "N same, N differ".
set -u
old=$(realpath "$1") new=$(realpath "$2") device=${3:-reference}
top=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-compare.XXXXXX")
trap 'rm -rf "$work"' EXIT
dem=$top/samples/kilauea_summit_30m.tif
# Twice as many cells each way: insolation's bands need a DEM whose whole
# grid takes more than one band does.
dem2=$work/kilauea_15m.tif
gdal_translate -q -outsize 200% 200% -r bilinear "$dem" "$dem2"
same=0 differ=0
device_option="--device $device"
[ "$device" = default ] && device_option=

# product NAME ARGS... (the last two are DEM and OUTPUT, OUTPUT relative to
# the build's folder; extra outputs are named with --distance/--cast-height).
product() {
    name=$1
    shift
    for b in old new; do
        mkdir -p "$work/$b"
        eval "bin=\$$b"
        (cd "$work/$b" && "$bin" "$@" -q $device_option >/dev/null 2>"$work/$b.err") ||
            { echo "$name: $b build failed: $(head -c 200 "$work/$b.err")"; differ=$((differ + 1)); return; }
    done
    verdict=same
    for f in "$work/old/"*.tif; do
        base=$(basename "$f")
        gdal_translate -q -of ENVI "$f" "$work/old.raw" &&
            gdal_translate -q -of ENVI "$work/new/$base" "$work/new.raw" &&
            cmp -s "$work/old.raw" "$work/new.raw" || verdict="differ ($base)"
    done
    echo "$name: $verdict"
    if [ "$verdict" = same ]; then same=$((same + 1)); else differ=$((differ + 1)); fi
    rm -rf "$work/old" "$work/new"
}

t=2026-06-21T19:00Z
for def in geometric radiative horizontal; do
    product "svf $def" svf --directions 16 --definition "$def" "$dem" out.tif
    product "svf $def, bands" svf --directions 16 --definition "$def" --memory 52M "$dem" out.tif
done
product "svf --radius" svf --directions 16 --radius 1000 "$dem" out.tif
product "openness +" openness --directions 16 "$dem" out.tif
product "openness -" openness --directions 16 --kind negative "$dem" out.tif
product "horizon" horizon --directions 8 --distance d.tif --cast-height c.tif "$dem" out.tif
product "horizon, bands" horizon --directions 8 --distance d.tif --cast-height c.tif \
    --memory 52M "$dem" out.tif
product "shadow" shadow --time "$t" "$dem" out.tif
product "shadow, bands" shadow --time "$t" --memory 52M "$dem" out.tif
product "hillshade" hillshade "$dem" out.tif
product "hillshade --cast-shadows" hillshade --cast-shadows --directions 16 "$dem" out.tif
product "hillshade --blend vat" hillshade --blend vat --directions 16 "$dem" out.tif
product "insolation" insolation --time 2026-06-21T16:00Z/PT6H --step PT1H --directions 16 \
    "$dem" out.tif
product "insolation, bands" insolation --time 2026-06-21T16:00Z/PT6H --step PT1H \
    --directions 16 --memory 76M "$dem2" out.tif
echo "$same same, $differ differ"
[ "$differ" -eq 0 ]
