#!/bin/bash
# skysweep canopy (doc/vegetation.md, "skysweep canopy"): on a synthetic
# first-return DSM over flat ground (a building whose wall lies a column
# east of its footprint, a tree blob, a car-sized 1.5 m bump, a lamp post,
# a crown over the building's corner, holes in the DSM and the DTM) both
# outputs equal hand-made rasters cell by cell; each threshold is an
# option that changes what it says it does; the metadata name the recipe
# and its thresholds; svf --canopy on the outputs equals svf --canopy on
# the hand-made rasters; a DTM above the DSM, a DTM that cannot be put on
# the DSM's grid, footprints missing, corrupt or elsewhere, and an output
# that is an input or the other output are refused in one line with the
# documented exit code, nothing written. On the Gothenburg data
# (../shared/data, skipped without it) the CDSM agrees with UMEP's.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
top=$(realpath "${TOP_SRCDIR:-.}")
SKYSWEEP=${SKYSWEEP:-$PWD/skysweep}
case $SKYSWEEP in /*) ;; *) SKYSWEEP=$PWD/$SKYSWEEP ;; esac
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-canopy.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1

# asc NAME EXPR: a 30 x 20 AAIGrid of 1 m cells (EPSG:3006, north-west
# corner at 400000, 6400020), EXPR of the column c and row r in awk
# (-9999: nodata), then a Float32 GeoTIFF.
asc() {
    awk "BEGIN {
        print \"ncols 30\"; print \"nrows 20\"; print \"xllcorner 400000\"
        print \"yllcorner 6400000\"; print \"cellsize 1\"; print \"NODATA_value -9999\"
        for (r = 0; r < 20; ++r) { line = \"\"
            for (c = 0; c < 30; ++c) line = line \" \" ($2)
            print line } }" >"$1.asc"
    gdal_translate -q -ot Float32 -a_srs EPSG:3006 "$1.asc" "$1.tif"
}
# The scene, ground at 10 m. Building: columns 3-11, rows 3-10, 22 m; its
# footprint (below) covers columns 3-10 only. A crown 25 m high over
# columns 9-14, rows 9-14 (over the building's south-east corner). A tree
# blob, columns 18-22, rows 4-8, 6 m tall, 8 m at its centre. A car, 1.5
# m. A lamp post, one cell 5 m tall. No DSM at (0, 19).
building='c >= 3 && c <= 11 && r >= 3 && r <= 10'
crown='c >= 9 && c <= 14 && r >= 9 && r <= 14'
blob='c >= 18 && c <= 22 && r >= 4 && r <= 8'
dsm="(c == 0 && r == 19) ? -9999 : ($crown) ? 25 : ($blob) ? ((c == 20 && r == 6) ? 18 : 16) : \
($building) ? 22 : (c >= 15 && c <= 16 && r == 17) ? 11.5 : (c == 26 && r == 15) ? 15 : 10"
# No DTM at (28, 0), outside the buildings, nor at (5, 5), inside one.
dtm='(c == 28 && r == 0) || (c == 5 && r == 5) ? -9999 : 10'
asc dsm "$dsm"
asc dtm "$dtm"
# Expected, by hand: the footprint (x 3-11 m, y 3-11 m) grown by 1 m
# holds the centres of columns 2-11, rows 2-11; there the DSM is kept and
# nothing is vegetation. Elsewhere the ground is 10 m; the blob and the
# crown outside the grown footprint are vegetation; the car is below 2.5
# m and the lamp post has no vegetated neighbour: ground.
grown='c >= 2 && c <= 11 && r >= 2 && r <= 11'
hole='(c == 0 && r == 19) || (c == 28 && r == 0)'
asc want_dsm "($hole) ? -9999 : ($grown) ? ($dsm) : 10"
asc want_cdsm "($hole) ? -9999 : ($grown) ? 0 : ($crown) ? 15 : ($blob) ? ((c == 20 && r == 6) ? 8 : 6) : 0"
# The footprint as GeoJSON (x east, y south of the north-west corner).
footprint() { # FILE X0 Y0 X1 Y1
    awk -v x0="$2" -v y0="$3" -v x1="$4" -v y1="$5" 'function p(x, y) { return sprintf("[%.3f,%.3f]", 400000 + x, 6400020 - y) }
    BEGIN { printf "{\"type\":\"FeatureCollection\",\"crs\":{\"type\":\"name\",\"properties\":{\"name\":\"EPSG:3006\"}},"
            printf "\"features\":[{\"type\":\"Feature\",\"properties\":{\"id\":\"A\"},\"geometry\":{\"type\":\"Polygon\","
            printf "\"coordinates\":[[%s,%s,%s,%s,%s]]}}]}\n", p(x0, y0), p(x1, y0), p(x1, y1), p(x0, y1), p(x0, y0) }' >"$1"
}
footprint footprints.geojson 3 3 11 11
footprint elsewhere.geojson 3003 3 3011 11

# band FILE: band 1's values, one a line (-9999 at nodata).
band() {
    gdal_translate -q -b 1 -of ENVI "$1" "$1.raw" && od -An -v -f -w4 "$1.raw" | tr -d ' '
}
# differ GOT WANT: the cells whose values differ by more than 1e-4, as
# "col,row:got/want" (none: empty).
differ() {
    paste <(band "$1") <(band "$2") | awk '{ d = $1 - $2; if (d < 0) d = -d
        if (d > 1e-4) printf "%d,%d:%s/%s ", (NR - 1) % 30, int((NR - 1) / 30), $1, $2 }'
}
# cell FILE C R: the value at column C, row R.
cell() { band "$1" | sed -n "$(($3 * 30 + $2 + 1))p"; }
canopy() { "$SKYSWEEP" canopy -q --buildings footprints.geojson --dtm dtm.tif "$@"; }

canopy --cdsm cdsm.tif dsm.tif out.tif 2>err.txt
tap_ok $? "canopy runs on the synthetic scene: $(head -c 300 err.txt)"
bad=$(differ out.tif want_dsm.tif)
tap_ok "$([ -z "$bad" ]; echo $?)" "the DSM of buildings and ground equals the hand-made one on every cell ${bad:+(differ: $(echo "$bad" | head -c 300))}"
bad=$(differ cdsm.tif want_cdsm.tif)
tap_ok "$([ -z "$bad" ]; echo $?)" "the CDSM equals the hand-made one on every cell ${bad:+(differ: $(echo "$bad" | head -c 300))}"
got="$(cell out.tif 10 10) $(cell cdsm.tif 10 10) $(cell out.tif 5 5) $(cell cdsm.tif 5 5)"
[ "$got" = "25 0 22 0" ]
tap_ok $? "a crown over a roof becomes roof (DSM 25, CDSM 0), and a DTM hole under a building keeps its DSM (22, 0): $got"

# Each threshold, moved, does what it says.
canopy --cdsm low.tif --min-tree-height 1 --min-tree-neighbours 0 dsm.tif low_dsm.tif
got="$(cell low.tif 15 17) $(cell low.tif 16 17) $(cell low.tif 26 15)"
[ "$got" = "1.5 1.5 5" ]
tap_ok $? "--min-tree-height 1 --min-tree-neighbours 0: the car and the lamp post become vegetation ($got; want 1.5 1.5 5)"
canopy --cdsm nobuffer.tif --building-buffer 0 --min-tree-neighbours 0 dsm.tif nobuffer_dsm.tif
got=$(for r in 3 4 5 6 7 8; do cell nobuffer.tif 11 "$r"; done | sort -u | tr '\n' ' ')
[ "$got" = "12 " ] && [ "$(cell nobuffer_dsm.tif 11 5)" = 10 ]
tap_ok $? "--building-buffer 0 --min-tree-neighbours 0: the wall outside the footprint (column 11, rows 3-8, south of it the crown) becomes a 12 m tree ($got) on 10 m ground"
canopy --cdsm wall.tif --building-buffer 0 dsm.tif wall_dsm.tif
got=$(for r in 3 4 5 6 7; do cell wall.tif 11 "$r"; done | sort -u | tr '\n' ' ')
[ "$got" = "0 " ]
tap_ok $? "--building-buffer 0 alone: that one-cell sliver has fewer than 3 vegetated neighbours and is ground (rows 3-7: $got)"

md_dsm=$(gdalinfo out.tif) md_cdsm=$(gdalinfo cdsm.tif)
ok=0
for md in "$md_dsm" "$md_cdsm"; do
    for key in 'SKYSWEEP_COMMAND=canopy' 'MIN_TREE_HEIGHT_M=2.5' 'BUILDING_BUFFER_M=1' \
        'MIN_TREE_NEIGHBOURS=3' 'RECIPE=footprints grown by 1 m' 'INPUT_DTM=dtm.tif' \
        'INPUT_BUILDINGS=footprints.geojson (1 footprints on the DSM)' 'NoData Value=-9999' \
        'Type=Float32'; do
        grep -qF "$key" <<<"$md" || { ok=1; tap_diag "missing: $key"; }
    done
done
grep -q 'QUANTITY=vegetation canopy height above the ground' <<<"$md_cdsm" &&
    grep -q 'QUANTITY=surface height of buildings and ground' <<<"$md_dsm" || ok=1
tap_ok $ok "both outputs are Float32 with nodata -9999 and name the recipe, its thresholds and inputs"

# Round trip: the tree options take the outputs as they take hand-made ones.
svf() { "$SKYSWEEP" svf -q --device reference --directions 16 "$@"; }
svf --canopy cdsm.tif out.tif svf_made.tif && svf --canopy want_cdsm.tif want_dsm.tif svf_want.tif
ok=$?
same=0
for b in 1 2 3; do
    gdal_translate -q -b $b -of ENVI svf_made.tif made.b$b && gdal_translate -q -b $b -of ENVI svf_want.tif want.b$b &&
        cmp -s made.b$b want.b$b || same=1
done
[ "$ok" -eq 0 ] && [ "$same" -eq 0 ]
tap_ok $? "svf --canopy CDSM DSM on the outputs equals it on the hand-made rasters, band for band"

# refused EXIT DESCRIPTION ARGS...: exit EXIT, one line on stderr, neither
# output written (nor an input replaced: the caller checks).
refused() {
    local want=$1 what=$2
    shift 2
    rm -f r_out.tif r_cdsm.tif
    "$SKYSWEEP" canopy -q "$@" >/dev/null 2>r.err
    local rc=$?
    [ "$rc" -eq "$want" ] && [ "$(wc -l <r.err)" -eq 1 ] && [ ! -e r_out.tif ] && [ ! -e r_cdsm.tif ] &&
        [ -z "$(find . -maxdepth 1 -name '.?*')" ]
    tap_ok $? "$what: exit $rc (want $want), one line: $(head -c 250 r.err)"
}
asc high_dtm 20
refused 3 "a DTM 10 m above the DSM over most cells" \
    --buildings footprints.geojson --dtm high_dtm.tif --cdsm r_cdsm.tif dsm.tif r_out.tif
asc some_high_dtm '(c < 2) ? 20 : 10'
"$SKYSWEEP" canopy -q --buildings footprints.geojson --dtm some_high_dtm.tif --cdsm r_cdsm.tif dsm.tif r_out.tif 2>r.err
tap_ok $? "a DTM above the DSM on 2 columns of 30 (6.7 %, within 10 %) is taken: $(head -c 200 r.err)"
# 20 x 20 cells without georeferencing: neither on the DSM's grid nor warpable.
gdal_translate -q -srcwin 0 0 20 20 -of VRT dtm.tif nogeo.vrt
sed -i '/<GeoTransform>/d; /<SRS.*<\/SRS>/d' nogeo.vrt
gdal_translate -q nogeo.vrt nogeo.tif
refused 3 "a DTM of another size without georeferencing" \
    --buildings footprints.geojson --dtm nogeo.tif --cdsm r_cdsm.tif dsm.tif r_out.tif
gdal_translate -q -srcwin 0 0 20 20 dtm.tif small_dtm.tif
refused 3 "a DTM that covers part of the DSM" \
    --buildings footprints.geojson --dtm small_dtm.tif --cdsm r_cdsm.tif dsm.tif r_out.tif
refused 3 "footprints that are not there" \
    --buildings missing.geojson --dtm dtm.tif --cdsm r_cdsm.tif dsm.tif r_out.tif
printf '{"type": "FeatureCollection", "features": [{"type"' >corrupt.geojson
refused 3 "corrupt footprints" \
    --buildings corrupt.geojson --dtm dtm.tif --cdsm r_cdsm.tif dsm.tif r_out.tif
refused 3 "footprints 3 km away from the DSM" \
    --buildings elsewhere.geojson --dtm dtm.tif --cdsm r_cdsm.tif dsm.tif r_out.tif
# A geographic DSM: the buffer in metres has no size in degrees.
gdalwarp -q -t_srs EPSG:4326 dsm.tif geo_dsm.tif && gdalwarp -q -t_srs EPSG:4326 dtm.tif geo_dtm.tif
refused 2 "--building-buffer 1 on a geographic DSM" \
    --buildings footprints.geojson --dtm geo_dtm.tif --cdsm r_cdsm.tif geo_dsm.tif r_out.tif
"$SKYSWEEP" canopy -q --building-buffer 0 --buildings footprints.geojson --dtm geo_dtm.tif \
    --cdsm r_cdsm.tif geo_dsm.tif r_out.tif 2>r.err
tap_ok $? "--building-buffer 0 on a geographic DSM runs: $(head -c 200 r.err)"
printf '{"type": "FeatureCollection", "features": []}' >none.geojson
"$SKYSWEEP" canopy -q --buildings none.geojson --dtm dtm.tif --cdsm none_cdsm.tif dsm.tif none_dsm.tif 2>r.err &&
    [ "$(cell none_cdsm.tif 6 6)" = 12 ] && [ "$(cell none_dsm.tif 6 6)" = 10 ]
tap_ok $? "a layer without features: no buildings, the building's top becomes vegetation ($(cell none_cdsm.tif 6 6) m) $(head -c 200 r.err)"
refused 4 "--cdsm in a folder that does not exist" \
    --buildings footprints.geojson --dtm dtm.tif --cdsm no/such/r_cdsm.tif dsm.tif r_out.tif
refused 2 "no --cdsm" --buildings footprints.geojson --dtm dtm.tif dsm.tif r_out.tif
sum_before=$(md5sum dsm.tif dtm.tif footprints.geojson)
refused 2 "OUT_DSM is the DSM" --buildings footprints.geojson --dtm dtm.tif --cdsm r_cdsm.tif dsm.tif dsm.tif
refused 2 "--cdsm is the DTM" --buildings footprints.geojson --dtm dtm.tif --cdsm dtm.tif dsm.tif r_out.tif
refused 2 "--cdsm is the footprints" --buildings footprints.geojson --dtm dtm.tif --cdsm footprints.geojson dsm.tif r_out.tif
refused 2 "--cdsm is OUT_DSM" --buildings footprints.geojson --dtm dtm.tif --cdsm r_out.tif dsm.tif r_out.tif
[ "$(md5sum dsm.tif dtm.tif footprints.geojson)" = "$sum_before" ]
tap_ok $? "the inputs named as outputs are left as they were"

# Gothenburg: a first-return DSM made of UMEP's DSM (ground and
# buildings) with UMEP's trees on the DEM, max(DSM, DEM + CDSM); canopy
# with UMEP's footprints and DEM gives back a CDSM that agrees with UMEP's
# on the share of cells measured (doc/vegetation.md), less a margin.
data=$top/../shared/data
if [ ! -f "$data/goteborg_kronenhuset_cdsm_1m.tif" ]; then
    tap_skip "Gothenburg: the CDSM agrees with UMEP's" "no $data"
else
    for f in dsm dem cdsm; do
        gdal_translate -q -of AAIGrid "$data/goteborg_kronenhuset_${f}_1m.tif" g_$f.asc
    done
    # The grids' rows after their 6 header lines (the same in all three).
    paste -d '\n' <(tail -n +7 g_dsm.asc) <(tail -n +7 g_dem.asc) <(tail -n +7 g_cdsm.asc) |
        awk 'NR % 3 == 1 { n = split($0, s, " ") } NR % 3 == 2 { split($0, g, " ") }
             NR % 3 == 0 { split($0, t, " "); line = ""
                 for (i = 1; i <= n; ++i) { v = g[i] + t[i]; line = line " " (v > s[i] ? v : s[i]) }
                 print line }' >g_body.txt
    { head -n 6 g_dsm.asc; cat g_body.txt; } >g_first.asc
    gdal_translate -q -ot Float32 -a_srs EPSG:3007 g_first.asc g_first.tif
    "$SKYSWEEP" canopy -q --buildings "$data/goteborg_buildings/goteborg_kronenhuset_buildings.shp" \
        --dtm "$data/goteborg_kronenhuset_dem_1m.tif" --cdsm g_cdsm.tif g_first.tif g_out.tif 2>g.err
    rc=$?
    says=$(paste <(band g_cdsm.tif) <(gdal_translate -q -of ENVI "$data/goteborg_kronenhuset_cdsm_1m.tif" g_ref.raw &&
        od -An -v -F -w8 g_ref.raw | tr -d ' ') | awk '
        { a = $1 > 0; b = $2 > 0; both += a && b; none += !a && !b; made += a; ref += b; n++ }
        END { printf "agree %.4f (both vegetation %.4f, both none %.4f), recall %.3f, precision %.3f",
                     (both + none) / n, both / n, none / n, both / ref, both / made
              exit !((both + none) / n >= 0.99 && both / ref >= 0.9 && both / made >= 0.97) }')
    agreed=$?
    [ "$rc" -eq 0 ] && [ "$agreed" -eq 0 ]
    tap_ok $? "Gothenburg: the CDSM agrees with UMEP's on at least 99 % of cells, recall 0.9, precision 0.97: $says $(head -c 200 g.err)"
fi
tap_done
