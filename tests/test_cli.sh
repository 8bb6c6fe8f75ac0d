#!/bin/bash
# The command line as a user meets it: the main jobs on a small DEM give
# outputs GDAL reads with the input's georeferencing, and every bad input or
# option in the catalogue gives one line on stderr, the documented exit code
# (doc/cli.md), no signal, and no output file or temporary left behind; an
# existing output is never replaced by a failed run.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-cli.XXXXXX")
trap 'rm -rf "$work"' EXIT

# A 60 x 50 DEM in UTM 5N with a hill and one nodata cell, written as an
# ASCII grid by awk (no Python needed) and converted by GDAL.
dem=$work/dem.tif
awk 'BEGIN {
    print "ncols 60"; print "nrows 50"; print "xllcorner 254325"; print "yllcorner 2152155"
    print "cellsize 30"; print "NODATA_value -9999"
    for (r = 0; r < 50; r++) {
        line = ""
        for (c = 0; c < 60; c++) {
            v = (r == 0 && c == 0) ? -9999 : 100 + 300 * exp(-((c - 30) ^ 2 + (r - 25) ^ 2) / 80)
            line = line sprintf("%.3f ", v)
        }
        print line
    }
}' >"$work/dem.asc"
gdal_translate -q -ot Float32 -a_srs EPSG:32605 "$work/dem.asc" "$dem"

run() { # runs skysweep, capturing stdout/stderr and the exit code in $rc
    "$SKYSWEEP" "$@" >"$work/stdout" 2>"$work/stderr"
    rc=$?
}

# ---- the main jobs -----------------------------------------------------------
run svf --directions 16 "$dem" "$work/svf.tif"
tap_ok $rc "svf on a small DEM exits 0 ($(head -c 200 "$work/stderr"))"
info=$(gdalinfo -stats "$work/svf.tif" 2>&1)
echo "$info" | grep -q 'ID\["EPSG",32605\]'
tap_ok $? "svf output keeps the CRS (EPSG:32605)"
echo "$info" | grep -q 'Origin = (254325.000000000000000,2153655.000000000000000)'
tap_ok $? "svf output keeps the geotransform origin"
echo "$info" | grep -q 'NoData Value=-9999'
tap_ok $? "svf output declares nodata -9999"
echo "$info" | grep -q 'Description = sky-view factor'
tap_ok $? "svf band is described"
min=$(echo "$info" | sed -n 's/.*STATISTICS_MINIMUM=//p')
max=$(echo "$info" | sed -n 's/.*STATISTICS_MAXIMUM=//p')
awk -v a="$min" -v b="$max" 'BEGIN { exit !(a > 0.5 && a < 1 && b <= 1) }'
tap_ok $? "svf values lie in (0.5, 1] on a gentle hill (min $min, max $max)"
grep -q '^svf .*min' "$work/stdout"
tap_ok $? "svf prints a summary"
# The phases line: its parts are non-negative and add up to its total (the
# rest is what is left, to the printed milliseconds), and its sweeps are the
# seconds the time line gives.
phases_add_up() {
    awk '/^phases/ { for (i = 1; i <= NF; i++) if ($i ~ /^[0-9.]+$/ && $(i + 1) ~ /^s,?$/) v[++n] = $i }
         /^time +sweep/ { sweep = $3 }
         END { if (n != 8 || sweep == "") exit 1
               sum = 0; for (i = 2; i <= 8; i++) { if (v[i] < 0) exit 1; sum += v[i] }
               exit !(sum - v[1] < 0.0045 && v[1] - sum < 0.0045 && v[6] == sweep && v[1] > 0) }' \
        "$work/stdout"
}
phases_add_up
tap_ok $? "svf's phases line adds up and agrees with its sweep time ($(grep '^phases' "$work/stdout"))"
# On PoCL with a cold kernel cache the memory plan opens the device, and so
# builds its kernels, while the DEM is opened: the build is counted once.
if "$SKYSWEEP" svf --device list 2>/dev/null | grep -q "Portable Computing Language"; then
    POCL_CACHE_DIR=$work/pocl-cold run svf --directions 16 --device Portable "$dem" "$work/svf_cl.tif"
    [ "$rc" -eq 0 ] && phases_add_up
    tap_ok $? "svf on PoCL, its kernels built cold: the phases line adds up ($(grep '^phases' "$work/stdout"))"
    rm -rf "$work/pocl-cold" "$work/svf_cl.tif"
else
    tap_skip "svf on PoCL, its kernels built cold: the phases line adds up" "no PoCL device"
fi

# Openness: degrees, the hill's top more open than 90 (it looks down all
# round) and its foot less, nodata kept; negative openness the reverse.
run openness --directions 16 "$dem" "$work/pos.tif"
tap_ok $rc "openness exits 0 ($(head -c 200 "$work/stderr"))"
top=$(gdallocationinfo -valonly "$work/pos.tif" 30 25)
foot=$(gdallocationinfo -valonly "$work/pos.tif" 30 35)
corner=$(gdallocationinfo -valonly "$work/pos.tif" 0 0)
awk -v t="$top" -v f="$foot" -v c="$corner" 'BEGIN { exit !(t > 90 && t < 180 && f < 90 && c == -9999) }'
tap_ok $? "positive openness: top $top > 90, foot $foot < 90, nodata corner $corner"
run openness --kind negative --radius 300 --directions 16 "$dem" "$work/neg.tif"
tap_ok $rc "negative openness with --radius exits 0"
top=$(gdallocationinfo -valonly "$work/neg.tif" 30 25)
gdalinfo "$work/neg.tif" | grep -q 'OPENNESS_RADIUS_M=300'
tap_ok $? "negative openness: radius recorded; top $top"
awk -v t="$top" 'BEGIN { exit !(t < 90) }'
tap_ok $? "negative openness of the hill's top is below 90 ($top)"

# The VAT relief blend: Byte 1..255 with 0 = nodata, georeferencing kept.
run hillshade --blend vat --directions 16 "$dem" "$work/vat.tif"
tap_ok $rc "hillshade --blend vat exits 0 ($(head -c 200 "$work/stderr"))"
info=$(gdalinfo -stats "$work/vat.tif" 2>&1)
echo "$info" | grep -q 'Type=Byte' && echo "$info" | grep -q 'NoData Value=0' &&
    echo "$info" | grep -q 'ID\["EPSG",32605\]' &&
    echo "$info" | grep -q 'Origin = (254325.000000000000000,2153655.000000000000000)'
tap_ok $? "VAT blend is Byte with nodata 0, CRS and origin kept"
min=$(echo "$info" | sed -n 's/.*STATISTICS_MINIMUM=//p')
corner=$(gdallocationinfo -valonly "$work/vat.tif" 0 0)
awk -v a="$min" -v c="$corner" 'BEGIN { exit !(a >= 1 && c == 0) }'
tap_ok $? "VAT values >= 1 (min $min), nodata cell 0 ($corner)"
gdalinfo "$work/vat.tif" | grep -q 'RELIEF_BLEND=RVT VAT'
tap_ok $? "VAT blend states its recipe in the metadata"

run horizon --directions 8 --distance "$work/dist.tif" "$dem" "$work/h.tif"
tap_ok $rc "horizon with --distance exits 0"
bands=$(gdalinfo "$work/h.tif" | grep -c '^Band ')
[ "$bands" -eq 8 ]
tap_ok $? "horizon writes one band per direction ($bands)"
gdalinfo "$work/h.tif" | grep -q 'Description = azimuth 135'
tap_ok $? "horizon bands are described by azimuth"
gdalinfo "$work/dist.tif" | grep -q 'Unit Type: m'
tap_ok $? "distance bands carry the unit m"

# Casting heights: band 3 looks east (azimuth 90). From the hill's western
# foot the caster is on the hill (ground 300..400 m); from the eastern edge
# nothing lies ahead: nodata, where the distance is 0.
run horizon --directions 8 --cast-height "$work/cast.tif" --distance "$work/dist2.tif" "$dem" \
    "$work/h2.tif"
tap_ok $rc "horizon with --cast-height and --distance exits 0 ($(head -c 200 "$work/stderr"))"
foot=$(gdallocationinfo -valonly -b 3 "$work/cast.tif" 10 25)
edge=$(gdallocationinfo -valonly -b 3 "$work/cast.tif" 59 25)
edge_dist=$(gdallocationinfo -valonly -b 3 "$work/dist2.tif" 59 25)
awk -v f="$foot" -v e="$edge" -v d="$edge_dist" 'BEGIN { exit !(f > 300 && f <= 400 && e == -9999 && d == 0) }'
tap_ok $? "casting height east of the foot is on the hill ($foot m); east edge nodata ($edge, distance $edge_dist)"
gdalinfo "$work/cast.tif" | grep -q 'QUANTITY=ground height of the horizon-casting point' &&
    [ "$(gdalinfo "$work/cast.tif" | grep -c '^Band ')" -eq 8 ]
tap_ok $? "casting heights: 8 bands, quantity stated"
# On box lines each cell's own ray gives the horizons (--box-sky march, the
# default): from the east edge nothing rises above the cell's own flat top,
# so its horizon is 0 deg, cast at its own edge (half of a 30 m cell) at its
# own height; the metadata say so, and what the run took.
run horizon --lines box --directions 8 --cast-height "$work/bcast.tif" --distance "$work/bdist.tif" \
    "$dem" "$work/bh.tif"
angle=$(gdallocationinfo -valonly -b 3 "$work/bh.tif" 59 25)
dist=$(gdallocationinfo -valonly -b 3 "$work/bdist.tif" 59 25)
cast=$(gdallocationinfo -valonly -b 3 "$work/bcast.tif" 59 25)
own=$(gdallocationinfo -valonly "$dem" 59 25)
meta=$(gdalinfo "$work/bh.tif"; gdalinfo "$work/bdist.tif"; gdalinfo "$work/bcast.tif")
[ $rc -eq 0 ] &&
    awk -v a="$angle" -v d="$dist" -v c="$cast" -v z="$own" \
        'BEGIN { exit !(a == 0 && d > 14.9 && d < 15.1 && c - z < 1e-3 && z - c < 1e-3) }' &&
    grep -q "LINE_MODEL=.*horizons.*by each cell's own ray" <<<"$meta" &&
    ! grep -q "lines swept" <<<"$meta" &&
    grep -q "QUANTITY=distance.*the distance to its own edge" <<<"$meta" &&
    grep -q "QUANTITY=ground height.*the cell's own height" <<<"$meta" &&
    grep -q "DEVICE=the host: the box model by each cell's own ray" <<<"$meta"
tap_ok $? "horizon on box lines: the east edge's own top, 0 deg ($angle) at its own edge ($dist m) and height ($cast m of $own), and LINE_MODEL, QUANTITY and DEVICE say each cell's own ray"
run horizon --lines box --box-sky lines --directions 8 "$dem" "$work/bh2.tif"
meta=$(gdalinfo "$work/bh2.tif")
[ $rc -eq 0 ] && grep -q "LINE_MODEL=.*the lines swept, 32 per cell" <<<"$meta" &&
    ! grep -q "own ray" <<<"$meta"
tap_ok $? "horizon on box lines with --box-sky lines: LINE_MODEL names the 32 lines swept and no ray ($(grep LINE_MODEL <<<"$meta" | head -c 200))"
run horizon --directions 8 --cast-height "$work/h3.tif" "$dem" "$work/h3.tif"
[ $rc -eq 2 ] && [ "$(wc -l <"$work/stderr")" -eq 1 ]
tap_ok $? "--cast-height naming OUTPUT: exit 2, one line"
# The same file spelled two ways would share one temporary name.
mkdir -p "$work/sub"
run horizon --directions 8 --distance "$work/sub/../d3.tif" --cast-height "$work/./d3.tif" "$dem" \
    "$work/h3.tif"
[ $rc -eq 2 ] && [ "$(wc -l <"$work/stderr")" -eq 1 ] && [ ! -e "$work/h3.tif" ]
tap_ok $? "--distance and --cast-height naming one file two ways: exit 2, one line, no output"

run svf -q --directions 8 "$dem" "$work/quiet.tif"
[ $rc -eq 0 ] && [ ! -s "$work/stdout" ] && [ ! -s "$work/stderr" ]
tap_ok $? "-q prints nothing"

run svf --device reference --directions 8 "$dem" "$work/ref.tif"
tap_ok $rc "--device reference runs the C twin"

# ---- the catalogue of bad inputs ------------------------------------------------
# expect_failure CODE DESCRIPTION -- ARGS...: the run must exit with CODE (not
# a signal), print exactly one line on stderr, and leave no output and no
# temporary file in $work/out.
mkdir -p "$work/out"
expect_failure() {
    local code=$1 what=$2
    shift 3
    rm -f "$work/out/"* "$work/out/".*.tmp 2>/dev/null
    run "$@"
    local lines leftovers
    lines=$(wc -l <"$work/stderr")
    leftovers=$(ls -A "$work/out" | wc -l)
    [ "$rc" -eq "$code" ] && [ "$lines" -eq 1 ] && [ "$leftovers" -eq 0 ]
    tap_ok $? "$what: exit $rc (want $code), $lines stderr line(s), $leftovers file(s) left: $(head -c 160 "$work/stderr")"
}

expect_failure 2 "does not take" -- hillshade --blend vat --cast-shadows "$dem" "$work/out/o.tif"
expect_failure 2 "negative openness radius" -- openness --radius -5 "$dem" "$work/out/o.tif"
expect_failure 2 "radius-limited radiative SVF" -- svf --radius 100 --definition radiative "$dem" "$work/out/o.tif"
expect_failure 3 "missing input" -- svf "$work/nope.tif" "$work/out/o.tif"
: >"$work/empty.tif"
expect_failure 3 "empty file" -- svf "$work/empty.tif" "$work/out/o.tif"
head -c 700 "$dem" >"$work/truncated.tif"
expect_failure 3 "truncated GeoTIFF" -- svf "$work/truncated.tif" "$work/out/o.tif"
echo "not a raster" >"$work/text.tif"
expect_failure 3 "text file" -- svf "$work/text.tif" "$work/out/o.tif"
gdal_create -q -of GTiff -outsize 20 20 -bands 3 -ot Byte -a_srs EPSG:32605 \
    -a_ullr 0 20 20 0 "$work/rgb.tif"
expect_failure 3 "RGB image" -- svf "$work/rgb.tif" "$work/out/o.tif"
gdal_create -q -of GTiff -outsize 20 20 -bands 1 -ot Float32 -burn -9999 -a_nodata -9999 \
    -a_srs EPSG:32605 -a_ullr 0 20 20 0 "$work/allnodata.tif"
expect_failure 3 "all-nodata DEM" -- svf "$work/allnodata.tif" "$work/out/o.tif"
gdal_create -q -of GTiff -outsize 1 1 -bands 1 -ot Float32 -burn 5 -a_srs EPSG:32605 \
    -a_ullr 0 1 1 0 "$work/one.tif"
expect_failure 3 "1x1 grid" -- svf "$work/one.tif" "$work/out/o.tif"
gdal_create -q -of GTiff -outsize 20 20 -bands 1 -ot Float32 -burn 5 "$work/plain.tif"
expect_failure 3 "raster without georeferencing" -- svf "$work/plain.tif" "$work/out/o.tif"
run svf --cell-size 2 "$work/plain.tif" "$work/plainsvf.tif"
tap_ok $rc "the same raster as a heightmap with --cell-size"
for bad in 0 -1 1e9 nan 3.5 ""; do
    expect_failure 2 "--directions '$bad'" -- svf --directions "$bad" "$dem" "$work/out/o.tif"
done
expect_failure 2 "unknown option '--frobnicate'" -- svf --frobnicate 3 "$dem" "$work/out/o.tif"
expect_failure 2 "unknown SVF definition" -- svf --definition fancy "$dem" "$work/out/o.tif"
expect_failure 2 "missing output argument" -- svf "$dem"
expect_failure 2 "unknown command" -- frobnicate "$dem" "$work/out/o.tif"
for sun in "--sun-azimuth 100" "--sun-elevation 20" "--time midday" \
    "--time 2026-06-21T12:00Z --sun-azimuth 100 --sun-elevation 20" ""; do
    # shellcheck disable=SC2086 # the sun's options, split on purpose
    expect_failure 2 "shadow with the sun given as '$sun'" -- shadow $sun "$dem" "$work/out/o.tif"
    [ ! -s "$work/stdout" ]
    tap_ok $? "shadow with the sun given as '$sun' is refused before the plan is shown"
done
run shadow --plan "$dem" "$work/out/o.tif"
[ "$rc" -eq 0 ] && grep -q '^sun_per_cell' "$work/stdout"
tap_ok $? "shadow --plan without a sun shows the plan (exit $rc)"
expect_failure 2 "output equal to the input" -- svf "$dem" "$dem"
expect_failure 4 "output in a missing folder" -- svf "$dem" "$work/out/missing/o.tif"
expect_failure 4 "output under a file" -- svf "$dem" "$dem/o.tif"
expect_failure 2 "bad creation option" -- svf -co NOEQUALS "$dem" "$work/out/o.tif"
expect_failure 2 "unknown output format" -- svf -of NOSUCHFORMAT "$dem" "$work/out/o.tif"
expect_failure 5 "device that does not exist" -- svf --device nosuchdevice "$dem" "$work/out/o.tif"

# A failed run leaves an existing output untouched.
echo "precious" >"$work/out/keep.tif"
run svf "$work/allnodata.tif" "$work/out/keep.tif"
[ "$rc" -eq 3 ] && [ "$(cat "$work/out/keep.tif")" = precious ] &&
    [ "$(ls -A "$work/out" | wc -l)" -eq 1 ]
tap_ok $? "a failed run does not replace an existing output"

tap_done
