#!/bin/bash
# Site horizon profiles from the command line (doc/pv-horizons.md): CSV,
# JSON and pvgis output parse back (awk and grep; jq or Python only as an
# extra check where present) with one value per step; a site's profile
# equals the horizon raster at its cell; an observer above the ground sees
# every horizon lower; sites outside the DEM or on nodata and bad options
# fail with one line on stderr and leave no output; skysweep sun
# --horizon-from marks the sun behind the terrain consistently; with
# --canopy a crown of known size gives its closed-form crown elevation.
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

# ---- horizon files for PV software -------------------------------------------------
# Each file is read back by a reader written here from its tool's documentation
# (doc/pv-horizons.md, Formats), independently of the writers: it turns the
# tool's azimuths back into degrees clockwise from north, and the elevations
# must equal the CSV profile's (clipped at 0, as the tools take 0..90) within
# the files' rounding.
# PVsyst's standard CSV import: lines holding text are comments; one azimuth,
# height pair a line (comma, semicolon, tab or space); the import dialog asks
# for the azimuths' rotation and north, which the file's comment gives.
read_pvsyst() {
    awk -F'[,; \t]' '/on import choose/ { cw = /choose Clockwise/; north = $0
            sub(/.*North azimuth /, "", north); north += 0; told = 1 }
        /[A-Za-z]/ { next }
        NF { if (NF != 2 || $1 < -180 || $1 > 180 || $2 < 0 || $2 > 90 || (n && $1 <= last)) bad = 1
            last = $1; n++; a = cw ? $1 - north : north - $1; a = (a % 360 + 360) % 360
            if (a in seen && seen[a] != $2) bad = 1
            seen[a] = $2; if (!(a in printed)) { printed[a] = 1; print a, $2 } }
        END { if (bad || !told) print "bad" }' "$1"
}
# PV*SOL .hor: two columns separated by a space, horizontal angle -180 (north),
# -90 (east), 0 (south), 90 (west) to 179, elevation 0..90.
read_pvsol() {
    awk -F' ' '{ if (NF != 2 || $1 < -180 || $1 > 179 || $2 < 0 || $2 > 90) bad = 1
        print ($1 + 180) % 360, $2 } END { if (bad) print "bad" }' "$1"
}
# HelioScope's SunEye CSV upload: the columns labelled "Compass Heading (0-360;
# North=0; East=90)" and "Average Elevation (0-90) Session"; the -180..180
# azimuth column (0 south) must agree with the heading.
read_helioscope() {
    awk -F, '!h { for (i = 1; i <= NF; i++) {
            if ($i == "Compass Heading (0-360; North=0; East=90)") hc = i
            if ($i == "Average Elevation (0-90) Session") ec = i
            if ($i ~ /^Azimuth \(-180 to 180; South=0/) ac = i }
        if (hc && ec && ac) h = 1; next }
    { if ($ec < 0 || $ec > 90 || ($ac + 180) % 360 != $hc + 0) bad = 1; print $hc + 0, $ec }
    END { if (!h || bad) print "bad" }' "$1"
}
# SAM's azimuth by altitude table (SSC shading:azal): first row the solar
# azimuths (clockwise from north), first column the altitudes, cells the beam
# loss in percent. A cell holds the part of the degree of altitude above its
# row that lies below the horizon, so the horizon is a column's losses / 100.
read_sam() {
    awk -F, 'NR == 1 { for (i = 2; i <= NF; i++) az[i] = $i; n = NF; next }
    { if ($1 != NR - 2 || NF != n) bad = 1
      for (i = 2; i <= NF; i++) { if ($i < 0 || $i > 100) bad = 1; sum[i] += $i / 100 } }
    END { if (NR != 92 || az[n] != 360) bad = 1
          for (i = 2; i < n; i++) print az[i], sum[i]; if (bad) print "bad" }' "$1"
}
# "azimuth elevation" lines from CSV profile $1 (elevations clipped at 0).
csv_profile() { awk -F, '!/^#/ && $1 != "id" { print $2 + 0, ($3 > 0 ? $3 : 0) }' "$1"; }
# Compares "azimuth elevation" lists $1 (reference) and $2 within tolerance $3.
same_profile() {
    awk -v tol="$3" 'FNR == NR { ref[$1] = $2; n++; next }
        $1 == "bad" { bad = 1; next }
        { m++; if (!($1 in ref)) bad = 1; d = $2 - ref[$1]; if (d < 0) d = -d; if (d > worst) worst = d }
        END { printf "%d azimuths, worst %.4f deg", m, worst; exit !(!bad && m == n && worst <= tol) }' "$1" "$2"
}
pv_formats="pvsyst pvsol helioscope sam"
pv_extension() { case $1 in pvgis) echo txt ;; pvsol) echo hor ;; *) echo csv ;; esac; }
pv_tolerance() { case $1 in sam) echo 0.0011 ;; *) echo 0.0051 ;; esac; }

run horizon --point "$site" --point-crs dem --step 1 "$dem" "$work/ref.csv"
csv_profile "$work/ref.csv" >"$work/ref.txt"
for f in $pv_formats; do
    run horizon --point "$site" --point-crs dem --step 1 --format $f "$dem" "$work/site.$f"
    rm -f "$work/cmp.txt"
    [ $rc -eq 0 ] && "read_$f" "$work/site.$f" >"$work/back.txt" &&
        same_profile "$work/ref.txt" "$work/back.txt" "$(pv_tolerance $f)" >"$work/cmp.txt"
    tap_ok $? "$f round-trips through its tool's convention to the CSV profile: $(cat "$work/cmp.txt")"
done
# The same at a 7.5-degree step (PVGIS's 48 directions) and from standard output.
run horizon --point "$site" --point-crs dem --step 7.5 "$dem" "$work/ref75.csv"
csv_profile "$work/ref75.csv" >"$work/ref75.txt"
for f in $pv_formats; do
    run horizon --point "$site" --point-crs dem --step 7.5 --format $f "$dem"
    rm -f "$work/cmp.txt"
    [ $rc -eq 0 ] && "read_$f" "$work/stdout" >"$work/back.txt" &&
        same_profile "$work/ref75.txt" "$work/back.txt" "$(pv_tolerance $f)" >"$work/cmp.txt"
    tap_ok $? "$f at step 7.5 on standard output: $(cat "$work/cmp.txt")"
done
grep -q '^Latitude 19\.[0-9]*, Longitude -155\.[0-9]*$' "$work/site.pvsyst" &&
    grep -q 'Clockwise and North azimuth 180' "$work/site.pvsyst"
tap_ok $? "the PVsyst file names its site and how to import its azimuths"

# A flat open site: 41 x 41 cells at 100 m, the site in the middle; and the
# same with a wall 50 m high 150 m east of the site (columns 25-27, rows 15-25).
flat_dem() { # NAME WALL(0/1)
    awk -v wall=$2 'BEGIN {
        print "ncols 41"; print "nrows 41"; print "xllcorner 254325"; print "yllcorner 2152155"
        print "cellsize 30"; print "NODATA_value -9999"
        for (r = 0; r < 41; r++) { line = ""
            for (c = 0; c < 41; c++) line = line ((wall && c >= 25 && c <= 27 && r >= 15 && r <= 25) ? "150 " : "100 ")
            print line } }' >"$work/$1.asc"
    gdal_translate -q -ot Float32 -a_srs EPSG:32605 "$work/$1.asc" "$work/$1.tif"
}
flat_dem flat 0
flat_dem wall 1
mid="$((254325 + 30 * 20 + 15)),$((2152155 + 41 * 30 - 30 * 20 - 15))"
for f in pvgis $pv_formats; do
    run horizon --point "$mid" --point-crs dem --step 5 --format $f "$work/flat.tif" "$work/flat.$f"
    case $f in
    pvgis) tr ',' '\n' <"$work/flat.$f" | awk '{ print 5 * (NR - 1), $1 }' >"$work/back.txt" ;;
    *) "read_$f" "$work/flat.$f" >"$work/back.txt" ;;
    esac
    [ $rc -eq 0 ] && awk '$1 == "bad" || $2 != 0 { bad++ } END { exit !(NR == 72 && !bad) }' "$work/back.txt"
    tap_ok $? "$f: a flat open site gives an all-zero horizon ($(wc -l <"$work/back.txt") azimuths)"
done
# The wall stands east: 18.4 degrees (atan(50 / 150)) at azimuth 90, nothing
# north, south or west. In the tools' own conventions east is PVsyst's and
# PV*SOL's -90, the SunEye azimuth -90 with compass heading 90, SAM's column 90.
run horizon --point "$mid" --point-crs dem --step 5 "$work/wall.tif" "$work/wall.csv"
awk -F, '$1 == "site" && ($2 == 90 && ($3 < 18 || $3 > 18.5) || ($2 == 0 || $2 == 180 || $2 == 270) && $3 != 0) { bad++ }
    END { exit bad > 0 }' "$work/wall.csv"
tap_ok $? "the wall shows at azimuth 90 in the CSV: $(grep '^site,90,' "$work/wall.csv")"
run horizon --point "$mid" --point-crs dem --step 5 --format pvsyst "$work/wall.tif" "$work/wall.pvsyst"
awk -F, '$1 == -90 && $2 > 18 { east = 1 } ($1 == 0 || $1 == 90 || $1 == 180 || $1 == -180) && $2 != 0 { bad = 1 }
    END { exit !(east && !bad) }' "$work/wall.pvsyst"
tap_ok $? "PVsyst: the wall at azimuth -90 (east), 0 at south, west and north: $(grep '^-90,' "$work/wall.pvsyst")"
# South of the equator PVsyst reckons from the north, west +90 and east -90:
# the same wall on a grid in UTM 5S (about 70.6 S).
gdal_translate -q -ot Float32 -a_srs EPSG:32705 "$work/wall.asc" "$work/wall_s.tif"
run horizon --point "$mid" --point-crs dem --step 5 --format pvsyst "$work/wall_s.tif" "$work/wall_s.pvsyst"
awk -F, '$1 == -90 && $2 > 18 { east = 1 } ($1 == 0 || $1 == 90 || $1 == 180 || $1 == -180) && $2 != 0 { bad = 1 }
    /choose Counterclockwise and North azimuth 0/ { told = 1 } END { exit !(east && told && !bad) }' "$work/wall_s.pvsyst"
tap_ok $? "PVsyst south of the equator: the wall at -90 (east), azimuths from the north, told to the import"
run horizon --point "$mid" --point-crs dem --step 5 "$work/wall_s.tif" "$work/wall_s.csv"
csv_profile "$work/wall_s.csv" >"$work/ref_s.txt"
read_pvsyst "$work/wall_s.pvsyst" >"$work/back.txt"
same_profile "$work/ref_s.txt" "$work/back.txt" 0.0051 >"$work/cmp.txt"
tap_ok $? "PVsyst south of the equator round-trips: $(cat "$work/cmp.txt")"
run horizon --point "$mid" --point-crs dem --step 5 --format pvsol "$work/wall.tif" "$work/wall.pvsol"
awk '$1 == -90 && $2 > 18 { east = 1 } ($1 == 0 || $1 == 90 || $1 == -180) && $2 != 0 { bad = 1 }
    END { exit !(east && !bad) }' "$work/wall.pvsol"
tap_ok $? "PV*SOL: the wall at -90 (east): $(grep '^-90 ' "$work/wall.pvsol")"
run horizon --point "$mid" --point-crs dem --step 5 --format helioscope "$work/wall.tif" "$work/wall.helioscope"
grep -q '^-90,90,18\.[0-9]*$' "$work/wall.helioscope" && grep -q '^90,270,0\.00$' "$work/wall.helioscope"
tap_ok $? "HelioScope: the wall at azimuth -90, compass heading 90: $(grep '^-90,' "$work/wall.helioscope")"
run horizon --point "$mid" --point-crs dem --step 5 --format sam "$work/wall.tif" "$work/wall.sam"
awk -F, 'NR == 1 { for (i = 2; i <= NF; i++) az[i] = $i; next }
    { for (i = 2; i <= NF; i++) if ($i > 0) { lost[az[i]]++; top[az[i]] = $1 } }
    END { exit !(lost[90] == 19 && top[90] == 18 && !(0 in lost) && !(180 in lost) && !(270 in lost) && !(360 in lost)) }' \
    "$work/wall.sam"
tap_ok $? "SAM: beam losses in the azimuth 90 column up to altitude 18, none north, south or west"

# --points: one file per site, ID plus the tool's extension.
for f in $pv_formats; do
    mkdir "$work/pv_$f"
    run horizon --points "$work/sites.csv" --step 7.5 --format $f "$dem" "$work/pv_$f"
    e=$(pv_extension $f)
    [ $rc -eq 0 ] && [ "$(ls "$work/pv_$f" | tr '\n' ' ')" = "low.$e ridge.$e top.$e " ] &&
        "read_$f" "$work/pv_$f/top.$e" | awk '$1 == "bad" { bad = 1 } END { exit !(NR == 48 && !bad) }'
    tap_ok $? "$f with --points writes one file of 48 directions per site: $(ls "$work/pv_$f" | tr '\n' ' ')"
done
expect_failure 2 "pvsyst for several sites into a file" -- horizon --points "$work/sites.csv" --format pvsyst "$dem" "$work/out/o.csv"

# ---- near and far merged (--far) --------------------------------------------------------
# A DEM merged with itself is itself.
run horizon --point "$site" --point-crs dem --step 2 "$dem" "$work/self0.csv"
run horizon --point "$site" --point-crs dem --step 2 --far "$dem" "$dem" "$work/self1.csv"
[ $rc -eq 0 ] && diff <(grep '^site,' "$work/self0.csv") <(grep '^site,' "$work/self1.csv") >/dev/null
tap_ok $? "a DEM merged with itself gives its own profile, every column ($(head -c 200 "$work/stderr"))"
grep -q "^# skysweep .* horizon profiles of near .*dem.tif merged with the far terrain .*dem.tif (the larger elevation per azimuth)$" "$work/self1.csv" &&
    grep -q '^# site id=site .* far_ground_height_m=[0-9.]* far_observer_height_m=0\.000$' "$work/self1.csv"
tap_ok $? "the CSV states both sources and the site on the far DEM"
# A flat near DSM and a far terrain DEM in another CRS and grid (WGS84, about
# 90 m) holding a ridge 600 m high 5 km south of the site: the merged profile
# has the far DEM's ridge at the south and the near zeros elsewhere.
awk -v ys=2152770 'BEGIN {
    print "ncols 200"; print "nrows 200"; print "xllcorner 245940"; print "yllcorner 2143770"
    print "cellsize 90"; print "NODATA_value -9999"
    for (r = 0; r < 200; r++) { y = 2143770 + 90 * (200 - r) - 45; line = ""
        for (c = 0; c < 200; c++) line = line ((y > ys - 5200 && y < ys - 4800) ? "700 " : "100 ")
        print line } }' >"$work/far.asc"
gdal_translate -q -ot Float32 -a_srs EPSG:32605 "$work/far.asc" "$work/far_utm.tif"
gdalwarp -q -t_srs EPSG:4326 -r bilinear "$work/far_utm.tif" "$work/far.tif"
mid_ll=$(echo "$mid" | tr , ' ' | gdaltransform -s_srs EPSG:32605 -t_srs EPSG:4326 -output_xy |
    awk '{ printf "%.9f,%.9f", $1, $2 }')
run horizon --point "$mid_ll" --step 1 "$work/far.tif" "$work/faronly.csv"
tap_ok $rc "the far DEM's own profile at the site ($(head -c 200 "$work/stderr"))"
run horizon --point "$mid_ll" --step 1 --far "$work/far.tif" "$work/flat.tif" "$work/merged.csv"
tap_ok $rc "a flat DSM merged with the far DEM ($(head -c 200 "$work/stderr"))"
far_south=$(awk -F, '$1 == "site" && $2 == 180 { print $3 }' "$work/faronly.csv")
awk -F, -v want="$far_south" '$1 == "site" { n++
        if ($2 == 180 && !($3 == want && $3 > 6 && $4 > 4500 && $4 < 5500)) bad++
        if (($2 < 90 || $2 > 270) && $3 != 0) bad++ }
    END { exit !(n == 360 && !bad) }' "$work/merged.csv"
tap_ok $? "the merged profile holds the ridge at the south ($far_south deg, as the far DEM alone) and the flat zeros to the north"
run horizon --point "$mid_ll" --step 1 --format pvsyst --far "$work/far.tif" "$work/flat.tif" "$work/merged.pvsyst"
grep -q "^0,$(printf '%.2f' "$far_south")$" "$work/merged.pvsyst" && grep -q 'far terrain' "$work/merged.pvsyst"
tap_ok $? "the PVsyst file carries the ridge at its south (0) and names both sources"
# Many sites with --far, into a folder of PV files and into JSON.
printf 'id,lon,lat\nmid,%s\nnear_mid,%s\n' "$mid_ll" \
    "$(echo "$mid_ll" | awk -F, '{ printf "%.9f,%.9f", $1 + 0.0001, $2 + 0.0001 }')" >"$work/fsites.csv"
mkdir "$work/fpv"
run horizon --points "$work/fsites.csv" --step 1 --format pvsol --far "$work/far.tif" "$work/flat.tif" "$work/fpv"
[ $rc -eq 0 ] && [ "$(ls "$work/fpv" | tr '\n' ' ')" = "mid.hor near_mid.hor " ] &&
    grep -q "^0 $(printf '%.2f' "$far_south")$" "$work/fpv/mid.hor"
tap_ok $? "--points with --far writes each site's merged PV*SOL file (the ridge at 0, south): $(ls "$work/fpv" | tr '\n' ' ')"
run horizon --points "$work/fsites.csv" --step 10 --format json --far "$work/far.tif" "$work/flat.tif" "$work/f.json"
[ $rc -eq 0 ] && grep -q '"far_dem": ".*far.tif"' "$work/f.json"
tap_ok $? "JSON names the far DEM"
# A far DEM standing 50 m above the eye at the site: the far horizon is seen
# from its own ground.
awk 'NR <= 6 { print; next } { for (i = 1; i <= NF; i++) $i += 50; print }' "$work/far.asc" >"$work/far_hi.asc"
gdal_translate -q -ot Float32 -a_srs EPSG:32605 "$work/far_hi.asc" "$work/far_hi.tif"
run horizon --point "$mid_ll" --step 10 --far "$work/far_hi.tif" "$work/flat.tif" "$work/hi.csv"
[ $rc -eq 0 ] && grep -q '^# site .* ground_height_m=100\.000 observer_height_m=0\.000 far_ground_height_m=150\.000 far_observer_height_m=0\.000$' "$work/hi.csv"
tap_ok $? "an eye below the far DEM's ground looks from that ground: $(grep '^# site' "$work/hi.csv")"
expect_failure 2 "--far with --north grid" -- horizon --point "$mid_ll" --north grid --far "$work/far.tif" "$work/flat.tif" "$work/out/o.csv"
expect_failure 2 "--far for horizon rasters" -- horizon --far "$work/far.tif" "$work/flat.tif" "$work/out/o.tif"
expect_failure 2 "a site outside the far DEM" -- horizon --point "$(cell_xy 50 10)" --point-crs dem --far "$work/flat.tif" "$dem" "$work/out/o.csv"
grep -q 'far DEM' "$work/stderr"
tap_ok $? "the message names the far DEM"
awk 'BEGIN { print "ncols 5\nnrows 5\nxllcorner 0\nyllcorner 0\ncellsize 1"; for (r = 0; r < 5; r++) print "1 1 1 1 1" }' >"$work/nogeo.asc"
expect_failure 3 "a far DEM without a CRS" -- horizon --point "$mid_ll" --far "$work/nogeo.asc" "$work/flat.tif" "$work/out/o.csv"
cp "$work/far.tif" "$work/out/far.tif"
run horizon --point "$mid_ll" --far "$work/out/far.tif" "$work/flat.tif" "$work/out/far.tif"
[ $rc -eq 2 ] && cmp -s "$work/far.tif" "$work/out/far.tif" && grep -q "also an input.*--far" "$work/stderr"
tap_ok $? "the far DEM named as the output: exit $rc, the DEM untouched: $(head -c 200 "$work/stderr")"

# ---- trees: --canopy ------------------------------------------------------------------
# Flat ground (10 m) of 101 x 101 cells of 1 m, in a transverse Mercator with
# scale 1 on its central meridian (UTM's 0.9996 would scale every distance),
# and a crown of radius R = 3, height H = 8 (the cells whose centres lie
# within R of cell (50, 50)) north of the site at cell (50, 70), d = 20 m
# away; a one-cell tree of 6 m at cell (20, 80) stands over a second site.
tm="+proj=tmerc +lat_0=0 +lon_0=-153 +k=1 +x_0=500000 +y_0=0 +datum=WGS84 +units=m"
tree_raster() { # NAME AWK-EXPRESSION-OF-c-AND-r
    awk -v name="$1" 'BEGIN { print "ncols 101\nnrows 101\nxllcorner 500000\nyllcorner 2100000\ncellsize 1" }
    END { for (r = 0; r < 101; r++) { l = ""; for (c = 0; c < 101; c++) l = l ('"$2"') " "; print l } }' </dev/null >"$work/$1.asc"
    gdal_translate -q -ot Float32 -a_srs "$tm" "$work/$1.asc" "$work/$1.tif"
}
tree_raster tflat 10
tree_raster tzeros 0
tree_raster tcrown '((c - 50) ^ 2 + (r - 50) ^ 2 <= 9) ? 8 : (c == 20 && r == 80) ? 6 : 0'
tsite=500050.5,2100030.5
run horizon --point "$tsite" --point-crs dem --step 5 --north grid "$work/tflat.tif"
cp "$work/stdout" "$work/solid.csv"
run horizon --point "$tsite" --point-crs dem --step 5 --north grid --canopy "$work/tzeros.tif" "$work/tflat.tif"
cp "$work/stdout" "$work/zeros.csv"
# Without the canopy's comment line and its two columns the output is today's.
grep -v '^# canopy_elevation_deg' "$work/zeros.csv" | sed 's/,canopy_elevation_deg,crown_elevation_deg$//; /^site,/s/,[^,]*,[^,]*$//' |
    cmp -s - "$work/solid.csv" &&
    awk -F, '/^site,/ { n++; if (NF != 9 || $8 != $3 || $9 != -90) bad++ } END { exit !(n == 72 && !bad) }' "$work/zeros.csv"
tap_ok $? "--canopy of zeros: the solid columns byte for byte, canopy_elevation_deg = elevation_deg, crown_elevation_deg -90"
run horizon --point "$tsite" --point-crs dem --step 90 --north grid --canopy "$work/tcrown.tif" "$work/tflat.tif"
cp "$work/stdout" "$work/crown.csv"
# The ray north enters the crown's nearest cell (row 53) at d - R - 1/2 =
# 16.5 m: atan(8 / 16.5) = 25.8664 deg. The true cylinder's edge is at
# d - R = 17 m, atan(8 / 17) = 25.2011 deg; a raster crown's edge lies
# within half a diagonal (0.71 m) of it, atan(8 / 16.29) = 26.15 deg at most.
awk -F, '$1 == "site" && $2 == 0 { n0 = ($9 - 25.8664 < 1e-3 && 25.8664 - $9 < 1e-3 && $8 == $9 && $9 > 25.2011 && $9 < 26.15) }
$1 == "site" && $2 == 180 { n180 = ($9 == -90 && $8 == $3) }
END { exit !(n0 && n180) }' "$work/crown.csv"
tap_ok $? "a crown 20 m north: crown_elevation_deg $(awk -F, '$1 == "site" && $2 == 0 { print $9 }' "$work/crown.csv") at azimuth 0 (atan(8 / 16.5) = 25.8664; the cylinder's atan(8 / 17) = 25.20), -90 at 180"
# Off the axes: a march along the ray in 0.1 mm steps, nearest cells, finds
# the first crown cell; the exact cell-by-cell ray agrees within its step.
run horizon --point "$tsite" --point-crs dem --step 1 --north grid --canopy "$work/tcrown.tif" "$work/tflat.tif"
awk -F, '$1 == "site" && ($2 == 3 || $2 == 7 || $2 == 352 || $2 == 45 || $2 == 90) {
    a = $2 * atan2(1, 1) / 45; want = -90
    for (t = 0.00005; t < 60; t += 0.0001) {
        c = int(50 + t * sin(a) + 0.5); r = int(70 - t * cos(a) + 0.5)
        if ((c - 50) ^ 2 + (r - 50) ^ 2 <= 9) { want = atan2(8, t) * 45 / atan2(1, 1); break }
    }
    d = $9 - want; if (d < 0) d = -d
    if (d > 0.001) bad++; n++
}
END { exit !(n == 5 && !bad) }' "$work/stdout"
tap_ok $? "off the axes (3, 7, 352, 45, 90 deg) the crown elevation equals a 0.1 mm march along the ray within 0.001 deg"
run horizon --point "$tsite" --point-crs dem --step 90 --north grid --height 2 --canopy "$work/tcrown.tif" "$work/tflat.tif"
awk -F, '$1 == "site" && $2 == 0 { ok = ($9 - 19.9831 < 1e-3 && 19.9831 - $9 < 1e-3) } END { exit !ok }' "$work/stdout"
tap_ok $? "an eye 2 m up sees the crown top lower: atan(6 / 16.5) = 19.9831 deg"
run horizon --point 500020.5,2100020.5 --point-crs dem --step 10 --canopy "$work/tcrown.tif" "$work/tflat.tif"
awk -F, '$1 == "site" { n++; bad += ($9 != -90) } END { exit !(n == 36 && !bad) }' "$work/stdout"
tap_ok $? "a site under its own one-cell crown does not see it: -90 at every azimuth"
run horizon --point "$tsite" --point-crs dem --step 10 --north grid --canopy "$work/tcrown.tif" --format json "$work/tflat.tif"
grep -q '"canopy_elevation_deg": \[25\.866' "$work/stdout" && grep -q '"crown_elevation_deg": \[25\.866' "$work/stdout" &&
    { ! command -v python3 >/dev/null || python3 -c 'import json, sys; json.load(sys.stdin)' <"$work/stdout"; }
tap_ok $? "JSON carries canopy_elevation_deg and crown_elevation_deg"
run horizon --point "$tsite" --point-crs dem --step 10 --north grid --format pvgis "$work/tflat.tif"
cp "$work/stdout" "$work/solid.pvgis"
run horizon --point "$tsite" --point-crs dem --step 10 --north grid --format pvgis --canopy "$work/tcrown.tif" "$work/tflat.tif"
cmp -s "$work/stdout" "$work/solid.pvgis"
tap_ok $? "--format pvgis with --canopy holds the solid horizon by default, byte for byte"
run horizon --point "$tsite" --point-crs dem --step 10 --north grid --format pvgis --canopy "$work/tcrown.tif" --horizon-of canopy "$work/tflat.tif"
[ "$(head -c 6 "$work/stdout")" = "25.87," ] && ! cmp -s "$work/stdout" "$work/solid.pvgis"
tap_ok $? "--horizon-of canopy --format pvgis shows the crown: $(head -c 30 "$work/stdout")"
expect_failure 2 "--transmissivity with a site's --canopy" -- horizon --point "$tsite" --point-crs dem --canopy "$work/tcrown.tif" --transmissivity 0.2 "$work/tflat.tif" "$work/out/o.csv"
expect_failure 2 "--trunk-ratio with a site's --canopy" -- horizon --point "$tsite" --point-crs dem --canopy "$work/tcrown.tif" --trunk-ratio 0.5 "$work/tflat.tif" "$work/out/o.csv"
expect_failure 2 "--canopy-horizon for sites" -- horizon --point "$tsite" --point-crs dem --canopy "$work/tcrown.tif" --canopy-horizon "$work/out/c.tif" "$work/tflat.tif" "$work/out/o.csv"
expect_failure 2 "--horizon-of canopy without --canopy" -- horizon --point "$tsite" --point-crs dem --format pvgis --horizon-of canopy "$work/tflat.tif" "$work/out/o.txt"
expect_failure 2 "--horizon-of with csv" -- horizon --point "$tsite" --point-crs dem --canopy "$work/tcrown.tif" --horizon-of canopy "$work/tflat.tif" "$work/out/o.csv"
expect_failure 2 "--horizon-of for rasters" -- horizon --horizon-of canopy "$work/tflat.tif" "$work/out/o.tif"

# ---- skysweep sun --horizon-from ------------------------------------------------------
run sun --at "$ll" --time 2026-12-21T15:00Z/P1D/PT15M --horizon-from "$dem"
tap_ok $rc "sun --horizon-from exits 0 ($(head -c 200 "$work/stderr"))"
awk -F, '/^time,/ { ok = ($8 == "horizon_elevation" && $9 == "behind_terrain"); next }
/^[0-9]/ { n++; want = ($4 < $8) ? 1 : 0; if ($9 != want || $8 < -90 || $8 > 90) bad++; behind += $9 }
END { exit !(ok && n == 96 && !bad && behind > 0 && behind < n) }' "$work/stdout"
tap_ok $? "sun table: behind_terrain = apparent elevation below the horizon, on 96 rows"
expect_failure 2 "sun with a site outside the DEM" -- sun --at -155.2,19.3 --time 2026-12-21T15:00Z --horizon-from "$dem"

tap_done
