#!/bin/bash
# Weather files: `skysweep weather` returns the records, stamps and values
# pvlib's readers return on EPW, TMY3, PVGIS TMY CSV and JSON files (their
# January and February in tests/data/weather/, cut from pvlib's test files;
# the PVGIS CSV whole in samples/weather/, since pvlib reads 8760 rows; and
# the whole files in ../shared/data/weather/ where present) and on a
# PSM4 sample (tests/data/); a plain CSV reads as written; malformed files
# are refused in one line with exit 3. The pvlib comparisons need pvlib
# (tests/run.sh installs it in a venv); they skip, saying why, without it.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
top=${TOP_SRCDIR:-$PWD}
SKYSWEEP=${SKYSWEEP:-./skysweep}
python=${SKYSWEEP_PVLIB_PYTHON:-$top/tests/pyvenv/bin/python}
weather=$top/../shared/data/weather
cut=$top/tests/data/weather
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-weather.XXXXXX")
trap 'rm -rf "$work"' EXIT

have_pvlib=0
"$python" -c "import pvlib" 2>/dev/null && have_pvlib=1
# against_pvlib FILE READER
against_pvlib() {
    local file=$1 reader=$2 name
    name=$(basename "$file")
    if [ "$have_pvlib" -eq 0 ]; then
        tap_skip "$name matches pvlib's $reader reader" "no pvlib at $python (tests/run.sh installs it)"
    elif [ ! -f "$file" ]; then
        tap_skip "$name matches pvlib's $reader reader" "$file is not here"
    else
        "$python" "$top/tests/pvlib/weather_readers.py" "$SKYSWEEP" "$file" "$reader" >"$work/out" 2>&1
        local rc=$?
        tap_ok $rc "$name matches pvlib's $reader reader: $(grep -c '^ok' "$work/out") checks pass, $(grep '^not ok' "$work/out" | head -c 300)$( [ $rc -gt 1 ] && tail -c 300 "$work/out")"
    fi
}
against_pvlib "$cut/amsterdam_iwec_jan_feb.epw" epw
against_pvlib "$cut/pvgis_45N_8E_jan_feb.epw" epw
against_pvlib "$cut/greensboro_tmy3_jan_feb.csv" tmy3
against_pvlib "$top/samples/weather/pvgis_tmy_45N_8E.csv" pvgis # pvlib reads 8760 rows
against_pvlib "$cut/pvgis_45N_8E_jan_feb.json" pvgis
against_pvlib "$weather/NLD_Amsterdam062400_IWEC.epw" epw
against_pvlib "$weather/tmy_45.000_8.000_2005_2023.epw" epw
against_pvlib "$weather/723170TYA.CSV" tmy3
against_pvlib "$weather/tmy_45.000_8.000_2005_2023.csv" pvgis
against_pvlib "$weather/tmy_45.000_8.000_2005_2023.json" pvgis
against_pvlib "$top/tests/data/psm4_sample.csv" psm4
# NSRDB PSM4 half-hourly (pvlib's test_read_psm4.csv, its empty spreadsheet
# columns kept) and 5-minute records (pvlib's 5-minute frame under the same
# header); a typical year stitching 31 January 2020 to 1 February 2007 at
# UTC-7, where the months change in the file's zone but not in UTC (it was
# refused as "times do not increase").
against_pvlib "$cut/nsrdb_psm4_30min_cut.csv" psm4
against_pvlib "$cut/nsrdb_psm4_5min_cut.csv" psm4
against_pvlib "$cut/nsrdb_psm4_tmy_stitched.csv" psm4
steps=$(for f in 30min_cut 5min_cut tmy_stitched; do "$SKYSWEEP" weather "$cut/nsrdb_psm4_$f.csv" | grep -v '^#' | sed -n 2p | cut -d, -f3; done | tr '\n' ' ')
[ "$steps" = "0.5 0.0833333 1 " ]
tap_ok $? "PSM records stand for their spacing: 30 min, 5 min, an hour ($steps)"
# PVGIS hourly series (seriescalc), CSV and JSON: pvlib's test file asks for
# a plane tilted 30 degrees (refused below); with its slope set to 0 it
# reads as a horizontal series: G(i) as GHI, Gd(i) as DHI, at the stamp.
sed 's/^Slope: 30 deg. $/Slope: 0 deg. /' "$cut/pvgis_hourly_45N_8E_30deg_2016.csv" >"$work/pvgis_hourly_0deg.csv"
against_pvlib "$work/pvgis_hourly_0deg.csv" pvgis_hourly
against_pvlib "$cut/pvgis_hourly_45N_8E_0deg_2016.json" pvgis_hourly
csv=$("$SKYSWEEP" weather "$work/pvgis_hourly_0deg.csv" | grep -v '^#')
json=$("$SKYSWEEP" weather "$cut/pvgis_hourly_45N_8E_0deg_2016.json" | grep -v '^#')
row=$(echo "$csv" | sed -n 10p | cut -d, -f1-6,12)
[ "$csv" = "$json" ] && [ "$row" = "2016-01-01T08:10:00Z,2016-01-01T08:10:00Z,1,35.2,193.821,8.28,closure" ]
tap_ok $? "a PVGIS hourly series reads the same from CSV and JSON, the sun at the stamp, DNI by the closure: $row"
# SAM's CSV weather format with NREL's short names (lat, lon, tz, elev;
# Tdry, Wspd, Pres, Albedo): the half-hourly PSM4 cut rewritten so, which
# must read as the PSM4 file does (that one equals pvlib's reader above).
sam=$("$SKYSWEEP" weather "$cut/sam_csv_30min.csv")
echo "$sam" | grep -q '^# format SAM CSV' &&
    [ "$(echo "$sam" | grep -v '^#')" = "$("$SKYSWEEP" weather "$cut/nsrdb_psm4_30min_cut.csv" | grep -v '^#')" ]
tap_ok $? "a SAM CSV with NREL's short names reads as the NSRDB file it was written from"
# The same without tz (SAM itself may do without): refused naming SAM and
# --weather-zone (exit 2), and read as before when the option gives the zone.
awk -F, -v OFS=, 'NR <= 2 { for (i = 1; i <= NF; ++i) if (NR == 1 && $i == "tz") col = i }
    NR <= 2 && col { $col = "" } { print }' "$cut/sam_csv_30min.csv" >"$work/sam_no_tz.csv"
zone=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "tz") col = i } NR == 2 { print $col }' \
    "$cut/sam_csv_30min.csv")
"$SKYSWEEP" weather "$work/sam_no_tz.csv" >/dev/null 2>"$work/err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "is a SAM CSV file whose metadata states no Time Zone: give its stamps' zone with --weather-zone" "$work/err"
tap_ok $? "a SAM CSV without tz is refused naming SAM and --weather-zone: exit $rc, $(cat "$work/err")"
hours=$(printf '%+03d:00' "$zone")
[ "$("$SKYSWEEP" weather --weather-zone "$hours" "$work/sam_no_tz.csv" | grep -v '^#')" = "$(echo "$sam" | grep -v '^#')" ]
tap_ok $? "... and with --weather-zone $hours (the zone it had) it reads as the file with tz"
against_pvlib "$cut/miami_tmy2_jan_1_2.tm2" tmy2
# pvlib ships NREL's whole Miami TMY2 file with its package.
pvlib_data=$("$python" -c "import os, pvlib; print(os.path.dirname(pvlib.__file__) + '/data')" 2>/dev/null)
against_pvlib "${pvlib_data:-no-pvlib}/12839.tm2" tmy2

# TMY2: the hour field (1-24) ends the hour summed; the sun at its middle;
# a solar source flag '?' while the sun is up marks missing data (the
# manual's Table 3-3): counted, the values missing. Line 14 is 12:00 on
# 1 January 1962 (UTC-5).
tm2=$cut/miami_tmy2_jan_1_2.tm2
noon=$("$SKYSWEEP" weather "$tm2" | grep -v '^#' | sed -n 14p | cut -d, -f1-6)
[ "$noon" = "1962-01-01T17:00:00Z,1962-01-01T17:30:00Z,1,145,9,137" ]
tap_ok $? "a TMY2 hour ending 13:00 local is stamped at its start, the sun at its middle: $noon"
sed '14s/^\(.\{21\}\)C/\1?/' "$tm2" >"$work/flagged.tm2"
out=$("$SKYSWEEP" weather "$work/flagged.tm2")
echo "$out" | grep -q "^# records 48, 1 with an irradiance value missing (1 of them flagged missing by the file)" &&
    [ "$(echo "$out" | grep -v '^#' | sed -n 14p | cut -d, -f4-6)" = ",9,137" ]
tap_ok $? "a TMY2 GHI flagged '?' at noon is missing and counted: $(echo "$out" | grep '^# records')"

# Where the sun is taken: the middle of an EPW hour; PVGIS's stated offset,
# also in its EPW export whose zone label is not applied.
epw=$("$SKYSWEEP" weather "$cut/pvgis_45N_8E_jan_feb.epw" | grep -v "^#" | sed -n 2p | cut -d, -f2)
csv=$("$SKYSWEEP" weather "$top/samples/weather/pvgis_tmy_45N_8E.csv" | grep -v "^#" | sed -n 2p | cut -d, -f2)
[ "$epw" = "2018-01-01T00:10:33.96Z" ] && [ "$csv" = "$epw" ]
tap_ok $? "PVGIS's EPW and CSV put the first record's sun at the same instant ($epw, $csv)"
amsterdam=$("$SKYSWEEP" weather "$cut/amsterdam_iwec_jan_feb.epw" | grep -v "^#" | sed -n 2p | cut -d, -f1,2)
[ "$amsterdam" = "1994-12-31T23:00:00Z,1994-12-31T23:30:00Z" ]
tap_ok $? "an EPW hour's sun is at its middle ($amsterdam)"

# JSON laid out over many lines reads as the same records as on one.
sed 's/}, {/},\n {/g' "$cut/pvgis_45N_8E_jan_feb.json" >"$work/pretty.json"
lines=$(wc -l <"$work/pretty.json")
"$SKYSWEEP" weather "$cut/pvgis_45N_8E_jan_feb.json" | grep -v "^#" >"$work/one.csv"
"$SKYSWEEP" weather "$work/pretty.json" | grep -v "^#" >"$work/many.csv"
[ "$lines" -gt 1000 ] && cmp -s "$work/one.csv" "$work/many.csv" && [ -s "$work/one.csv" ]
tap_ok $? "PVGIS JSON over $lines lines reads as on one line"

# A plain CSV, with a missing value and a zone.
cat >"$work/plain.csv" <<'CSV'
time,ghi,dni,dhi,temp_air
2026-06-21T10:00+02:00,700,600,150,21.5
2026-06-21T11:00+02:00,800,,160,22
CSV
out=$("$SKYSWEEP" weather "$work/plain.csv")
rows=$(echo "$out" | grep -v '^#' | tail -n +2 | tr '\n' ';')
[ "$rows" = "2026-06-21T08:00:00Z,2026-06-21T08:00:00Z,1,700,600,150,21.5,,,;2026-06-21T09:00:00Z,2026-06-21T09:00:00Z,1,800,,160,22,,,;" ] &&
    echo "$out" | grep -q "records 2, 1 with an irradiance value missing"
tap_ok $? "a plain CSV reads as written: $rows"
printf 'time,ghi\n2026-06-21T10:00Z,500\n2026-06-21T11:00Z,600\n' >"$work/ghi.csv"
"$SKYSWEEP" weather "$work/ghi.csv" | grep -q "GHI alone"
tap_ok $? "a CSV with GHI alone is taken as such"

# GHI alone, or GHI and DHI (issue 45): a month of the PVGIS sample (its
# sun times as stamps) without the other columns; `--at` the file's site,
# each record's DNI and DHI equal pvlib's erbs and dni within 0.1 %.
for month in 2018-01 2006-06; do
    for cols in ghi ghi,dhi; do
        "$SKYSWEEP" weather "$top/samples/weather/pvgis_tmy_45N_8E.csv" |
            awk -F, -v m="$month" -v c="$cols" '!/^#/ && index($2, m) == 1 {
                if (!h++) print "time," c; print $2 "," $4 (c == "ghi" ? "" : "," $6) }' \
                >"$work/$month.$cols.csv"
        if [ "$have_pvlib" -eq 0 ]; then
            tap_skip "$month, $cols: completed as pvlib does" "no pvlib at $python (tests/run.sh installs it)"
            continue
        fi
        "$python" "$top/tests/pvlib/decomposition.py" "$SKYSWEEP" "$work/$month.$cols.csv" 8,45 \
            >"$work/out" 2>&1
        tap_ok $? "$month, $cols: completed as pvlib does: $(grep -v '^ok' "$work/out" | head -c 300) $(grep 'within 0.1' "$work/out" | tr '\n' ' ' | head -c 400)"
    done
done
# Item 2 of issue 45: a TMY3, EPW, PVGIS or PSM file whose DNI column is
# absent or missing throughout (DNI and DHI: GHI alone) is completed as a
# plain CSV is, at its own site, and says so; pvlib's erbs and dni agree.
# completed NAME FILE LON,LAT WORDS
completed() {
    local out
    out=$("$SKYSWEEP" weather "$2" 2>"$work/err")
    echo "$out" | grep -q "^# irradiance $4" && echo "$out" | grep -q "^# model the DNI and DHI columns are the model's"
    tap_ok $? "$1: read as '$4' $(head -c 200 "$work/err")"
    if [ "$have_pvlib" -eq 0 ]; then
        tap_skip "$1: completed as pvlib does" "no pvlib at $python (tests/run.sh installs it)"
    else
        "$python" "$top/tests/pvlib/decomposition.py" "$SKYSWEEP" "$2" "$3" >"$work/out" 2>&1
        tap_ok $? "$1: completed as pvlib does: $(grep -v '^ok' "$work/out" | head -c 300) $(grep -o '[0-9]* of [0-9]* records within 0.1 %' "$work/out" | tr '\n' ' ')"
    fi
}
awk -F, -v OFS=, 'NR == 1 { print; next } { $8 = $9 = $10 = ""; print }' "$cut/greensboro_tmy3_jan_feb.csv" |
    sed 's/,,,,/,/' >"$work/tmy3_no_dni.csv"
completed "a TMY3 file without its DNI columns" "$work/tmy3_no_dni.csv" -79.95,36.1 "GHI and DHI"
awk -F, -v OFS=, 'NR <= 8 { print; next } { $15 = 9999; $16 = 9999; print }' "$cut/amsterdam_iwec_jan_feb.epw" \
    >"$work/epw_ghi.epw"
completed "an EPW whose DNI and DHI are 9999 throughout" "$work/epw_ghi.epw" 4.77,52.3 "GHI alone"
awk -F, -v OFS=, '/^time\(UTC\)|^20[0-9][0-9][01][0-9]/ { $5 = ""; sub(/,,/, ",") } { print }' \
    "$top/samples/weather/pvgis_tmy_45N_8E.csv" >"$work/pvgis_no_gbn.csv"
completed "a PVGIS CSV without Gb(n)" "$work/pvgis_no_gbn.csv" 8,45 "GHI and DHI"
sed 's/"Gb(n)": [-0-9.e]*, //g; s/"Gd(h)": [-0-9.e]*, //g' "$cut/pvgis_45N_8E_jan_feb.json" >"$work/pvgis_ghi.json"
completed "a PVGIS JSON without Gb(n) and Gd(h)" "$work/pvgis_ghi.json" 8,45 "GHI alone"
awk -F, -v OFS=, 'NR <= 2 { print; next } { $7 = $8 = ""; print }' "$top/tests/data/psm4_sample.csv" |
    sed 's/,,,/,/' >"$work/psm_ghi.csv"
completed "an NSRDB PSM file of GHI alone" "$work/psm_ghi.csv" -105.18,39.73 "GHI alone"
out=$("$SKYSWEEP" weather "$work/2006-06.ghi,dhi.csv")
echo "$out" | grep -q "^# irradiance GHI and DHI from the file; DNI = (GHI - DHI) / cos(zenith)" &&
    echo "$out" | grep -q "^# model applied at the DEM's sun in a run (--at LON,LAT shows it here)" &&
    echo "$out" | grep -q "^stamp,sun_time,duration_h,ghi,dni,dhi,temp_air,wind_speed,albedo,pressure$"
tap_ok $? "without a site, skysweep weather says where the model applies"
"$SKYSWEEP" weather --at 8,95 "$work/2006-06.ghi.csv" >/dev/null 2>"$work/err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ]
tap_ok $? "--at 8,95 is refused: exit $rc, $(cat "$work/err")"

# UMEP/SUEWS met files (issue 45): no zone in the file, so --weather-zone
# gives it, or the file is refused in one line; the zone also overrides an
# EPW's. The real file is UMEP's Gothenburg year in ../shared/data (its
# first line and 21 June here); the malformed ones are written inline.
umep=$weather/goteborg_tmy_1977_umep.txt
if [ -f "$umep" ]; then
    { head -n 1 "$umep"; awk 'NR > 1 && $2 == 172' "$umep"; } >"$work/umep.txt"
    "$SKYSWEEP" weather "$work/umep.txt" >/dev/null 2>"$work/err"
    rc=$?
    [ "$rc" -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ] &&
        grep -q "a UMEP/SUEWS met file, which states no time zone: give its stamps' zone with --weather-zone" "$work/err"
    tap_ok $? "a UMEP met file without --weather-zone is refused: exit $rc, $(cat "$work/err")"
    out=$("$SKYSWEEP" weather --weather-zone +01:00 "$work/umep.txt")
    noon=$(echo "$out" | grep '^1977-06-21T11:00:00Z' | cut -d, -f1-6)
    # Local noon (hour 12 at UTC+1) is 11:00Z; kdown, kdir, kdiff as given,
    # the sun at the middle of the hour ending there.
    [ "$noon" = "1977-06-21T11:00:00Z,1977-06-21T10:30:00Z,1,$(awk '$3 == 12 { printf "%g,%g,%g", $15, $23, $22 }' "$work/umep.txt")" ] &&
        [ "$(echo "$out" | grep -c '^1977-06')" -eq 24 ] && echo "$out" | grep -q "^# format UMEP/SUEWS met"
    tap_ok $? "a UMEP met file read with --weather-zone +01:00: $noon"
else
    tap_skip "a UMEP met file without --weather-zone is refused" "$umep is not here"
    tap_skip "a UMEP met file read with --weather-zone +01:00" "$umep is not here"
fi
umep_head='iy id it imin qn qh qe qs qf U RH Tair pres rain kdown snow ldown fcld wuh xsmd lai kdiff kdir wdir'
printf '%s\n1977 172 12 0 -999 -999 -999 -999 -999 3.1 50 18 101.2 0 700 -999 -999 -999 -999 -999 -999 -999 -999 -999\n1977 172 13 0 -999 -999 -999 -999 -999 3.1 50 18 101.2 0 650 -999 -999 -999 -999 -999 -999 -999 -999 -999\n' \
    "$umep_head" >"$work/umep_ghi.txt"
"$SKYSWEEP" weather --weather-zone +01:00 "$work/umep_ghi.txt" >"$work/out" 2>"$work/err"
grep -q "^# irradiance GHI alone" "$work/out" &&
    grep -q "^1977-06-21T11:00:00Z,1977-06-21T10:30:00Z,1,700,,,18,3.1,,1012$" "$work/out"
tap_ok $? "a UMEP file whose kdiff and kdir are -999 throughout gives GHI alone (pressure kPa to hPa) $(cat "$work/err")"
refused_zone() { # NAME CONTENT TEXT [ZONE]: exit 2 or 3, one line saying TEXT
    printf '%b' "$2" >"$work/$1"
    "$SKYSWEEP" weather --weather-zone "${4:-+01:00}" "$work/$1" >/dev/null 2>"$work/err"
    local rc=$?
    [ "$rc" -ge 2 ] && [ "$rc" -le 3 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -qF -- "$3" "$work/err"
    tap_ok $? "$1 refused: exit $rc, $(cat "$work/err")"
}
refused_zone umep_day367.txt "$umep_head\n1977 367 12 0 -999 -999 -999 -999 -999 3 50 18 101 0 700 -999 -999 -999 -999 -999 -999 -999 -999 -999\n" "line 2: a UMEP record starts with year, day of the year (1-366)"
refused_zone umep_day366.txt "$umep_head\n1977 366 12 0 -999 -999 -999 -999 -999 3 50 18 101 0 700 -999 -999 -999 -999 -999 -999 -999 -999 -999\n" "line 2: day 366 in 1977, which is not a leap year"
refused_zone umep_short.txt "$umep_head\n1977 172 12 0 -999 -999\n" "line 2: a UMEP record has as many fields as the column names"
refused_zone umep_no_kdown.txt 'iy id it imin Tair\n1977 172 12 0 18\n' "line 1: a UMEP met file's first line names iy, id, it, imin and kdown"
refused_zone zone_for_pvgis.csv 'Latitude (decimal degrees): 45\nLongitude (decimal degrees): 8\ntime(UTC),G(h),Gb(n),Gd(h)\n20180101:0000,1,2,3\n' "--weather-zone applies to files whose stamps are local time"
refused_zone bad_zone.txt "$umep_head\n" "--weather-zone expects a UTC offset such as +01:00" "+1:00x"
first=$("$SKYSWEEP" weather --weather-zone +02:00 "$cut/amsterdam_iwec_jan_feb.epw" | grep -v '^#' | sed -n 2p | cut -d, -f1)
[ "$first" = "1994-12-31T22:00:00Z" ]
tap_ok $? "--weather-zone +02:00 overrides an EPW's zone (+1): its first stamp is $first"

# TMY3 exports whose header differs from NREL's (issue 45): columns are
# matched by meaning (case, blanks, units in brackets, stray characters);
# only two columns of one meaning, or a unit other than NREL's, are refused.
sed '2s|Date (MM/DD/YYYY)|date (mm/dd/yyyy)|; 2s|Time (HH:MM)| TIME |; 2s|GHI (W/m^2)| ghi [W/m2]|; 2s|DNI (W/m^2)|DNI(W/m2)|; 2s|Dry-bulb (C)|DRY BULB (C)|; 2s|Wspd (m/s)|wspd_[m s-1]|' \
    "$cut/greensboro_tmy3_jan_feb.csv" >"$work/tmy3_odd.csv"
same_tmy3() { "$SKYSWEEP" weather "$1" | grep -v '^#' >"$work/a.csv"; "$SKYSWEEP" weather "$2" | grep -v '^#' >"$work/b.csv" 2>"$work/err"; [ -s "$work/a.csv" ] && cmp -s "$work/a.csv" "$work/b.csv"; }
same_tmy3 "$cut/greensboro_tmy3_jan_feb.csv" "$work/tmy3_odd.csv"
tap_ok $? "a TMY3 header with other case, blanks and brackets reads as NREL's $(head -c 200 "$work/err")"
sed '2s|Pressure (mbar)|Pressure (kPa)|' "$cut/greensboro_tmy3_jan_feb.csv" >"$work/tmy3_kpa.csv"
"$SKYSWEEP" weather "$work/tmy3_kpa.csv" >/dev/null 2>"$work/err"
rc=$?
[ "$rc" -eq 3 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "line 2: column 41 ('Pressure (kPa)') is not in Pressure's unit" "$work/err"
tap_ok $? "a TMY3 pressure in kPa is refused: exit $rc, $(cat "$work/err")"
sed '2s|DHI (W/m^2)|GHI|' "$cut/greensboro_tmy3_jan_feb.csv" >"$work/tmy3_two.csv"
"$SKYSWEEP" weather "$work/tmy3_two.csv" >/dev/null 2>"$work/err"
rc=$?
[ "$rc" -eq 3 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "line 2: columns 5 and 11 both read as GHI" "$work/err"
tap_ok $? "two TMY3 columns meaning GHI are refused: exit $rc, $(cat "$work/err")"

# Spreadsheet exports (issue 40): a UTF-8 byte-order mark, and ';' between
# fields with decimal commas (a European locale), read as the file they
# were made from: the TMY3 cut with a BOM, the PVGIS sample's first 60
# lines with ';' and ','.
same_records() { # ORIGINAL QUIRKY: the rows after the '#' lines are equal
    "$SKYSWEEP" weather "$1" | grep -v '^#' >"$work/a.csv"
    "$SKYSWEEP" weather "$2" | grep -v '^#' >"$work/b.csv" 2>"$work/err"
    [ -s "$work/a.csv" ] && cmp -s "$work/a.csv" "$work/b.csv"
}
printf '\357\273\277' | cat - "$cut/greensboro_tmy3_jan_feb.csv" >"$work/bom_tmy3.csv"
same_records "$cut/greensboro_tmy3_jan_feb.csv" "$work/bom_tmy3.csv"
tap_ok $? "a TMY3 file behind a UTF-8 byte-order mark reads as without it $(head -c 200 "$work/err")"
head -n 60 "$top/samples/weather/pvgis_tmy_45N_8E.csv" >"$work/pvgis60.csv"
tr ',.' ';,' <"$work/pvgis60.csv" >"$work/pvgis60_semicolon.csv"
same_records "$work/pvgis60.csv" "$work/pvgis60_semicolon.csv"
tap_ok $? "a PVGIS CSV with ';' separators and decimal commas reads as the original $(head -c 200 "$work/err")"
printf '\357\273\277' | cat - "$work/plain.csv" | tr ',.' ';,' >"$work/plain_bom_semicolon.csv"
same_records "$work/plain.csv" "$work/plain_bom_semicolon.csv"
tap_ok $? "a plain CSV with a BOM, ';' and decimal commas reads as the original"

# 29 February in a year that is not a leap year is named as such (it was
# 'an EPW record starts with year, month, day and hour').
sed '1424s/^1999,2,28,24,/1999,2,29,1,/' "$cut/amsterdam_iwec_jan_feb.epw" >"$work/feb29.epw"
"$SKYSWEEP" weather "$work/feb29.epw" >/dev/null 2>"$work/err"
rc=$?
[ "$rc" -eq 3 ] && [ "$(wc -l <"$work/err")" -eq 1 ] &&
    grep -q "29 February in 1999, which is not a leap year, line 1424" "$work/err"
tap_ok $? "29 February 1999 in an EPW is named: exit $rc, $(cat "$work/err")"
sed '3s|^01/01/1988|02/29/1989|' "$cut/greensboro_tmy3_jan_feb.csv" >"$work/feb29_tmy3.csv"
"$SKYSWEEP" weather "$work/feb29_tmy3.csv" >/dev/null 2>"$work/err"
grep -q "29 February in 1989, which is not a leap year, line 3" "$work/err"
tap_ok $? "29 February 1989 in a TMY3 file is named: $(cat "$work/err")"
printf 'Latitude (decimal degrees): 45\nLongitude (decimal degrees): 8\ntime(UTC),G(h),Gb(n),Gd(h)\n20230229:0000,1,2,3\n' >"$work/feb29_pvgis.csv"
"$SKYSWEEP" weather "$work/feb29_pvgis.csv" >/dev/null 2>"$work/err"
grep -q "29 February in 2023, which is not a leap year, line 4" "$work/err"
tap_ok $? "29 February 2023 in a PVGIS file is named: $(cat "$work/err")"
printf 'time,ghi\n2023-02-29T10:00Z,1\n' >"$work/feb29_plain.csv"
"$SKYSWEEP" weather "$work/feb29_plain.csv" >/dev/null 2>"$work/err"
[ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "line 2: .*February 2023 has 28 days" "$work/err"
tap_ok $? "29 February 2023 in a plain CSV is named at its line: $(cat "$work/err")"

# refused NAME CONTENT: exit 3, one line that names the file.
refused() {
    local name=$1
    printf '%b' "$2" >"$work/$name"
    "$SKYSWEEP" weather "$work/$name" >/dev/null 2>"$work/err"
    local rc=$?
    [ "$rc" -eq 3 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "$name" "$work/err"
    tap_ok $? "$name refused: exit $rc, $(head -c 250 "$work/err")"
}
refused empty.csv ''
refused binary.epw 'LOCATION,\0\1\2'
refused no_columns.csv 'when,sun\n2026-06-21T10:00Z,1\n'
# What a file no reader takes lacks, named (it was 'not a weather file').
refused_saying() { # NAME CONTENT TEXT
    refused "$1" "$2"
    grep -qF "$3" "$work/err"
    tap_ok $? "$1: the message says \"$3\""
}
refused_saying tabs.csv 'time\tghi\n2026-06-21T10:00Z\t1\n' "first line 'time?ghi' is none of EPW's, TMY3's, TMY2's, PVGIS's or NSRDB PSM/SAM CSV's, and as a CSV header it has no separated columns"
refused_saying no_time.csv 'date;ghi\n2026-06-21T10:00Z;1\n' "its first line 'date,ghi' is none of"
refused_saying no_ghi.csv 'time,global\n2026-06-21T10:00Z,1\n' "it has no 'ghi' column"
refused_saying dni_alone.csv 'time,ghi,dni\n2026-06-21T10:00Z,1,1\n' "it has 'dni' without 'dhi'"
refused no_zone.csv 'time,ghi,dni,dhi\n2026-06-21T10:00,1,2,3\n'
refused short.epw 'LOCATION,x,-,y,z,1,45,8,1,250\nDESIGN CONDITIONS,0\nDATA PERIODS,1,1,Data,Sunday, 1/ 1,12/31\n2018,1,1,1,0,?,2,3\n'
refused bad_location.epw 'LOCATION,x,-,y,z,1,145,8,1,250\nDATA PERIODS,1\n'
refused broken.json '{"inputs": {"location": {"latitude": 45'
refused other.json '{"a": 1}'
refused bad_time.csv 'Latitude (decimal degrees): 45\nLongitude (decimal degrees): 8\ntime(UTC),G(h),Gb(n),Gd(h)\n2018011:0000,1,2,3\n'
refused_saying short.tm2 "$(head -3 "$tm2" | cut -c1-100)" "line 2: a TMY2 record has 142 characters"
refused_saying bad_hour.tm2 "$(head -2 "$tm2" | sed '2s/^\(.\{7\}\)01/\125/')" "line 2: a TMY2 record starts with year (2 digits), month (1-12), day and hour (1-24)"
refused_saying tmy3_no_ghi.csv "$(head -3 "$cut/greensboro_tmy3_jan_feb.csv" | sed '2s/,GHI (W\/m^2),/,GHX,/')" "line 2: the TMY3 column names lack GHI (W/m^2)"
refused_saying pvgis_no_gh.csv 'Latitude (decimal degrees): 45\nLongitude (decimal degrees): 8\ntime(UTC),Gb(n),Gd(h)\n20180101:0000,2,3\n' "line 3: the PVGIS columns lack G(h)"
refused_saying psm_minute60.csv "$(head -3 "$cut/nsrdb_psm4_5min_cut.csv")\n2023,1,1,9,60,0.1,0.024,48,808,264,0,6,-0.4,41,0,0,41,0.294,96.74,74.47,0.95,0.65,770,1,188,4.5\n" "line 4: a PSM record's date or time is not valid"
refused_saying psm_back_in_month.csv "$(head -5 "$cut/nsrdb_psm4_tmy_stitched.csv")\n2019,1,31,23,30,-8.1,0.012,0,0,0,0,4,-9.4,0,0,0,0,0.339,90.28,159.73,0.91,0.8,779,0.5,246,1.8\n" "the records' times do not increase (record 3)"
refused_saying pvgis_hourly_30deg.csv "$(cat "$cut/pvgis_hourly_45N_8E_30deg_2016.csv")" "is a PVGIS hourly series on a plane tilted 30 degrees, not global horizontal irradiance"
sed 's/"slope": {"value": 0/"slope": {"value": 35/' "$cut/pvgis_hourly_45N_8E_0deg_2016.json" >"$work/tilted.json"
refused_saying pvgis_hourly_35deg.json "$(cat "$work/tilted.json")" "is a PVGIS hourly series on a plane tilted 35 degrees"
refused_saying sam_no_latitude.csv 'lon,tz\n-108.54,-7\nYear,Month,Day,Hour,Minute,GHI\n2023,1,1,7,30,0\n' "none of EPW's"
refused_saying sam_bad_zone.csv 'lat,lon,tz\n40.53,-108.54,x\nYear,Month,Day,Hour,Minute,GHI\n2023,1,1,7,30,0\n' "line 2: the PSM/SAM metadata's Time Zone is not hours from UTC (-14..14)"
refused_saying sam_no_ghi.csv 'lat,lon,tz\n40.53,-108.54,-7\nYear,Month,Day,Hour,Minute,DNI\n2023,1,1,7,30,0\n' "line 3: the PSM/SAM columns lack Year, Month, Day, Hour, Minute or GHI"
# Gaps (issue 45, item 4): records absent from a file's spacing are counted;
# a file most of whose records are absent or missing is refused in one line.
sed '100,129d' "$cut/greensboro_tmy3_jan_feb.csv" >"$work/tmy3_gap.csv"
"$SKYSWEEP" weather "$work/tmy3_gap.csv" | grep -q "^# records 1386, 0 with an irradiance value missing, 30 absent from the file's spacing"
tap_ok $? "30 records cut from a TMY3 file are counted absent: $("$SKYSWEEP" weather "$work/tmy3_gap.csv" 2>&1 | grep '^# records')"
awk 'NR <= 2 || NR % 3 == 0' "$cut/greensboro_tmy3_jan_feb.csv" >"$work/tmy3_sparse.csv"
refused_saying tmy3_sparse.csv "$(cat "$work/tmy3_sparse.csv")" "is mostly gaps: 940 of its 1412 records are absent (940) or lack an irradiance value (0), more than half"
refused_saying epw_mostly_missing.epw "$(awk -F, -v OFS=, 'NR > 8 && NR % 3 != 0 { $14 = 9999 } { print }' "$cut/amsterdam_iwec_jan_feb.epw")" "is mostly gaps: 944 of its 1416 records are absent (0) or lack an irradiance value (944), more than half"
refused backwards.csv 'time,ghi,dni,dhi\n2026-06-21T10:00Z,1,2,3\n2026-06-21T10:00Z,1,2,3\n'
refused back_later.csv 'time,ghi,dni,dhi\n2026-06-21T10:00Z,1,2,3\n2026-06-21T11:00Z,1,2,3\n2026-06-21T10:30Z,1,2,3\n'
refused no_irradiance.csv 'time,ghi,dni,dhi\n2026-06-21T10:00Z,,,\n2026-06-21T11:00Z,,,\n'
mkdir "$work/folder.csv"
"$SKYSWEEP" weather "$work/folder.csv" >/dev/null 2>"$work/err"
rc=$?
[ "$rc" -eq 3 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && grep -q "not a regular file" "$work/err"
tap_ok $? "a folder is refused as not a regular file (it once said 'over 512 MiB'): exit $rc, $(cat "$work/err")"
"$SKYSWEEP" weather "$work/missing.epw" >/dev/null 2>"$work/err"
rc=$?
[ "$rc" -eq 3 ] && grep -q "No such file" "$work/err"
tap_ok $? "a missing file is refused: exit $rc, $(cat "$work/err")"
tap_done
