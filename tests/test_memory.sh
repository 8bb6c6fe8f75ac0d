#!/bin/bash
# Bounded memory: a DEM whose whole-grid sweep needs several times --memory
# is swept in bands (exactly: its SVF equals the whole-grid run's), and
# the peak resident memory the process reports (getrusage) stays within
# --memory, the program and its libraries included (tests/test_memory_bound.sh
# checks every product on the C twin and PoCL); a horizon swept whole, with
# all its outputs, within --memory too. Horizons (with distances and casting heights), shadows and
# insolation (exact and interpolated shadows) and hillshade's sweeping layers
# band too, with the same results. Bad sizes are refused in one line.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
. "${TOP_SRCDIR:-.}/tests/raster_compare.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-memory.XXXXXX")
trap 'rm -rf "$work"' EXIT

# 2400 x 2000 cells of rolling hills (UTM 5N, 10 m): a whole-grid sweep
# holds up to 24 bytes a cell (110 MiB) and 48 MiB of buffers, against --memory 128M.
awk 'BEGIN {
    W = 2400; H = 2000
    print "ncols " W; print "nrows " H; print "xllcorner 254325"; print "yllcorner 2140000"
    print "cellsize 10"; print "NODATA_value -9999"
    for (r = 0; r < H; r++) {
        line = ""
        for (c = 0; c < W; c++) {
            v = 300 * sin(c / 170.0) * cos(r / 230.0) + 90 * sin((c + 2 * r) / 61.0) \
                + 25 * sin(c / 13.0 + r / 17.0) + 7 * sin((c * 7 + r * 3) / 5.0)
            line = line sprintf("%.2f ", 600 + v)
        }
        print line
    }
}' >"$work/dem.asc"
gdal_translate -q -ot Float32 -a_srs EPSG:32605 -co TILED=YES "$work/dem.asc" "$work/dem.tif"
# The same with an ocean: 60 rows of nodata on top, and 50 more across the middle.
awk 'NR <= 6 { print; next } { r = NR - 7 }
     r < 60 || (r >= 1000 && r < 1050) { line = ""; for (i = 1; i <= NF; i++) line = line "-9999 "; print line; next }
     { print }' "$work/dem.asc" >"$work/sea.asc"
gdal_translate -q -ot Float32 -a_srs EPSG:32605 -co TILED=YES "$work/sea.asc" "$work/sea.tif"
rm -f "$work/dem.asc" "$work/sea.asc"
gdal_translate -q -srcwin 0 0 40 40 "$work/dem.tif" "$work/tiny.tif"

peak() { sed -n 's/^memory  peak resident \([0-9]*\) MiB.*/\1/p' "$1"; }
# bands_budget BUDGET COMMAND ARGS...: BUDGET, which bands the command here;
# a sanitizer build's process is larger (AddressSanitizer's shadow memory),
# so there the least budget the command names, and 4 MiB more.
bands_budget() {
    budget=$1
    shift
    if "$SKYSWEEP" info | grep -q 'sanitizers yes'; then
        least=$("$SKYSWEEP" "$@" --memory 1M "$work/dem.tif" "$work/least.tif" 2>&1 |
            sed -n 's/.*at least --memory \([0-9]*\)M.*/\1/p')
        budget=$((${least:-124} + 4))M
    fi
    echo "$budget"
}

svf_budget=$(bands_budget 128M svf --directions 8 --device reference)
"$SKYSWEEP" svf --directions 8 --memory "$svf_budget" --device reference "$work/dem.tif" \
    "$work/banded.tif" >"$work/banded.out"
rc=$?
used=$(peak "$work/banded.out")
grep -q '^bands ' "$work/banded.out"
tap_ok $? "a DEM needing ~140 MiB whole is swept in bands under --memory $svf_budget (exit $rc): $(grep '^bands ' "$work/banded.out" | cut -c1-80)"
if "$SKYSWEEP" info | grep -q 'sanitizers yes'; then
    tap_skip "peak resident memory within the bound" "AddressSanitizer's shadow memory and quarantine inflate it"
else
    [ -n "$used" ] && [ "$used" -le 128 ]
    tap_ok $? "peak resident ${used:-?} MiB <= --memory 128M, the program included"
fi

"$SKYSWEEP" svf --directions 8 --device reference -q "$work/dem.tif" "$work/whole.tif"
worst=$(worst_of "$work/whole.tif" "$work/banded.tif" 1)
worst_within "$worst" 1e-6
tap_ok $? "banded SVF == whole-grid SVF (worst $worst)"

# A window of the banded run equals the same window of the whole-grid run.
win="260325 2155000 272325 2146000"
"$SKYSWEEP" svf --directions 8 --memory "$svf_budget" --device reference -q -projwin $win "$work/dem.tif" "$work/bwin.tif"
gdal_translate -q -projwin $win "$work/whole.tif" "$work/wcut.tif"
size=$(gdalinfo "$work/bwin.tif" | grep 'Size is')
worst=$(worst_of "$work/bwin.tif" "$work/wcut.tif" 1)
[ "$size" = "Size is 1200, 900" ] && worst_within "$worst" 1e-6
tap_ok $? "banded -projwin window == the whole-grid output's window ($size, worst $worst)"

"$SKYSWEEP" svf --memory 20M "$work/dem.tif" "$work/x.tif" 2>"$work/err"
rc=$?
[ "$rc" -eq 6 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && [ ! -e "$work/x.tif" ]
tap_ok $? "--memory too small for one band: exit $rc, $(head -c 120 "$work/err")"
# Horizons, with distances and casting heights, in bands: the same files.
horizon_budget=$(bands_budget 128M horizon --directions 4 --device reference --distance \
    "$work/hd_least.tif" --cast-height "$work/hc_least.tif")
"$SKYSWEEP" horizon --directions 4 --memory "$horizon_budget" --device reference --distance "$work/hd_b.tif" \
    --cast-height "$work/hc_b.tif" "$work/dem.tif" "$work/h_b.tif" >"$work/hb.out"
rc=$?
used=$(peak "$work/hb.out")
grep -q '^bands ' "$work/hb.out"
tap_ok $? "horizon with distances and casting heights is swept in bands under --memory $horizon_budget (exit $rc): $(grep '^bands ' "$work/hb.out" | cut -c1-80)"
if "$SKYSWEEP" info | grep -q 'sanitizers yes'; then
    tap_skip "horizon's peak resident memory within the bound" "AddressSanitizer inflates it"
else
    [ -n "$used" ] && [ "$used" -le 128 ]
    tap_ok $? "horizon: peak resident ${used:-?} MiB <= --memory 128M"
fi
# Swept whole, horizon writes its outputs direction by direction, and GDAL's
# block cache held their written blocks up to its default, 5 % of the RAM (8
# directions of angles, distances and casting heights are 440 MiB: with 16,
# 1112 MiB peak under --memory 256M). The cache is now among the fixed
# buffers counted, and the outputs' blocks a whole grid holds (the plan
# may band it for them): the peak stays within --memory, the program included.
"$SKYSWEEP" horizon --directions 8 --memory 256M --device reference --distance "$work/wd.tif" \
    --cast-height "$work/wc.tif" "$work/dem.tif" "$work/wh.tif" >"$work/wh.out"
rc=$?
used=$(peak "$work/wh.out")
if "$SKYSWEEP" info | grep -q 'sanitizers yes'; then
    tap_skip "whole-grid horizon's peak resident memory within --memory" "AddressSanitizer inflates it"
else
    [ "$rc" -eq 0 ] && grep -q '^memory ' "$work/wh.out" && [ -n "$used" ] &&
        [ "$used" -le 256 ]
    tap_ok $? "horizon with distances and casting heights under --memory 256M: peak resident ${used:-?} MiB <= --memory 256M (exit $rc)"
fi
rm -f "$work/wd.tif" "$work/wc.tif" "$work/wh.tif"
# Within a radius of 50 cells (hulls, whose stack grid holds a hull point a
# cell): banded under the bound, the whole grid's values.
"$SKYSWEEP" svf --radius 500 --directions 8 --device reference "$work/dem.tif" \
    --memory "$(bands_budget 128M svf --radius 500 --directions 8 --device reference)" \
    "$work/r_b.tif" >"$work/rb.out"
rc=$?
used=$(peak "$work/rb.out")
"$SKYSWEEP" svf --radius 500 --directions 8 --device reference -q "$work/dem.tif" "$work/r_w.tif"
w=$(worst_of "$work/r_w.tif" "$work/r_b.tif" 1)
grep -q '^bands ' "$work/rb.out" && worst_within "$w" 1e-6
tap_ok $? "svf within 500 m in bands == whole grid (worst $w; exit $rc): $(grep '^bands ' "$work/rb.out" | cut -c1-60)"
if "$SKYSWEEP" info | grep -q 'sanitizers yes'; then
    tap_skip "radius SVF's peak resident memory within the bound" "AddressSanitizer inflates it"
else
    [ -n "$used" ] && [ "$used" -le 128 ]
    tap_ok $? "svf within 500 m: peak resident ${used:-?} MiB <= --memory 128M"
fi
"$SKYSWEEP" horizon --directions 4 --device reference -q --distance "$work/hd_w.tif" \
    --cast-height "$work/hc_w.tif" "$work/dem.tif" "$work/h_w.tif"
wa=$(worst_of "$work/h_w.tif" "$work/h_b.tif")
wd=$(worst_of "$work/hd_w.tif" "$work/hd_b.tif")
wc=$(worst_of "$work/hc_w.tif" "$work/hc_b.tif")
worst_within "$wa" 1e-4 "$wd" 1e-2 "$wc" 1e-2
tap_ok $? "banded horizon == whole grid in 4 azimuths: angles worst $wa deg, distances $wd m, casting heights $wc m"

# Shadows in bands, for a given sun and for an instant with a sun per cell.
for sun in "--sun-azimuth 120 --sun-elevation 9" "--time 2026-12-21T16:30:00-10:00 --sun-per-cell on"; do
    # shellcheck disable=SC2086
    "$SKYSWEEP" shadow $sun --memory 128M "$work/dem.tif" "$work/s_b.tif" >"$work/sb.out"
    rc=$?
    # shellcheck disable=SC2086
    "$SKYSWEEP" shadow $sun --device reference -q "$work/dem.tif" "$work/s_w.tif"
    w=$(worst_of "$work/s_w.tif" "$work/s_b.tif")
    lit=$(sed -n 's/^shadow  \([0-9.]*\) %.*/\1/p' "$work/sb.out")
    grep -q '^bands ' "$work/sb.out" && worst_within "$w" 1e-6 &&
        awk -v l="$lit" 'BEGIN { exit !(l > 1 && l < 99) }'
    tap_ok $? "banded shadow ($sun) == whole grid in all 3 bands (worst $w; $lit % sunlit; exit $rc)"
done

# Insolation in bands (a sun per cell, five steps): the same totals and steps.
sun="--time 2026-12-21T07:00-10:00/PT10H --step PT2H --sun-per-cell on"
# shellcheck disable=SC2086
"$SKYSWEEP" insolation $sun --memory 320M --device reference --steps "$work/is_b.tif" "$work/dem.tif" \
    "$work/i_b.tif" >"$work/ib.out"
rc=$?
# shellcheck disable=SC2086
"$SKYSWEEP" insolation $sun --device reference -q --steps "$work/is_w.tif" "$work/dem.tif" \
    "$work/i_w.tif"
wg=$(worst_of "$work/i_w.tif" "$work/i_b.tif" 1)
wh=$(worst_of "$work/i_w.tif" "$work/i_b.tif" 5)
ws=$(worst_of "$work/is_w.tif" "$work/is_b.tif")
grep -q '^bands ' "$work/ib.out" && worst_within "$wg" 0.01 "$wh" 1e-6 "$ws" 0.01
tap_ok $? "banded insolation == whole grid: global worst $wg Wh/m2, sun hours $wh h, steps $ws Wh/m2 (exit $rc): $(grep '^bands ' "$work/ib.out" | cut -c1-60)"
# Interpolated shadows store every direction's horizons: in bands they wait
# in a temporary file until the bands' steps need them.
# shellcheck disable=SC2086
"$SKYSWEEP" insolation $sun --shadow interpolated --memory 320M --device reference "$work/dem.tif" \
    "$work/ii_b.tif" >"$work/iib.out"
rc=$?
# shellcheck disable=SC2086
"$SKYSWEEP" insolation $sun -q --shadow interpolated --device reference "$work/dem.tif" \
    "$work/ii_w.tif"
wg=$(worst_of "$work/ii_w.tif" "$work/ii_b.tif" 1)
grep -q '^bands ' "$work/iib.out" && worst_within "$wg" 0.01
tap_ok $? "interpolated shadows in bands == whole grid: global worst $wg Wh/m2 (exit $rc)"
# A plain hillshade in bands: the same bytes as on the whole grid.
"$SKYSWEEP" hillshade --multidirectional --memory 128M "$work/dem.tif" "$work/hs_b.tif" >"$work/hs.out"
rc=$?
"$SKYSWEEP" hillshade --multidirectional -q "$work/dem.tif" "$work/hs_w.tif"
w=$(worst_of "$work/hs_w.tif" "$work/hs_b.tif" 1)
grep -q '^bands ' "$work/hs.out" && [ "$w" = 0 ]
tap_ok $? "banded hillshade == whole grid, every byte (worst $w; exit $rc)"
# Nodata rows on top (the heights' origin is looked for below them, once)
# and a band of nodata in the middle, which some bands hold alone.
"$SKYSWEEP" shadow --sun-azimuth 200 --sun-elevation 15 --memory 113M "$work/sea.tif" "$work/ss_b.tif" >"$work/ss.out"
rc=$?
"$SKYSWEEP" shadow --sun-azimuth 200 --sun-elevation 15 --device reference -q "$work/sea.tif" "$work/ss_w.tif"
"$SKYSWEEP" hillshade --memory 113M -q "$work/sea.tif" "$work/sh_b.tif"
rc2=$?
"$SKYSWEEP" hillshade -q "$work/sea.tif" "$work/sh_w.tif"
w=$(worst_of "$work/ss_w.tif" "$work/ss_b.tif")
w2=$(worst_of "$work/sh_w.tif" "$work/sh_b.tif" 1)
grep -q '^bands ' "$work/ss.out" && [ "$w" = 0 ] && [ "$w2" = 0 ] && [ "$rc" -eq 0 ] && [ "$rc2" -eq 0 ]
tap_ok $? "an ocean on top and across the middle: banded shadow and hillshade == whole grid (worst $w and $w2; exits $rc, $rc2)"
# Hillshade's sweeping layers band too: the sky view is swept first and kept
# in a temporary file, the cast shadows walk with the shading.
"$SKYSWEEP" hillshade --sky-view 0.3 --cast-shadows --directions 8 \
    --memory "$(bands_budget 128M hillshade --sky-view 0.3 --cast-shadows --directions 8)" \
    "$work/dem.tif" "$work/hv_b.tif" >"$work/hv.out"
rc=$?
"$SKYSWEEP" hillshade --sky-view 0.3 --cast-shadows --directions 8 -q --device reference \
    "$work/dem.tif" "$work/hv_w.tif"
w=$(worst_of "$work/hv_w.tif" "$work/hv_b.tif" 1)
grep -q '^bands ' "$work/hv.out" && worst_within "$w" 1
tap_ok $? "hillshade with sky view and cast shadows in bands == whole grid (worst $w; exit $rc)"

"$SKYSWEEP" svf --memory lots "$work/tiny.tif" "$work/x.tif" 2>"$work/err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ]
tap_ok $? "--memory lots: exit $rc, $(head -c 120 "$work/err")"
tap_done
