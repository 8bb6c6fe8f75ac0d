#!/bin/bash
# Input data types: a DEM is read as GDAL means its band, whatever the
# type. One small DEM (a cone with a -99 m pit and a row of nodata) written
# as each integer and float type gives the SVF of its Int16 copy, bit for
# bit: signed bytes (GDAL 3.6's Byte with PIXELTYPE=SIGNEDBYTE, not 157
# for -99), 32 and 64-bit integers, Float32 and Float64; unsigned types
# hold it 200 m higher (the SVF is the same) with nodata 2^16 - 1, 2^32 - 1
# and 2^40 (UInt64). Complex bands are refused. Other rasters (quicklook's,
# render's drapes) are read the same way: a quicklook of the signed bytes
# is the Int16 copy's.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-types.XXXXXX")
trap 'rm -rf "$work"' EXIT

# asc LIFT NODATA BYTE: the DEM as an ASCII grid, heights + LIFT, nodata
# cells NODATA; BYTE=1 writes negative values as their unsigned byte.
asc() {
    awk -v lift="$1" -v nd="$2" -v byte="$3" 'BEGIN {
        print "ncols 40\nnrows 40\nxllcorner 500000\nyllcorner 4000000\ncellsize 30"
        print "NODATA_value " nd
        for (r = 0; r < 40; ++r) {
            line = ""
            for (c = 0; c < 40; ++c) {
                d = sqrt((r - 20) ^ 2 + (c - 22) ^ 2)
                h = int(110 - 9 * d); if (h < -120) h = -120
                if (r == 6 && c == 6) h = -99
                v = h + lift
                if (byte && v < 0) v += 256
                if (r == 30 && c >= 10 && c < 16) v = nd
                line = line (c ? " " : "") v
            }
            print line
        }
    }'
}
epsg="-a_srs EPSG:32633"
asc 0 -128 0 >"$work/s.asc"
gdal_translate -q $epsg -ot Int16 "$work/s.asc" "$work/ref.tif"
asc 0 128 1 >"$work/b.asc"
gdal_translate -q $epsg -ot Byte -co PIXELTYPE=SIGNEDBYTE -a_nodata -128 "$work/b.asc" \
    "$work/Int8.tif"
asc 128 0 0 >"$work/u8.asc"
gdal_translate -q $epsg -ot Byte "$work/u8.asc" "$work/Byte.tif"
for t in Int32 Int64 Float32 Float64; do
    gdal_translate -q -ot $t "$work/ref.tif" "$work/$t.tif"
done
for t in "UInt16 65535" "UInt32 4294967295" "UInt64 1099511627776"; do
    set -- $t
    asc 200 "$2" 0 >"$work/$1.asc"
    gdal_translate -q $epsg -oo DATATYPE=Float64 -ot "$1" -a_nodata "$2" "$work/$1.asc" \
        "$work/$1.tif"
done

svf() { "$SKYSWEEP" svf -q --directions 8 --device reference "$1" "$2"; }
raw() { gdal_translate -q -of ENVI "$1" "$2"; }
svf "$work/ref.tif" "$work/ref_svf.tif" && raw "$work/ref_svf.tif" "$work/ref.raw"
tap_ok $? "svf of the Int16 DEM"
for t in Int8 Byte UInt16 UInt32 UInt64 Int32 Int64 Float32 Float64; do
    svf "$work/$t.tif" "$work/${t}_svf.tif" 2>"$work/err" &&
        raw "$work/${t}_svf.tif" "$work/$t.raw" && cmp -s "$work/$t.raw" "$work/ref.raw"
    tap_ok $? "$t ($(gdalinfo "$work/$t.tif" | grep -o 'Type=[A-Za-z0-9]*' | head -1), $(gdalinfo "$work/$t.tif" | grep -o 'NoData Value=.*')): the SVF of the Int16 DEM, bit for bit $(head -c 200 "$work/err")"
done

for t in CInt16 CInt32 CFloat32 CFloat64; do
    gdal_translate -q -ot $t "$work/ref.tif" "$work/$t.tif"
    svf "$work/$t.tif" "$work/${t}_svf.tif" 2>"$work/err"
    rc=$?
    [ "$rc" -eq 3 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "complex" "$work/err" &&
        [ ! -e "$work/${t}_svf.tif" ]
    tap_ok $? "a $t band is refused: exit $rc, $(head -c 200 "$work/err")"
done

# Products and drapes: quicklook reads any band the same way.
"$SKYSWEEP" quicklook "$work/ref.tif" "$work/ref.png" >"$work/ref.out" 2>"$work/err"
rc=$?
if [ $rc -eq 5 ] && grep -q 'built without OpenImageIO' "$work/err"; then
    tap_skip "quicklook of signed bytes" "built without OpenImageIO"
else
    "$SKYSWEEP" quicklook "$work/Int8.tif" "$work/Int8.png" >"$work/Int8.out" 2>>"$work/err" &&
        cmp -s "$work/Int8.png" "$work/ref.png"
    tap_ok $? "quicklook of the signed bytes == the Int16 copy's: $(head -1 "$work/Int8.out") $(head -c 200 "$work/err")"
fi
"$SKYSWEEP" quicklook "$work/CInt16.tif" "$work/CInt16.png" 2>"$work/err"
rc=$?
[ "$rc" -eq 3 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && [ ! -e "$work/CInt16.png" ]
tap_ok $? "quicklook of a CInt16 band is refused: exit $rc, $(head -c 200 "$work/err")"
tap_done
