#!/bin/bash
# Site horizon profiles from the command line (doc/pv-horizons.md): CSV,
# JSON and pvgis output parse back (awk and grep; jq or Python only as an
# extra check where present) with one value per step; a site's profile
# equals the horizon raster at its cell; an observer above the ground sees
# every horizon lower; sites outside the DEM or on nodata and bad options
# fail with one line on stderr and leave no output; skysweep sun
# --horizon-from marks the sun behind the terrain consistently.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-points.XXXXXX")
trap 'rm -rf "$work"' EXIT

# The DEM of test_cli.sh: 60 x 50 cells of 30 m in UTM 5N, a hill at
# column 30, row 25, nodata at cell (0, 0).
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
# Easting, northing of the centre of cell (column $1, row $2).
cell_xy() { echo "$((254325 + 30 * $1 + 15)),$((2153655 - 30 * $2 - 15))"; }

# ---- CSV ----------------------------------------------------------------------
site=$(cell_xy 20 30)
run horizon --point "$site" --point-crs dem --step 0.5 "$dem"
tap_ok $rc "--point to standard output exits 0 ($(head -c 200 "$work/stderr"))"
cp "$work/stdout" "$work/p.csv"
grep -q '^id,azimuth_deg,elevation_deg,distance_m,cast_lon,cast_lat,cast_height_m$' "$work/p.csv"
tap_ok $? "CSV names its columns"
grep -q '^# site id=site lon=-155\.[0-9]* lat=19\.[0-9]* ground_height_m=[0-9.]* observer_height_m=0\.000$' "$work/p.csv"
tap_ok $? "CSV header carries the site: $(grep '^# site' "$work/p.csv")"
grep -q '^# model: interpolated lines, earth curvature and refraction off; step 0.5 deg$' "$work/p.csv"
tap_ok $? "CSV header states the model: $(grep '^# model' "$work/p.csv")"
awk -F, '!/^#/ && NR > 1 && $1 != "id" {
    n++
    if (NF != 7 || $1 != "site" || $2 != (n - 1) * 0.5 || $3 < -90 || $3 > 90 || $4 < 0) bad++
    if ($4 > 0 && ($5 > -155 || $5 < -156 || $6 < 19 || $6 > 20 || $7 < 99)) bad++
}
END { exit !(n == 720 && bad == 0) }' "$work/p.csv"
tap_ok $? "CSV parses back: 720 rows of 7 fields at azimuths 0, 0.5, ..., casting points on the DEM"

# ---- the profile equals the horizon raster at the site's cell --------------------
run horizon --directions 8 --north grid "$dem" "$work/h8.tif"
tap_ok $rc "horizon raster with 8 directions"
run horizon --point "$site" --point-crs dem --north grid --step 45 "$dem" "$work/p45.csv"
tap_ok $rc "--point with OUTPUT writes a file"
for b in 1 2 3 4 5 6 7 8; do
    gdallocationinfo -valonly -b $b "$work/h8.tif" 20 30
done >"$work/raster.txt"
awk -F, '!/^#/ && $1 == "site" { print $3 }' "$work/p45.csv" >"$work/point.txt"
paste -d' ' "$work/raster.txt" "$work/point.txt" | awk '{
    n++; d = $1 - $2; if (d < 0) d = -d; if (d > worst) worst = d }
END { printf "worst %.2e deg over %d azimuths\n", worst, n; exit !(n == 8 && worst < 5.7e-4) }' \
    >"$work/cmp.txt"
tap_ok $? "point profile == raster at cell (20, 30) within 1e-5 rad: $(cat "$work/cmp.txt")"

# ---- observer height --------------------------------------------------------------
run horizon --point "$site" --point-crs dem --step 10 --height 2 "$dem" "$work/p2.csv"
run horizon --point "$site" --point-crs dem --step 10 "$dem" "$work/p0.csv"
paste -d, <(grep '^site,' "$work/p0.csv") <(grep '^site,' "$work/p2.csv") |
    awk -F, '{ n++; if (!($10 < $3)) bad++ } END { exit !(n == 36 && bad == 0) }'
tap_ok $? "an eye 2 m above the ground sees every azimuth's horizon lower"

# ---- JSON ---------------------------------------------------------------------------
run horizon --point "$site" --point-crs dem --step 2 --format json --curvature on "$dem" "$work/p.json"
tap_ok $rc "--format json exits 0"
for key in azimuth_deg elevation_deg distance_m cast_lon cast_lat cast_height_m; do
    count=$(grep "\"$key\": \[" "$work/p.json" | sed 's/.*\[//; s/\].*//' | awk -F, '{ print NF }')
    [ "$count" = 180 ]
    tap_ok $? "JSON column $key holds 180 values ($count)"
done
grep -q '"model": "interpolated lines, earth curvature on (R = [0-9]* m, refraction k = 0.130' "$work/p.json"
tap_ok $? "JSON states curvature and refraction"
if command -v jq >/dev/null; then
    [ "$(jq '.sites[0].elevation_deg | length' "$work/p.json")" = 180 ] &&
        [ "$(jq -r '.sites[0].id' "$work/p.json")" = site ]
    tap_ok $? "jq reads the JSON back"
elif command -v python3 >/dev/null; then
    python3 -c 'import json, sys; d = json.load(open(sys.argv[1])); assert len(d["sites"][0]["elevation_deg"]) == 180' "$work/p.json"
    tap_ok $? "Python reads the JSON back"
else
    tap_skip "JSON read back by a parser" "neither jq nor python3"
fi

# ---- pvgis --------------------------------------------------------------------------
for step in 7.5 1 0.5; do
    run horizon --point "$site" --point-crs dem --step $step --format pvgis "$dem"
    want=$(awk -v s=$step 'BEGIN { print 360 / s }')
    got=$(awk -F, 'NF { print NF; lines++ } END { if (lines != 1) print "lines", lines }' "$work/stdout")
    [ $rc -eq 0 ] && [ "$got" = "$want" ] && ! grep -q '[^-0-9.,]' <(tr -d '\n' <"$work/stdout")
    tap_ok $? "pvgis at step $step: one line of $want numbers ($got)"
done

# ---- several sites, lon/lat in WGS84 --------------------------------------------------
# WGS84 longitude,latitude of the centre of cell (column $1, row $2).
cell_ll() {
    echo "$(cell_xy "$1" "$2" | tr , ' ')" | gdaltransform -s_srs EPSG:32605 -t_srs EPSG:4326 \
        -output_xy | awk '{ printf "%.9f,%.9f", $1, $2 }'
}
ll=$(cell_ll 20 30)
{
    echo "id,lat,lon,height"
    echo "ridge,$(echo "$ll" | awk -F, '{ print $2 "," $1 }'),"
    echo "# a comment line"
    echo "top,$(cell_ll 30 25 | awk -F, '{ print $2 "," $1 }'),1.5"
    echo "low,$(cell_ll 5 45 | awk -F, '{ print $2 "," $1 }'),0"
} >"$work/sites.csv"
run horizon --points "$work/sites.csv" --step 5 "$dem" "$work/many.csv"
tap_ok $rc "--points with three sites ($(head -c 200 "$work/stderr"))"
[ "$(grep -c '^# site' "$work/many.csv")" = 3 ] && [ "$(grep -c '^ridge,' "$work/many.csv")" = 72 ] &&
    [ "$(grep -c '^top,' "$work/many.csv")" = 72 ] && [ "$(grep -c '^low,' "$work/many.csv")" = 72 ]
tap_ok $? "three sites, 72 rows each"
echo "$ll" | awk -F, -v line="$(grep '^# site id=ridge' "$work/many.csv")" '{
    split(line, f, /[ =]/); for (i in f) { if (f[i] == "lon") lon = f[i + 1]; if (f[i] == "lat") lat = f[i + 1] }
    d1 = lon - $1; d2 = lat - $2; exit !(d1 * d1 < 1e-14 && d2 * d2 < 1e-14) }'
tap_ok $? "a WGS84 site comes back at its longitude, latitude"
grep -q '^# site id=top .* observer_height_m=1\.500$' "$work/many.csv"
tap_ok $? "a site's height column sets its observer height"
mkdir "$work/pv"
run horizon --points "$work/sites.csv" --step 7.5 --format pvgis "$dem" "$work/pv"
[ $rc -eq 0 ] && [ "$(ls "$work/pv" | tr '\n' ' ')" = "low.txt ridge.txt top.txt " ] &&
    [ "$(awk -F, '{ print NF }' "$work/pv/top.txt")" = 48 ]
tap_ok $? "pvgis with --points writes one file of 48 values per site: $(ls "$work/pv" | tr '\n' ' ')"

# ---- refusals -------------------------------------------------------------------------
mkdir -p "$work/out"
expect_failure() { # CODE DESCRIPTION -- ARGS...
    local code=$1 what=$2
    shift 3
    rm -rf "$work/out/"* "$work/out/".*.tmp 2>/dev/null
    run "$@"
    local lines leftovers
    lines=$(wc -l <"$work/stderr")
    leftovers=$(ls -A "$work/out" | wc -l)
    [ "$rc" -eq "$code" ] && [ "$lines" -eq 1 ] && [ "$leftovers" -eq 0 ]
    tap_ok $? "$what: exit $rc (want $code), $lines stderr line(s), $leftovers file(s) left: $(head -c 200 "$work/stderr")"
}
expect_failure 2 "site outside the DEM" -- horizon --point -155.2,19.3 "$dem" "$work/out/o.csv"
grep -q 'lies outside the DEM' "$work/stderr"
tap_ok $? "the message says the site is outside the DEM"
expect_failure 2 "site on nodata" -- horizon --point "$(cell_xy 0 0)" --point-crs dem "$dem" "$work/out/o.csv"
grep -q 'nodata' "$work/stderr"
tap_ok $? "the message says the site is on nodata"
printf 'id,lon,lat\nin,%s\nout,-155.2,19.3\n' "$ll" >"$work/outside.csv"
expect_failure 2 "one of several sites outside" -- horizon --points "$work/outside.csv" "$dem" "$work/out/o.csv"
grep -q "id 'out'" "$work/stderr"
tap_ok $? "the message names the site"
expect_failure 2 "step not dividing 360" -- horizon --point "$ll" --step 7 "$dem" "$work/out/o.csv"
expect_failure 2 "malformed --point" -- horizon --point 12.5 "$dem" "$work/out/o.csv"
expect_failure 2 "--point and --points together" -- horizon --point "$ll" --points "$work/sites.csv" "$dem" "$work/out/o.csv"
expect_failure 2 "pvgis for several sites into a file" -- horizon --points "$work/sites.csv" --format pvgis "$dem" "$work/out/o.txt"
printf 'name,lon,lat\na,1,2\n' >"$work/badhead.csv"
expect_failure 3 "sites file without an id column" -- horizon --points "$work/badhead.csv" "$dem" "$work/out/o.csv"
printf 'id,lon,lat\na,%s\na,%s\n' "$ll" "$ll" >"$work/dup.csv"
expect_failure 3 "duplicate site ids" -- horizon --points "$work/dup.csv" "$dem" "$work/out/o.csv"
expect_failure 3 "missing sites file" -- horizon --points "$work/nope.csv" "$dem" "$work/out/o.csv"
# A sites file is a regular file of at most 256 MiB, refused before it is
# read: /dev/zero was read for ever (12.7 GB in 20 s), a FIFO blocked, a huge
# file would have been held whole. The old build is stopped by timeout.
mkfifo "$work/fifo.csv"
printf 'id,lon,lat\n' >"$work/huge.csv"
truncate -s 300M "$work/huge.csv"
for f in /dev/zero "$work/fifo.csv" "$work/huge.csv"; do
    start=$(date +%s)
    timeout -s KILL 10 "$SKYSWEEP" horizon --points "$f" "$dem" "$work/out/o.csv" \
        >"$work/stdout" 2>"$work/stderr"
    rc=$?
    took=$(($(date +%s) - start))
    [ "$rc" -eq 3 ] && [ "$(wc -l <"$work/stderr")" -eq 1 ] && grep -q '256 MiB' "$work/stderr" &&
        [ -z "$(ls -A "$work/out")" ]
    tap_ok $? "sites file ${f##*/}: exit $rc (want 3) in $took s, naming the cap: $(head -c 200 "$work/stderr")"
done
rm -f "$work/huge.csv"
expect_failure 2 "unknown --point-crs" -- horizon --point "$ll" --point-crs EPSG:999999 "$dem" "$work/out/o.csv"

# ---- skysweep sun --horizon-from ------------------------------------------------------
run sun --at "$ll" --time 2026-12-21T15:00Z/P1D/PT15M --horizon-from "$dem"
tap_ok $rc "sun --horizon-from exits 0 ($(head -c 200 "$work/stderr"))"
awk -F, '/^time,/ { ok = ($8 == "horizon_elevation" && $9 == "behind_terrain"); next }
/^[0-9]/ { n++; want = ($4 < $8) ? 1 : 0; if ($9 != want || $8 < -90 || $8 > 90) bad++; behind += $9 }
END { exit !(ok && n == 96 && !bad && behind > 0 && behind < n) }' "$work/stdout"
tap_ok $? "sun table: behind_terrain = apparent elevation below the horizon, on 96 rows"
expect_failure 2 "sun with a site outside the DEM" -- sun --at -155.2,19.3 --time 2026-12-21T15:00Z --horizon-from "$dem"

tap_done
