#!/bin/bash
# skysweep roofs on a synthetic city of known roofs (tests/data/make_city.sh):
# planes recover tilt and azimuth within 1 degree and true area within 2 %;
# a chimney is an obstacle; sums per building equal the sums over its planes
# and the months sum to the year; a flat roof north of a tall neighbour
# loses to shade, an open one does not; footprints in another CRS give the
# same rows; invalid (bowtie), empty, multi-part and out-of-grid footprints
# are repaired, counted and flagged; the GeoPackage has the fixed layers and
# fields; --dtm gives building heights; a file read that is also the output is refused and left as it
# was; an open plane's unshaded irradiation equals pvlib's
# get_total_irradiance within 1 % (skips without pvlib); panel counts equal
# the closed form, portrait and landscape differ, modules lie on usable
# cells and sum to their planes; the shade table has open planes in sun
# exactly when the sun is up and in front, the shaded flat roof less at
# noon; the shade masks' bits are the shadow product's.
# Without --weather the sky is clear (hourly records written for the run);
# kwh_dc_year exceeds kwh_ac_year by the inverter's efficiency (pvlib).
# Windows of rows holding whole footprints give the whole grid's layers.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
top=${TOP_SRCDIR:-$PWD}
SKYSWEEP=${SKYSWEEP:-./skysweep}
case $SKYSWEEP in /*) ;; *) SKYSWEEP=$PWD/$SKYSWEEP ;; esac
python=${SKYSWEEP_PVLIB_PYTHON:-$top/tests/pyvenv/bin/python}
weather=$top/samples/weather/pvgis_tmy_45N_8E.csv
window=2018-01-10T00:00Z/P1D
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-roofs.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
sh "$top/tests/data/make_city.sh" .

roofs() { # FOOTPRINTS OUT.gpkg CSV [options]
    local fp=$1 out=$2 csv=$3
    shift 3
    "$SKYSWEEP" roofs --buildings "$fp" --weather "$weather" --time "$window" \
        --device reference --directions 8 --min-irradiation 0 --csv "$csv" "$@" city.tif "$out"
}
roofs footprints.geojson city.gpkg planes.csv --dtm ground.tif --panels --shade-table --shade-masks masks.tif \
    >run.out 2>run.err
tap_ok $? "roofs runs on the synthetic city: $(head -c 300 run.err)"
ogr2ogr -f CSV buildings.csv city.gpkg buildings 2>/dev/null

# plane BUILDING TILT AZIMUTH AREA: the building's plane of that azimuth
# (nearest, circularly) has tilt and azimuth within 1 degree, area within 2 %.
plane() {
    awk -F, -v b="\"$1\"" -v t="$2" -v a="$3" -v area="$4" '
        NR == 1 { for (k = 1; k <= NF; k++) col[$k] = k; next }
        $col["building_id"] == b {
            d = $col["azimuth_deg"] - a; d = d < 0 ? -d : d; d = d > 180 ? 360 - d : d
            if (t < 1) d = 0
            if (!found || d < best) { best = d; found = 1; tilt = $col["tilt_deg"]; ar = $col["area_m2"] } }
        END { dt = tilt - t; dt = dt < 0 ? -dt : dt; da = (ar - area) / area; da = da < 0 ? -da : da
              printf "tilt %.3f azimuth off by %.3f area %.2f (%.2f %%)", tilt, best, ar, 100 * da
              exit !(found && dt <= 1 && best <= 1 && da <= 0.02) }' planes.csv
}
c30=0.8660254 c35=0.8191520 c25=0.9063078 c20=0.9396926
check_plane() { # NAME BUILDING TILT AZIMUTH AREA
    local name=$1
    shift
    local says
    says=$(plane "$@")
    tap_ok $? "$name: $says (expected tilt $2, azimuth $3, area $4)"
}
check_plane "gable, north face" A 30 0 "$(awk -v c="$c30" 'BEGIN { print 100 / c }')"
check_plane "gable, south face less the chimney" A 30 180 "$(awk -v c="$c30" 'BEGIN { print 99 / c }')"
check_plane "hip, south face" B 35 180 "$(awk -v c="$c35" 'BEGIN { print 84 / c }')"
check_plane "hip, north face" B 35 0 "$(awk -v c="$c35" 'BEGIN { print 84 / c }')"
check_plane "hip, east face" B 35 90 "$(awk -v c="$c35" 'BEGIN { print 36 / c }')"
check_plane "hip, west face" B 35 270 "$(awk -v c="$c35" 'BEGIN { print 36 / c }')"
check_plane "shed facing south" C 25 180 "$(awk -v c="$c25" 'BEGIN { print 200 / c }')"
check_plane "shed facing east" S 20 90 "$(awk -v c="$c20" 'BEGIN { print 150 / c }')"
check_plane "flat roof" D 0 180 225
check_plane "tall neighbour's flat roof" E 0 180 120

# Fields of a building (buildings.csv) and of its planes (planes.csv).
field() { # FILE BUILDING FIELD: the first row's value
    awk -F, -v b="\"$2\"" -v f="$3" 'NR == 1 { for (k = 1; k <= NF; k++) { h = $k; gsub(/"/, "", h); col[h] = k }; next }
        { id = $col["building_id"]; if (id !~ /^"/) id = "\"" id "\"" }
        id == b { v = $col[f]; gsub(/"/, "", v); print v; exit }' "$1"
}
n=$(awk -F, 'NR > 1 && $1 == "\"A\""' planes.csv | wc -l)
obstacle=$(field buildings.csv A obstacle_area_m2)
awk -v n="$n" -v o="$obstacle" 'BEGIN { exit !(n == 2 && o > 0.98 && o < 1.02) }'
tap_ok $? "the gable has 2 planes ($n) and the chimney is an obstacle of 1 m2 ($obstacle m2)"

height=$(field buildings.csv E height_m)
awk -v h="$height" 'BEGIN { exit !(h > 29.99 && h < 30.01) }'
tap_ok $? "--dtm: the tall neighbour stands $height m above the ground (30)"

# Sums: each building's against its planes', each plane's months against its year.
worst=$(awk -F, 'NR == FNR { if (FNR == 1) { for (k = 1; k <= NF; k++) pc[$k] = k; next }
                             b = $pc["building_id"]; kwh[b] += $pc["kwh_ac_year"]; kwp[b] += $pc["kwp"]
                             dc[b] += $pc["kwh_dc_year"]
                             use[b] += $pc["usable_area_m2"]; np[b] += $pc["n_panels"]
                             m = 0; for (k = pc["kwh_ac_jan"]; k <= pc["kwh_ac_dec"]; k++) m += $k
                             d = m - $pc["kwh_ac_year"]; d = d < 0 ? -d : d; if (d > w) w = d; next }
                 FNR == 1 { for (k = 1; k <= NF; k++) bc[$k] = k; next }
                 { b = "\"" $bc["building_id"] "\""; gsub(/""/, "\"", b)
                   split("kwh_ac_year kwp usable_area_m2 n_panels kwh_dc_year", f, " ")
                   v[1] = kwh[b]; v[2] = kwp[b]; v[3] = use[b]; v[4] = np[b]; v[5] = dc[b]
                   for (i = 1; i <= 5; i++) { x = $bc[f[i]]; gsub(/"/, "", x); d = x - v[i]; d = d < 0 ? -d : d; if (d > w) w = d } }
                 END { printf "%.3g", w }' planes.csv buildings.csv)
awk -v w="$worst" 'BEGIN { exit !(w < 1e-6) }'
tap_ok $? "sums per building equal the sums over its planes; months sum to the year (largest difference $worst)"
# DC (after the system losses, before the inverter) against AC on every
# plane: more wherever modules yield, and by no more than the inverter's
# PVWatts efficiency allows (its best is 0.96 / 0.9637 x 0.96625 = 0.9625).
says=$(awk -F, 'NR == 1 { for (k = 1; k <= NF; k++) c[$k] = k; next }
    { ac = $c["kwh_ac_year"]; dc = $c["kwh_dc_year"]; n++
      if ($c["n_panels"] > 0) { yielding++; r = ac / dc; if (!(dc > ac && r <= 0.9626 && r > 0.85)) bad = bad " " $1 "/" $2
                                if (r < lo || lo == "") lo = r; if (r > hi) hi = r }
      else if (ac != 0 || dc != 0) bad = bad " " $1 "/" $2 }
    END { printf "%d planes, %d with modules, AC/DC %.4f to %.4f%s", n, yielding, lo, hi, bad ? ", wrong:" bad : ""
          exit !(yielding > 0 && bad == "") }' planes.csv)
tap_ok $? "kwh_dc_year above kwh_ac_year on every plane with modules, by the inverter's efficiency: $says"
kwh_c=$(field planes.csv C kwh_ac_year)
awk -v k="$kwh_c" 'BEGIN { exit !(k > 0) }'
tap_ok $? "the open south-facing shed yields ($kwh_c kWh AC in the window)"

# Panel layouts (doc/roofs.md, "Panels"): the counts by hand. The shed C
# (20 x 10 m, 25 deg) is one plane of 40 x 20 cells; the setback (0.5 m)
# leaves 38 x 18 usable: 19 m along the eave, 9 m / cos 25 up the slope.
# The flat D (15 x 15 m) keeps 28 x 28 cells, 14 x 14 m, racked at 10 deg
# facing south, rows clear of each other's shadow with the sun at the
# winter solstice's noon (90 - 45 - 23.44 deg). Modules 1.7 x 1.0 m, gaps
# 0.02 m; a row of n modules takes n pitches less one gap.
count() { # PLANE-ALONG PLANE-UP MODULE-ALONG MODULE-UP TILT RACKED
    awk -v U="$1" -v V="$2" -v a="$3" -v b="$4" -v t="$5" -v racked="$6" 'BEGIN {
        d = atan2(0, -1) / 180; s = 0.02
        n_along = int((U + s) / (a + s))
        if (!racked) n_up = int((V + s) / (b + s))
        else { e = (90 - 45 - 23.44) * d; depth = b * cos(t * d); gap = b * sin(t * d) * cos(e) / sin(e)
               n_up = 1 + int((V - depth) / (depth + (gap > s ? gap : s))) }
        print n_along * n_up }'
}
c_up=$(awk -v c="$c25" 'BEGIN { print 9 / c }')
c_land=$(count 19 "$c_up" 1.7 1.0 25 0) c_port=$(count 19 "$c_up" 1.0 1.7 25 0)
d_land=$(count 14 14 1.7 1.0 10 1) d_port=$(count 14 14 1.0 1.7 10 1)
roofs footprints.geojson portrait.gpkg portrait.csv --orientation portrait >run_p.out 2>&1
roofs footprints.geojson landscape.gpkg landscape.csv --orientation landscape >run_l.out 2>&1
got="C $(field portrait.csv C n_panels)/$(field landscape.csv C n_panels)/$(field planes.csv C n_panels)"
got="$got D $(field portrait.csv D n_panels)/$(field landscape.csv D n_panels)/$(field planes.csv D n_panels)"
best_c=$((c_land > c_port ? c_land : c_port)) best_d=$((d_land > d_port ? d_land : d_port))
c_use=$(field planes.csv C usable_area_m2)
[ "$got" = "C $c_port/$c_land/$best_c D $d_port/$d_land/$best_d" ] &&
    awk -v u="$c_use" -v c="$c25" 'BEGIN { e = u / (684 * 0.25 / c) - 1; exit !(e < 0.002 && e > -0.002) }'
tap_ok $? "panel counts (portrait/landscape/best) as by hand: got $got, expected C $c_port/$c_land/$best_c D $d_port/$d_land/$best_d (C usable $c_use m2)"
[ "$c_port" != "$c_land" ] && [ "$d_port" != "$d_land" ]
tap_ok $? "portrait and landscape differ on the shed ($c_port, $c_land) and the flat roof ($d_port, $d_land)"
worst=$(awk -F, 'NR == 1 { for (k = 1; k <= NF; k++) c[$k] = k; next }
    { d = $c["kwp"] - 0.4 * $c["n_panels"]; d = d < 0 ? -d : d; if (d > w) w = d }
    END { printf "%.3g", w }' planes.csv)
awk -v w="$worst" 'BEGIN { exit !(w < 1e-9) }'
tap_ok $? "kwp is the modules' nameplate, n_panels x 0.4 kWp (largest difference $worst)"
# The layer panels: each module within its plane shrunk by the setback (the
# usable cells: a module on any other cell crosses it), and its yields sum
# to the plane's.
sql() { ogrinfo -q -dialect sqlite -sql "$1" city.gpkg 2>&1 | awk -F' = ' '/=/ { print $2 }'; }
out=$(sql "SELECT count(*) FROM panels p JOIN roof_planes r ON p.building_id = r.building_id
           AND p.plane_id = r.plane_id WHERE NOT ST_Within(p.geom, ST_Buffer(r.geom, -0.499))")
near=$(sql "SELECT count(*) FROM panels p JOIN roof_planes r ON p.building_id = r.building_id
           AND p.plane_id = r.plane_id WHERE NOT ST_Within(p.geom, ST_Buffer(r.geom, -0.6))")
n_layer=$(sql "SELECT count(*) FROM panels")
n_planes=$(awk -F, 'NR == 1 { for (k = 1; k <= NF; k++) c[$k] = k; next } { n += $c["n_panels"] } END { print n }' planes.csv)
if [ -z "$out" ] || ! [ "$out" -eq "$out" ] 2>/dev/null; then
    tap_skip "modules lie on usable cells" "GDAL's SQLite dialect has no ST_Buffer (no SpatiaLite): $out"
else
    [ "$out" = 0 ] && [ "$near" -gt 0 ] && [ "$n_layer" = "$n_planes" ]
    tap_ok $? "every module lies on usable cells ($out of $n_layer outside its plane shrunk by the setback; $near within 0.1 m of that edge; $n_planes in the planes' n_panels)"
fi
worst=$(ogr2ogr -f CSV /vsistdout/ city.gpkg panels 2>/dev/null | awk -F, '
    NR == FNR { if (FNR == 1) { for (k = 1; k <= NF; k++) c[$k] = k; next }
                key = $c["building_id"] "/" $c["plane_id"]; gsub(/"/, "", key)
                s[key] += $c["kwh_ac_year"]; next }
    FNR == 1 { for (k = 1; k <= NF; k++) pc[$k] = k; next }
    { key = $pc["building_id"] "/" $pc["plane_id"]; gsub(/"/, "", key)
      d = s[key] - $pc["kwh_ac_year"]; d = d < 0 ? -d : d; if (d > w) w = d }
    END { printf "%.3g", w }' - planes.csv)
awk -v w="$worst" 'BEGIN { exit !(w < 1e-6) }'
tap_ok $? "the layer panels' kWh sum to each plane's kwh_ac_year (largest difference $worst)"
for bad in 0x1 1.7x-1 1.7 abc 1.7x1.0x2; do
    "$SKYSWEEP" roofs --buildings footprints.geojson --weather "$weather" --module-size "$bad" \
        city.tif bad.gpkg >/dev/null 2>err.txt
    rc=$?
    [ $rc = 2 ] && [ "$(wc -l <err.txt)" = 1 ] && [ ! -e bad.gpkg ] || break
done
tap_ok $? "--module-size $bad refused: exit $rc, $(head -c 200 err.txt)"

# Shade over time (doc/roofs.md): the table plane_shade, a row per plane and
# hour of the window's records. The open shed C (25 deg facing south) is in
# direct sun whenever the sun (skysweep sun, at the records' instants) is up
# and in front of it, and in none at night; hours with the sun within 1 deg
# of the horizon are left out (a hair decides them). The flat roof D north
# of the tall neighbour E has less sun than E's roof at the winter noon.
ogr2ogr -f CSV shade.csv city.gpkg plane_shade 2>/dev/null
rows=$(awk 'END { print NR - 1 }' shade.csv)
"$SKYSWEEP" weather "$weather" | awk -F, '!/^#/ && $1 ~ /^2018-01-10T/ { print $2 }' >instants.txt
first=$(head -n 1 instants.txt | sed 's/\.[0-9]*Z$/Z/')
"$SKYSWEEP" sun --at 9.00013,45.00076 --time "$first/P1D/PT1H" >sun.csv # the DSM's centre
in_sun() { # BUILDING PLANE TILT AZIMUTH: the plane's hours against the sun's
    awk -F, -v B="$1" -v P="$2" -v T="$3" -v A="$4" '
    NR == FNR { if (FNR > 1) { split($1, t, "T"); h = substr(t[2], 1, 2) + 0; az[h] = $2; el[h] = $4 }; next }
    FNR == 1 { for (k = 1; k <= NF; k++) c[$k] = k; next }
    { b = $c["building_id"]; p = $c["plane_id"]; gsub(/"/, "", b); gsub(/"/, "", p)
      if (b != B || p != P) next
      h = $c["hour"]; gsub(/"/, "", h); h += 0; f = $c["sun_fraction"]
      e = el[h]; if (e < 1 && e > -1) { skipped++; next }
      d = atan2(0, -1) / 180; z = (90 - e) * d
      front = cos(z) * cos(T * d) + sin(z) * sin(T * d) * cos((az[h] - A) * d) > 0
      want = e > 0 && front ? 1 : 0
      if (f != want) bad = bad " " h ":" f "/" want; else if (want) day++; else if (e > 0) behind++; else night++ }
    END { printf "%d hours in sun, %d behind it, %d dark, %d at the horizon left out;%s", day, behind,
          night, skipped, bad ? " wrong (hour:got/expected)" bad : ""; exit bad != "" }' sun.csv shade.csv
}
north=$(awk -F, '$1 == "\"A\"" && ($4 < 90 || $4 > 270) { print $2 }' planes.csv)
says_c=$(in_sun C 1 25 180) && says_a=$(in_sun A "$north" 30 0) &&
    [[ $says_c != "0 hours in sun"* ]] && [[ $says_a == "0 hours in sun, "[1-9]* ]] &&
    [ "$rows" = $((15 * 24)) ]
tap_ok $? "plane_shade: open planes in direct sun exactly when the sun is up and in front: the shed facing south $says_c; the gable's north face (30 deg) $says_a ($rows rows: 15 planes x 24 hours)"
noon() { awk -F, -v b="$1" 'NR == 1 { for (k = 1; k <= NF; k++) c[$k] = k; next }
    { id = $c["building_id"]; gsub(/"/, "", id); h = $c["hour"]; gsub(/"/, "", h) }
    id == b && h == 11 { print $c["sun_fraction"] }' shade.csv; }
d_noon=$(noon D) e_noon=$(noon E)
awk -v d="$d_noon" -v e="$e_noon" 'BEGIN { exit !(d < 0.5 && e == 1) }'
tap_ok $? "at the January noon (11 UTC) the flat roof north of the tall neighbour has $d_noon of its cells in sun, the neighbour's roof $e_noon"
# Hourly shade masks: band (month - 1) x 24 + hour + 1, bit day - 1: at three
# of the day's records every cell's bit is the shadow product's sunlit band
# at the record's instant, and no other day's bit is set.
worst=
for h in 08 11 14; do
    "$SKYSWEEP" shadow -q --time "$(sed -n "$((10#$h + 1))p" instants.txt)" --device reference \
        city.tif "shadow$h.tif" >/dev/null 2>&1
    gdal_translate -q -b $((10#$h + 1)) -of XYZ masks.tif mask.xyz
    gdal_translate -q -b 1 -of XYZ "shadow$h.tif" shadow.xyz
    says=$(paste -d' ' mask.xyz shadow.xyz | awk '{ bit = int($3 / 512) % 2; n++
        if ($1 != $4 || $2 != $5 || bit != $6 + 0) d++; if ($3 != 0 && $3 != 512) other++; lit += bit }
        END { printf "%d:%d/%d differ (%d lit, %d other bits)", h, d, n, lit, other; exit d || other || !lit }' h=$h)
    rc=$?
    worst="$worst $says"
    [ $rc = 0 ] || break
done
bands=$(gdalinfo masks.tif 2>/dev/null | grep -c "^Band ")
[ $rc = 0 ] && [ "$bands" = 288 ] && gdalinfo masks.tif | grep -q "Type=UInt32"
tap_ok $? "--shade-masks: $bands UInt32 bands, each cell's bit for day 10 is the shadow product's at the record's instant:$worst"

loss_d=$(field planes.csv D shading_loss_pct)
loss_e=$(field planes.csv E shading_loss_pct)
awk -v d="$loss_d" -v e="$loss_e" 'BEGIN { exit !(d > 10 && e < 0.5 && e > -0.5) }'
tap_ok $? "the flat roof north of the tall neighbour loses $loss_d % to shade, the neighbour's own roof $loss_e %"

# Footprints: counted and flagged.
grep -q "11 read from 'footprints.geojson': 9 placed (1 partly outside the DSM, flagged), 1 repaired; skipped 0 invalid, 1 empty, 1 outside the DSM" run.out
tap_ok $? "footprints counted: $(head -n 1 run.out | head -c 300)"
grep -q "footprint empty skipped: empty geometry" run.out && grep -q "footprint X skipped: outside the DSM" run.out &&
    grep -q "footprint bowtie repaired" run.out
tap_ok $? "each footprint skipped or repaired is named with its reason"
p_out=$(field buildings.csv P partly_outside) m_planes=$(field buildings.csv M n_planes)
bow=$(field buildings.csv bowtie repaired) x_rows=$(grep -c '^"*X' buildings.csv)
[ "$p_out" = 1 ] && [ "$m_planes" = 2 ] && [ "$bow" = 1 ] && [ "$x_rows" = 0 ]
tap_ok $? "partly outside flagged ($p_out), multi-part gives a plane per part ($m_planes), bowtie repaired ($bow), outside not written ($x_rows)"

# The GeoPackage's layers and fields.
info=$(ogrinfo -so city.gpkg buildings 2>&1; ogrinfo -so city.gpkg roof_planes 2>&1)
missing=
for f in building_id tilt_deg azimuth_deg area_m2 usable_area_m2 kwp kwh_ac_year kwh_dc_year kwh_per_kwp \
    kwh_ac_jan kwh_ac_jun kwh_ac_dec shading_loss_pct class partly_outside; do
    grep -q "^$f: " <<<"$info" || missing="$missing $f"
done
ogrinfo -so city.gpkg | grep -q "1: buildings (Multi Polygon)" &&
    ogrinfo -so city.gpkg | grep -q "2: roof_planes (Multi Polygon)" && [ -z "$missing" ] &&
    grep -q "FIELD_kwh_ac_year=.*(kWh/year)" <<<"$info"
tap_ok $? "the GeoPackage opens with ogrinfo: layers buildings and roof_planes, the fixed fields, units in the metadata (missing:${missing:- none})"
left=$(ls -A | grep -c '^\.city\.gpkg\.' || true)
[ "$left" = 0 ]
tap_ok $? "no temporary left beside the output ($left)"

# Footprints in another CRS give the same rows.
ogr2ogr -f GeoJSON -t_srs EPSG:4326 -lco COORDINATE_PRECISION=12 fp4326.geojson footprints.geojson
roofs fp4326.geojson wgs.gpkg planes_wgs.csv >run_wgs.out 2>&1
# (the same cells; plane fits differ by float rounding only)
worst=$(paste -d, planes.csv planes_wgs.csv | awk -F, 'NR > 1 { h = NF / 2
    for (k = 1; k <= h; k++) { a = $k; b = $(k + h)
        if (a ~ /^"/ || b ~ /^"/) { if (a != b) w = 1e9; continue }
        d = a - b; d = d < 0 ? -d : d; s = (a < 0 ? -a : a) + 1e-6; if (d / s > w) w = d / s } }
    END { printf "%.3g", w }')
[ "$(wc -l <planes.csv)" = "$(wc -l <planes_wgs.csv)" ] && awk -v w="$worst" 'BEGIN { exit !(w < 1e-6) }'
tap_ok $? "footprints in EPSG:4326 give the same planes, field for field (largest relative difference $worst)"

# A file read that is also the output: refused in one line, left as it was.
cp footprints.geojson same.gpkg
sum=$(cksum <same.gpkg)
"$SKYSWEEP" roofs --buildings same.gpkg --weather "$weather" --time "$window" city.tif same.gpkg \
    >/dev/null 2>err.txt
rc=$?
[ $rc = 2 ] && [ "$(wc -l <err.txt)" = 1 ] && [ "$(cksum <same.gpkg)" = "$sum" ]
tap_ok $? "--buildings that is the output refused, left as it was (exit $rc: $(head -c 200 err.txt))"
cp "$weather" w.csv
"$SKYSWEEP" roofs --buildings footprints.geojson --weather w.csv --time "$window" city.tif w.csv \
    >/dev/null 2>err.txt
rc=$?
[ $rc = 2 ] && [ "$(wc -l <err.txt)" = 1 ] && cmp -s w.csv "$weather"
tap_ok $? "--weather that is the output refused (exit $rc: $(head -c 200 err.txt))"
"$SKYSWEEP" roofs --buildings footprints.geojson --weather "$weather" --time "$window" \
    --csv city.tif city.tif out2.gpkg >/dev/null 2>err.txt
rc=$?
[ $rc = 2 ] && [ ! -e out2.gpkg ]
tap_ok $? "--csv that is the DSM refused (exit $rc: $(head -c 200 err.txt))"
cp footprints.geojson kept.gpkg
"$SKYSWEEP" roofs --buildings footprints.geojson --weather "$weather" --time "$window" \
    --shade-masks kept.gpkg city.tif kept.gpkg >/dev/null 2>err.txt
rc=$?
[ $rc = 2 ] && [ "$(wc -l <err.txt)" = 1 ] && cmp -s kept.gpkg footprints.geojson
tap_ok $? "--shade-masks that is OUT.gpkg refused, the file left as it was (exit $rc: $(head -c 200 err.txt))"
"$SKYSWEEP" roofs --weather "$weather" city.tif out3.gpkg >/dev/null 2>err.txt
rc=$?
[ $rc = 2 ] && [ ! -e out3.gpkg ] && grep -q -- "--buildings" err.txt
tap_ok $? "without --buildings: exit $rc, $(head -c 200 err.txt)"
"$SKYSWEEP" roofs --buildings nothere.shp --weather "$weather" --time "$window" city.tif out4.gpkg \
    >/dev/null 2>err.txt
rc=$?
[ $rc = 3 ] && [ ! -e out4.gpkg ] && [ "$(wc -l <err.txt)" = 1 ]
tap_ok $? "footprints that cannot be opened: exit $rc, $(head -c 200 err.txt)"

"$SKYSWEEP" roofs --plan --buildings footprints.geojson --weather "$weather" --time "$window" \
    --device reference city.tif plan.gpkg >plan.out 2>err.txt
rc=$?
[ $rc = 0 ] && [ ! -e plan.gpkg ] && grep -q "^cost" plan.out && [ -z "$(ls -A | grep '^\.plan\.gpkg')" ]
tap_ok $? "--plan prints the insolation run's plan and writes nothing (exit $rc)"

# --horizon-files: a PVsyst horizon file per roof plane, seen from its centre
# (doc/pv-horizons.md). The flat roof D, 15 m north of the tall neighbour E
# (26 m higher), sees E at its south, PVsyst's 0: atan(26 / 15) = 60.0 deg.
mkdir hz
roofs footprints.geojson hz.gpkg hz.csv --horizon-files hz --horizon-format pvsyst >hz.out 2>err.txt
rc=$?
planes=$(($(wc -l <hz.csv) - 1))
[ $rc = 0 ] && [ "$(ls hz | wc -l)" = "$planes" ] && [ -e hz/D_1.csv ] && [ -e hz/A_2.csv ]
tap_ok $? "--horizon-files writes one file per roof plane, BUILDING_PLANE.csv ($planes planes: $(ls hz | head -4 | tr '\n' ' ')...)"
awk -F, '$1 == 0 { s = $2 } $1 == -180 { n = $2 } END { printf "south %s, north %s", s, n; exit !(s > 59.5 && s < 60.5 && n == 0) }' \
    hz/D_1.csv >hz.says
tap_ok $? "the flat roof north of the tall neighbour sees it at PVsyst's 0 (south), open to the north: $(cat hz.says)"
# Building ids that differ only in characters a file name cannot hold.
sed 's/"building_id": "D"/"building_id": "x y"/; s/"building_id": "E"/"building_id": "x\/y"/' \
    footprints.geojson >clash.geojson
mkdir hz2
roofs clash.geojson clash.gpkg clash.csv --horizon-files hz2 >/dev/null 2>err.txt
rc=$?
[ $rc = 3 ] && [ ! -e clash.gpkg ] && [ -z "$(ls -A hz2)" ] && grep -q "x_y_1.txt" err.txt
tap_ok $? "two planes that would share a horizon file: exit $rc, nothing written, $(head -c 200 err.txt)"
"$SKYSWEEP" roofs --buildings footprints.geojson --weather "$weather" --horizon-files nothere \
    city.tif out5.gpkg >/dev/null 2>err.txt
rc=$?
[ $rc = 2 ] && [ ! -e out5.gpkg ] && [ "$(wc -l <err.txt)" = 1 ] && grep -q "existing folder" err.txt
tap_ok $? "--horizon-files that is not a folder: exit $rc, $(head -c 200 err.txt)"

# OpenStreetMap footprints (GDAL's OSM driver): the file's areas tagged
# building, not its first layer (points) nor its other areas (a landuse
# over building A); the shed C found as from the GeoJSON.
i=0
gdaltransform -s_srs EPSG:32632 -t_srs EPSG:4326 -output_xy >osm.lonlat <<'EOF_XY'
500045 4983005
500065 4983005
500065 4983015
500045 4983015
499955 4983005
499975 4983005
499975 4983015
499955 4983015
EOF_XY
{
    echo "<?xml version='1.0' encoding='UTF-8'?>"
    echo "<osm version='0.6' generator='test_roofs.sh'>"
    while read -r lon lat; do
        i=$((i + 1))
        echo "<node id='$i' version='1' lat='$lat' lon='$lon'/>"
    done <osm.lonlat
    echo "<node id='100' version='1' lat='45.0001' lon='9.0001'><tag k='amenity' v='bench'/></node>"
    echo "<way id='1000' version='1'><nd ref='1'/><nd ref='2'/><nd ref='3'/><nd ref='4'/><nd ref='1'/><tag k='building' v='yes'/></way>"
    echo "<way id='1001' version='1'><nd ref='5'/><nd ref='6'/><nd ref='7'/><nd ref='8'/><nd ref='5'/><tag k='landuse' v='grass'/></way>"
    echo "</osm>"
} >city.osm
roofs city.osm osm.gpkg osm.csv >/dev/null 2>err.txt
rc=$?
n_osm=$(ogrinfo -so osm.gpkg buildings 2>/dev/null | sed -n 's/^Feature Count: //p')
[ $rc = 0 ] && [ "$n_osm" = 1 ]
tap_ok $? "footprints from an OpenStreetMap file: its one area tagged building ($n_osm building; $(head -c 160 err.txt))"
says=$(awk -F, -v c="$c25" 'NR == 1 { for (k = 1; k <= NF; k++) col[$k] = k; next }
    { n++; t = $col["tilt_deg"]; a = $col["azimuth_deg"]; ar = $col["area_m2"] }
    END { printf "%d plane(s), tilt %.2f azimuth %.2f area %.1f", n, t, a, ar
          d = ar / (200 / c) - 1
          exit !(n == 1 && t > 24 && t < 26 && a > 179 && a < 181 && d < 0.02 && d > -0.02) }' osm.csv)
tap_ok $? "the OpenStreetMap footprint of the south shed gives its plane: $says"
roofs city.osm osm2.gpkg osm2.csv --buildings-layer nothere >/dev/null 2>err.txt
rc=$?
[ $rc = 2 ] && [ ! -e osm2.gpkg ] && [ "$(wc -l <err.txt)" = 1 ]
tap_ok $? "--buildings-layer naming no layer: exit $rc, $(head -c 160 err.txt)"

# Trees (--canopy, passed on to insolation): a crown 15 m tall south of the
# south shed C (e 105, n 2.5, radius 2.5 m) takes from its irradiation in
# January (leaf off: transmissivity 0.5), more with dense winter crowns
# (0.03), and not from its open-plane reference; a canopy of zeros leaves
# every row as without --canopy.
canopy_asc() { # HEIGHT: the crown's height (0: a canopy of zeros)
    awk -v h="$1" 'BEGIN {
      print "ncols 240"; print "nrows 140"; print "xllcorner 499950"; print "yllcorner 4983000"
      print "cellsize 0.5"
      for (r = 0; r < 140; r++) { line = ""
        for (c = 0; c < 240; c++) { e = (c + 0.5) * 0.5; n = 70 - (r + 0.5) * 0.5
          line = line (((e - 105) ^ 2 + (n - 2.5) ^ 2 <= 6.25) ? h : 0) " " }
        print line } }'
}
canopy_asc 15 >tree.asc
canopy_asc 0 >notree.asc
gdal_translate -q -ot Float32 -a_srs EPSG:32632 tree.asc tree.tif &&
    gdal_translate -q -ot Float32 -a_srs EPSG:32632 notree.asc notree.tif
roofs footprints.geojson zero.gpkg zero.csv --canopy notree.tif >/dev/null 2>&1 &&
    roofs footprints.geojson plain.gpkg plain.csv >/dev/null 2>&1 && cmp -s plain.csv zero.csv
tap_ok $? "roofs --canopy of zeros: every plane's row as without --canopy"
roofs footprints.geojson tree.gpkg tree.csv --canopy tree.tif >/dev/null 2>&1 &&
    roofs footprints.geojson dense.gpkg dense.csv --canopy tree.tif --transmissivity-leaf-off 0.03 \
        >/dev/null 2>&1
c_plain=$(field plain.csv C kwh_m2_year) c_tree=$(field tree.csv C kwh_m2_year)
c_dense=$(field dense.csv C kwh_m2_year)
u_plain=$(field plain.csv C unshaded_kwh_m2_year) u_tree=$(field tree.csv C unshaded_kwh_m2_year)
awk -v p="$c_plain" -v t="$c_tree" -v d="$c_dense" -v up="$u_plain" -v ut="$u_tree" \
    'BEGIN { exit !(t < p && d < t && up == ut) }'
tap_ok $? "roofs --canopy: a winter crown south of shed C lowers its kWh/m2 $c_plain -> $c_tree (leaf off, 0.5) -> $c_dense (0.03); its open-plane reference stays $u_plain"
ogrinfo -so tree.gpkg roof_planes 2>/dev/null | grep -q "with trees from tree.tif, transmissivity 0.03 leaf on, 0.5 leaf off"
tap_ok $? "roofs --canopy: the layers' description names the trees and their transmissivities"

# Beer-Lambert crown light (--crown-light, passed on to insolation) on a
# leaf-on day: so dense a crown (LAD 20, G 1) lets no beam through, every
# row as the constant transmissivity 0 with its crowns on the same (digital)
# lines; and the layers name the model.
june() { # CSV OUT.gpkg [options]: a clear 21 June with the crown south of C
    local csv=$1 out=$2
    shift 2
    "$SKYSWEEP" roofs --buildings footprints.geojson --time 2018-06-21T00:00Z/P1D \
        --device reference --directions 8 --min-irradiation 0 --canopy tree.tif --csv "$csv" "$@" \
        city.tif "$out" >/dev/null 2>err.txt
}
june t0.csv t0.gpkg --transmissivity 0 --crown-lines digital &&
    june bl.csv bl.gpkg --crown-light beer-lambert --leaf-area-density 20 \
        --extinction 1 &&
    worst=$(paste -d '\n' t0.csv bl.csv | awk -F, 'NR % 2 { split($0, a, ","); next }
        { for (k = 1; k <= NF; k++) if (a[k] != $k) { d = (a[k] - $k) / (1e-9 + (a[k] < 0 ? -a[k] : a[k]))
              d = d < 0 ? -d : d; w = d > w ? d : w; if (a[k] + 0 != a[k] || NF != length(a)) bad = 1 } }
        END { printf "%.2g", w; exit bad || w > 1e-6 }')
tap_ok $? "roofs --crown-light beer-lambert, LAD 20 and G 1: every plane's row as transmissivity 0 (the crowns on digital lines both), worst relative $worst (exp(-20 L) is not quite 0 on the shortest paths) $(head -c 160 err.txt)"
ogrinfo -so bl.gpkg roof_planes 2>/dev/null |
    grep -q "transmissivity Beer-Lambert leaf on, 0.5 leaf off, crown light: Beer-Lambert: exp(-1 x 20 m2/m3"
tap_ok $? "roofs --crown-light: the layers' description names Beer-Lambert (not the constant it replaces)"
june bad.csv bad.gpkg --leaf-area-density 2
rc=$?
[ $rc = 2 ] && [ "$(wc -l <err.txt)" = 1 ] && [ ! -e bad.gpkg ]
tap_ok $? "roofs --leaf-area-density without --crown-light beer-lambert is refused (exit $rc: $(head -c 160 err.txt))"

# --max-off-equator 90.5: the planes facing more than that from the
# equator (A's and B's north faces, azimuth 0) have no usable area and no
# module; every other plane (B's east and west faces, 90 degrees off and a
# fit's 1e-4 degrees, among them) keeps its usable area as without the rule.
roofs footprints.geojson off.gpkg off.csv --max-off-equator 90.5 >/dev/null 2>err.txt
rc=$?
says=$(paste -d '\n' plain.csv off.csv | awk -F, 'NR <= 2 { if (NR == 2) for (k = 1; k <= NF; k++) col[$k] = k; next }
    NR % 2 { split($0, a, ","); next }
    { az = a[col["azimuth_deg"]]; off = az - 180; off = off < 0 ? -off : off
      if (off > 90.5) { dropped++; bad += ($col["usable_area_m2"] != 0 || $col["n_panels"] != 0) }
      else { kept++; bad += ($col["usable_area_m2"] != a[col["usable_area_m2"]]) } }
    END { printf "%d planes dropped, %d kept", dropped, kept; exit !(bad == 0 && dropped == 2 && kept > 5) }')
tap_ok $? "roofs --max-off-equator 90.5 (exit $rc): $says $(head -c 120 err.txt)"

# --cell-raster keeps the per-cell results: the insolation run's raster,
# every band as `skysweep insolation --pv` with the same options gives it
# alone, with the bands' names and units; no temporary is left beside it.
# Not a GeoTIFF's name, or an input's, is refused in one line.
roofs footprints.geojson cells.gpkg cells.csv --cell-raster cells.tif >/dev/null 2>err.txt &&
    "$SKYSWEEP" insolation --weather "$weather" --time "$window" --device reference --directions 8 \
        --pv -q city.tif alone.tif 2>>err.txt &&
    gdal_translate -q -of ENVI cells.tif cells.bin && gdal_translate -q -of ENVI alone.tif alone.bin &&
    cmp -s cells.bin alone.bin && cmp -s cells.csv plain.csv
rc=$?
n_bands=$(gdalinfo cells.tif 2>/dev/null | grep -c "^Band ")
n_units=$(gdalinfo cells.tif 2>/dev/null | grep -c "Unit Type: ")
[ $rc = 0 ] && [ "$n_bands" -gt 5 ] && [ "$n_units" = "$n_bands" ] && [ -z "$(ls -A | grep '^\.cells')" ]
tap_ok $? "roofs --cell-raster: $n_bands bands ($n_units with units) equal to insolation --pv's alone, the planes as without it $(head -c 160 err.txt)"
roofs footprints.geojson bad.gpkg bad.csv --cell-raster cells.png >/dev/null 2>err.txt
rc=$?
roofs footprints.geojson bad.gpkg bad.csv --cell-raster city.tif >/dev/null 2>err2.txt
rc2=$?
[ $rc = 2 ] && [ "$(wc -l <err.txt)" = 1 ] && [ $rc2 -ne 0 ] && [ "$(wc -l <err2.txt)" = 1 ] &&
    [ ! -e bad.gpkg ] && [ ! -e cells.png ]
tap_ok $? "roofs --cell-raster not a .tif (exit $rc: $(head -c 120 err.txt)) or the DSM itself (exit $rc2: $(head -c 120 err2.txt)) is refused"

# Sums over usable cells, from the per-cell raster (issue 44's "sums per
# building equal the sum of the per-cell raster over its usable cells";
# buildings are their planes' sums, above): with --setback 0 a plane's
# cells are all inner, so its kwh_m2_year is band 1's mean over the cells
# of its polygon (gdal_rasterize of roof_planes on the DSM's grid) and its
# usable_area_m2 is its share of cells receiving at least --min-irradiation
# (here shed C's mean, which splits the south faces) times its area.
t_min=$(field plain.csv C kwh_m2_year)
roofs footprints.geojson sum.gpkg sum.csv --setback 0 --min-irradiation "$t_min" \
    --cell-raster sum.tif >/dev/null 2>err.txt &&
    gdal_rasterize -q -a k -sql "SELECT geom, fid * 1 AS k FROM roof_planes" -ot Int32 -init 0 \
        -te 499950 4983000 500070 4983070 -ts 240 140 sum.gpkg sum_k.tif &&
    gdal_translate -q -of AAIGrid sum_k.tif sum_k.asc && gdal_translate -q -of AAIGrid -b 1 sum.tif sum_g.asc
rc=$?
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
    { print $col["area_m2"], $col["kwh_m2_year"], $col["usable_area_m2"] }' sum.csv >sum.txt
says=$(awk -v t="$t_min" 'FNR == 1 { file++ } /^[a-zA-Z]/ { next }
    file == 1 { for (i = 1; i <= NF; i++) k[n1++] = $i; next }
    file == 2 { for (i = 1; i <= NF; i++) g[n2++] = $i; next }
    file == 3 { rows++; area[rows] = $1; kwh[rows] = $2; use[rows] = $3 }
    END { for (i = 0; i < n1; i++) if (k[i] > 0) { s[k[i]] += g[i]; n[k[i]]++; if (g[i] >= t) u[k[i]]++ }
        for (r = 1; r <= rows; r++) {
            if (!n[r]) { bad++; continue }
            d = s[r] / n[r] / kwh[r] - 1; d = d < 0 ? -d : d; wk = d > wk ? d : wk
            e = u[r] * area[r] / n[r] - use[r]; e = e < 0 ? -e : e; wa = e > wa ? e : wa
            split_ += (u[r] > 0 && u[r] < n[r]) }
        printf "%d planes, %d split by the threshold; worst relative kwh_m2_year %.2g, usable area %.2g m2",
            rows, split_, wk, wa
        exit !(rows > 10 && n1 == n2 && !bad && split_ >= 2 && wk < 1e-6 && wa < 1e-4) }' sum_k.asc sum_g.asc sum.txt)
agree=$?
[ $rc = 0 ] && [ $agree = 0 ]
tap_ok $? "each plane's kwh_m2_year and usable_area_m2 from the --cell-raster cells under its polygon: $says $(head -c 160 err.txt)"

# Without --weather: a clear sky, hourly over --time (doc/roofs.md). The
# tall neighbour E's flat roof, the highest in the DSM, has no horizon above
# its horizontal, so its cells' mean equals the open plane's to float
# rounding (0.01 %); the open shed C within 1 % (its cells' sky view over 8
# directions and the DSM's ground differ from an open plane's (1 + cos
# tilt) / 2 and level ground: 0.35 % on this day).
"$SKYSWEEP" roofs --buildings footprints.geojson --time 2018-06-21T00:00Z/P1D --device reference \
    --directions 8 --min-irradiation 0 --csv clear.csv city.tif clear.gpkg >clear.out 2>err.txt
rc=$?
off() { awk -v a="$(field clear.csv "$1" kwh_m2_year)" -v b="$(field clear.csv "$1" unshaded_kwh_m2_year)" \
    'BEGIN { printf "%.4f", 100 * (a / b - 1) }'; }
off_e=$(off E) off_c=$(off C) kwh_c=$(field clear.csv C kwh_ac_year)
[ $rc = 0 ] && [ "$(wc -l <clear.csv)" = "$(wc -l <planes.csv)" ] &&
    awk -v e="$off_e" -v c="$off_c" -v k="$kwh_c" 'BEGIN { exit !(e < 0.01 && e > -0.01 && c < 1 && c > -1 && k > 0) }'
tap_ok $? "without --weather a clear sky: $(($(wc -l <clear.csv) - 1)) planes; per-cell mean against the open plane E $off_e %, C $off_c %; C yields $kwh_c kWh AC (exit $rc $(head -c 200 err.txt))"
grep -q "^sky       a clear sky (ESRA, Linke turbidity 3; no --weather), hourly from 2018-06-21T00:00:00Z" clear.out &&
    ogrinfo -so clear.gpkg roof_planes 2>/dev/null | grep -q "DESCRIPTION=.*under a clear sky (ESRA" &&
    ogrinfo -so city.gpkg buildings 2>/dev/null | grep -q "DESCRIPTION=.*under the weather records of"
tap_ok $? "the summary and the layers' descriptions say which sky: $(grep '^sky' clear.out | head -c 200)"
"$SKYSWEEP" roofs --buildings footprints.geojson --weather-zone +01:00 city.tif bad.gpkg >/dev/null 2>err.txt
rc=$?
"$SKYSWEEP" roofs --buildings footprints.geojson --time 2018-06-21T10:00Z city.tif bad.gpkg >/dev/null 2>err2.txt
rc2=$?
[ $rc = 2 ] && [ "$(wc -l <err.txt)" = 1 ] && [ $rc2 = 2 ] && [ "$(wc -l <err2.txt)" = 1 ] &&
    [ ! -e bad.gpkg ] && [ -z "$(ls -A | grep '^\.bad\.gpkg')" ]
tap_ok $? "without --weather, --weather-zone (exit $rc: $(head -c 120 err.txt)) and an instant --time (exit $rc2: $(head -c 120 err2.txt)) are refused"

# Scale (doc/roofs.md, "Scale"): windows of rows that each hold whole
# footprints give the whole grid's rows, byte for byte, in every layer. The
# test hook makes windows of 30 rows on this small DSM (--memory makes them
# where the DSM is too large for it): 4 windows, the gable A (rows 110 to
# 129) across the row 120 that bands of 30 or 40 rows would cut it at. A
# window too small for a footprint (25 rows, the flat roof D spans 30) is
# refused in one line, exit 6, before any work.
SKYSWEEP_TEST_ROOF_WINDOW_ROWS=30 roofs footprints.geojson win.gpkg win.csv --dtm ground.tif \
    --panels --shade-table >win.out 2>err.txt
rc=$?
differ=
for layer in buildings roof_planes panels plane_shade; do
    cmp -s <(ogr2ogr -f CSV /vsistdout/ city.gpkg $layer -lco GEOMETRY=AS_WKT 2>/dev/null) \
        <(ogr2ogr -f CSV /vsistdout/ win.gpkg $layer -lco GEOMETRY=AS_WKT 2>/dev/null) ||
        differ="$differ $layer"
done
cmp -s planes.csv win.csv || differ="$differ csv"
[ $rc = 0 ] && [ -z "$differ" ] && grep -q "^memory    the DSM held whole, 4 windows of up to 30 rows" win.out
tap_ok $? "windows of 30 rows give the whole grid's layers byte for byte (differ:${differ:- none}; $(grep '^memory' win.out))"
SKYSWEEP_TEST_ROOF_WINDOW_ROWS=25 roofs footprints.geojson win25.gpkg win25.csv >/dev/null 2>err.txt
rc=$?
[ $rc = 6 ] && [ "$(wc -l <err.txt)" = 1 ] && [ ! -e win25.gpkg ] && [ ! -e win25.csv ] &&
    grep -q "footprint 'D' spans 30" err.txt
tap_ok $? "a window smaller than a footprint refused: exit $rc, $(head -c 240 err.txt)"

# An open plane against pvlib.
if "$python" -c "import pvlib" 2>/dev/null; then
    "$python" "$top/tests/pvlib/roof_plane.py" "$SKYSWEEP" "$weather" "$window" planes.csv C \
        500055 4983010 2 >pvlib.out 2>&1
    tap_ok $? "$(tail -n 2 pvlib.out | tr '\n' ' ' | head -c 500)"
else
    tap_skip "an open plane's irradiation equals pvlib's" "no pvlib at $python (tests/run.sh installs it)"
fi
tap_done
