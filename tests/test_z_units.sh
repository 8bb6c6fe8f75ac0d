#!/bin/bash
# Heights in feet: a DEM whose band unit type is ft, or whose compound CRS
# has a vertical axis in US survey feet, gives the sky-view factor of the
# same terrain stored in metres; --z-units overrides the file; a unit that
# cannot be interpreted is refused in one line naming --z-units; the unit
# used is in the output's metadata.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-zunits.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
gdal_translate -q -ot Float32 -srcwin 180 530 48 40 \
    "${TOP_SRCDIR:-$OLDPWD}/samples/kilauea_summit_30m.tif" m.tif
# The same heights in international feet (band unit ft, set through a VRT)
# and in US survey feet under a compound CRS (UTM 5N + NAVD88 height ftUS).
gdal_translate -q -ot Float32 -scale 0 0.3048 0 1 -of VRT m.tif ft.vrt
sed -i 's|<VRTRasterBand \([^>]*\)>|<VRTRasterBand \1>\n    <UnitType>ft</UnitType>|' ft.vrt
gdal_translate -q ft.vrt ft.tif
gdal_translate -q -ot Float32 -scale 0 0.3048006096 0 1 m.tif feet_no_unit.tif
gdal_translate -q -ot Float32 -a_srs EPSG:32605+6360 -scale 0 0.3048006096 0 1 -of VRT m.tif crs.vrt
sed -i '/<UnitType>/d' crs.vrt # the vertical CRS alone says feet
sed 's|<UnitType>ft</UnitType>|<UnitType>furlong</UnitType>|' ft.vrt >furlong.vrt
# A unit written with its datum: its first word names it.
gdal_translate -q -of VRT m.tif asl.vrt
sed -i 's|<VRTRasterBand \([^>]*\)>|<VRTRasterBand \1>\n    <UnitType>m a.s.l.</UnitType>|' asl.vrt

svf() { "$SKYSWEEP" svf -q --device reference --directions 16 "$@"; }
# maxdiff A B: the largest |a - b| over the cells of two rasters.
maxdiff() {
    gdal_translate -q -of ENVI "$1" a.raw && gdal_translate -q -of ENVI "$2" b.raw &&
        paste <(od -An -v -f -w4 a.raw) <(od -An -v -f -w4 b.raw) |
        awk '{d = $1 - $2; if (d < 0) d = -d; if (d > m) m = d} END {printf "%.3g", m + 0}'
}
svf m.tif m_svf.tif
for input in ft.tif crs.vrt; do
    svf "$input" "out_$input.tif"
    d=$(maxdiff m_svf.tif "out_$input.tif")
    unit=$(gdalinfo "out_$input.tif" | grep INPUT_HEIGHT_UNIT)
    awk -v d="$d" 'BEGIN {exit !(d < 1e-5)}'
    tap_ok $? "$input: SVF equals the metre DEM's (max |diff| $d); $unit"
done
svf asl.vrt asl.tif
d=$(maxdiff m_svf.tif asl.tif)
awk -v d="$d" 'BEGIN {exit !(d == 0)}' && gdalinfo asl.tif | grep -q "unit type 'm a.s.l.'"
tap_ok $? "a band unit 'm a.s.l.' is metres (max |diff| $d)"
unit=$(gdalinfo out_crs.vrt.tif | grep -c "CRS's vertical unit 'US survey foot'")
tap_ok $((unit != 1)) "the CRS's vertical unit is named in the metadata"

# Unitless feet are read as metres (nothing says otherwise): the SVF
# differs, and --z-units us-ft puts it right.
svf feet_no_unit.tif plain.tif
d=$(maxdiff m_svf.tif plain.tif)
awk -v d="$d" 'BEGIN {exit !(d > 1e-3)}'
tap_ok $? "feet without a unit are taken as metres (max |diff| $d)"
svf --z-units us-ft feet_no_unit.tif given.tif
d=$(maxdiff m_svf.tif given.tif)
awk -v d="$d" 'BEGIN {exit !(d < 1e-5)}'
tap_ok $? "--z-units us-ft converts them (max |diff| $d)"

"$SKYSWEEP" svf -q --directions 16 furlong.vrt bad.tif 2>err.txt
rc=$?
[ "$rc" -eq 3 ] && [ "$(wc -l <err.txt)" -eq 1 ] && grep -q -- "--z-units" err.txt && [ ! -e bad.tif ]
tap_ok $? "an unknown unit is refused: exit $rc, $(cat err.txt)"
"$SKYSWEEP" svf --directions 16 --z-units cubits m.tif bad.tif >/dev/null 2>err.txt
rc=$?
[ "$rc" -eq 2 ] && [ ! -e bad.tif ]
tap_ok $? "an unknown --z-units is refused: exit $rc, $(head -c 200 err.txt)"
tap_done
