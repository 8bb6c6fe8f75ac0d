#!/bin/bash
# Hard cases through the command line (the library half is
# tests/test_hardcases.c): every product on
#   - the same heights stored as Int16, UInt16, Int32, Float32 and Float64
#     (with their nodata values), and as Float32 with NaN holes and no
#     nodata tag: all five types must give identical outputs (the reader
#     turns every type into the same float heights), nodata -9999 exactly
#     where the input has none, no NaN;
#   - lat/lon grids (EPSG:4326) at 89.9 N, across the antimeridian and on
#     the equator, where the DEM frame turns degrees into ground metres
#     (cells 800 times narrower than tall near the pole): no NaN, values in
#     range, and on flat ground the exact answers (SVF 1 everywhere, every
#     horizon with terrain ahead 0, every cell lit by a sun above it).
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-hard.XXXXXX")
trap 'rm -rf "$work"' EXIT

run() { # runs skysweep quietly; exit code in $rc (and returned), stderr kept
    "$SKYSWEEP" "$@" -q >"$work/stdout" 2>"$work/stderr"
    rc=$?
    [ $rc -eq 0 ] || cat "$work/stderr" >>"$work/all_errors"
    return $rc
}

# ascii_grid FILE NCOLS NROWS XLL YLL CELL NODATA EXPR: an ESRI ASCII grid
# whose value at (c, r) is the awk expression EXPR (r = 0 is the top row).
ascii_grid() {
    awk -v nc="$2" -v nr="$3" -v x="$4" -v y="$5" -v cs="$6" -v nd="$7" "BEGIN {
        print \"ncols \" nc; print \"nrows \" nr; print \"xllcorner \" x
        print \"yllcorner \" y; print \"cellsize \" cs; print \"NODATA_value \" nd
        for (r = 0; r < nr; r++) {
            line = \"\"
            for (c = 0; c < nc; c++) { v = $8; line = line v \" \" }
            print line
        }
    }" >"$1"
}

# all_values FILE BAND: every value of a band, one per line (AAIGrid text).
all_values() {
    gdal_translate -q -of AAIGrid -b "$2" "$1" "$work/values.asc" >/dev/null 2>&1 &&
        tail -n +7 "$work/values.asc" | tr -s ' ' '\n' | grep -v '^$'
}

# in_range FILE BAND LO HI [NODATA]: no NaN/Inf, every value NODATA
# (default -9999; hillshades are Byte with 0) or in [LO, HI]; prints the
# offending count.
in_range() {
    all_values "$1" "$2" | awk -v lo="$3" -v hi="$4" -v nd="${5:--9999}" '
        { v = $1 }
        tolower(v) ~ /nan|inf/ { bad++; next }
        v + 0 == nd + 0 { next }
        v + 0 < lo || v + 0 > hi { bad++ }
        END { print bad + 0 }'
}

# ---- reader data types ------------------------------------------------------------
# A 40 x 30 hill in UTM 5N, integer heights 100..1300 m, with a 3 x 2 hole.
ascii_grid "$work/hill.asc" 40 30 254325 2152155 30 -9999 \
    '(r >= 10 && r < 12 && c >= 5 && c < 8) ? -9999 : int(100 + 1200 * exp(-((c - 22) ^ 2 + (r - 14) ^ 2) / 60))'
types="Int16:-32768 UInt16:65535 Int32:-2147483648 Float32:-9999 Float64:-9999"
gdal_translate -q -ot Float32 -a_srs EPSG:32605 "$work/hill.asc" "$work/hill_f32.tif"
for t in $types; do
    ty=${t%%:*} nd=${t#*:}
    # The hole gets the type's own nodata value (-9999 does not fit UInt16).
    gdalwarp -q -srcnodata -9999 -dstnodata "$nd" -ot "$ty" "$work/hill_f32.tif" "$work/hill_$ty.tif"
done
# Float32 with NaN in the hole and no nodata tag at all.
gdalwarp -q -srcnodata -9999 -dstnodata nan -ot Float32 "$work/hill_f32.tif" "$work/nan_tagged.tif"
gdal_translate -q -a_nodata none "$work/nan_tagged.tif" "$work/hill_NaN.tif"
gdalinfo "$work/hill_NaN.tif" | grep -q 'NoData' && tap_diag "NaN file still carries a nodata tag"

products() { # DEM PREFIX: runs every product, returns the number of failed runs
    local dem=$1 p=$2 failed=0
    run svf --directions 16 "$dem" "$p.svf.tif" || failed=$((failed + 1))
    run horizon --directions 8 --distance "$p.dist.tif" "$dem" "$p.hor.tif" ||
        failed=$((failed + 1))
    run shadow --sun-azimuth 135 --sun-elevation 20 "$dem" "$p.sh.tif" || failed=$((failed + 1))
    run hillshade "$dem" "$p.hs.tif" || failed=$((failed + 1))
    run insolation --time 2026-06-21T00:00Z/PT24H --step PT3H --directions 8 "$dem" \
        "$p.ins.tif" || failed=$((failed + 1))
    return $failed
}

for t in $types NaN:nan; do
    ty=${t%%:*}
    : >"$work/all_errors"
    products "$work/hill_$ty.tif" "$work/$ty"
    tap_ok $? "$ty DEM: svf, horizon, shadow, hillshade and insolation all run ($(head -c 200 "$work/all_errors"))"
done
# Identical outputs: the raw bytes of every band of every product.
dump() { # PREFIX: all products' raw data into PREFIX.all.bin, floats into PREFIX.f32.bin
    local p=$1 f
    : >"$p.all.bin"
    : >"$p.f32.bin"
    for f in svf hor dist sh hs ins; do
        gdal_translate -q -of ENVI "$p.$f.tif" "$p.$f.bin" >/dev/null 2>&1 || return 1
        cat "$p.$f.bin" >>"$p.all.bin"
        [ $f = hs ] || cat "$p.$f.bin" >>"$p.f32.bin" # hillshades are Byte
    done
}
dump "$work/Float32"
for ty in Int16 UInt16 Int32 Float64 NaN; do
    dump "$work/$ty"
    cmp -s "$work/Float32.all.bin" "$work/$ty.all.bin" && [ -s "$work/$ty.all.bin" ]
    tap_ok $? "$ty DEM gives exactly the Float32 DEM's outputs ($(wc -c <"$work/$ty.all.bin") bytes)"
done
# Nodata exactly at the hole (6 cells), and no NaN or Inf in any output.
for ty in Int16 NaN; do
    holes=$(gdallocationinfo -valonly "$work/$ty.svf.tif" 6 10)
    nan=$(od -An -v -f "$work/$ty.f32.bin" | grep -ci 'nan\|inf')
    count=$(all_values "$work/$ty.svf.tif" 1 | grep -c '^-9999$')
    [ "$holes" = "-9999" ] && [ "$nan" -eq 0 ] && [ "$count" -eq 6 ]
    tap_ok $? "$ty DEM: SVF nodata exactly at the 6 hole cells ($count, value there $holes), no NaN or Inf in any output ($nan lines)"
done
# Physical ranges on the hill (Float32 run): SVF, horizons, shadow, hillshade.
f=$work/Float32
bad=$(($(in_range "$f.svf.tif" 1 0 1) + $(in_range "$f.sh.tif" 1 0 1) +
    $(in_range "$f.hs.tif" 1 1 255 0) + $(in_range "$f.ins.tif" 1 0 1e5) + $(in_range "$f.ins.tif" 5 0 24)))
for b in $(seq 1 8); do bad=$((bad + $(in_range "$f.hor.tif" "$b" -90 90))); done
tap_ok "$bad" "hill: SVF in [0, 1], horizons in [-90, 90], sunlit in {0, 1}, hillshade in [1, 255], irradiation >= 0, hours of sun <= 24 ($bad outside)"

# ---- geographic grids ---------------------------------------------------------------
# name:xll:yll:local noon in UTC (cells of 0.001 deg, 40 x 30). At 89.9 N
# the June sun stands near 23 deg all day; at 17 S (Fiji) and on the
# equator it is high at local noon.
geo_cases="pole:10:89.92:12:00 antimeridian:179.98:-17.015:00:00 equator:-0.02:-0.015:12:00"
for g in $geo_cases; do
    IFS=: read -r name xll yll hh mm <<<"$g"
    noon=2026-06-21T$hh:${mm}Z
    shapes="flat hill"
    [ "$name" = equator ] && shapes=flat # the least unusual place: its known answer only
    for shape in $shapes; do
        if [ $shape = flat ]; then expr=250; else
            expr='250 + 200 * exp(-((c - 20) ^ 2 + (r - 15) ^ 2) / 30)'
        fi
        ascii_grid "$work/$name.asc" 40 30 "$xll" "$yll" 0.001 -9999 "$expr"
        dem=$work/${name}_$shape.tif
        gdal_translate -q -ot Float32 -a_srs EPSG:4326 "$work/$name.asc" "$dem"
        p=$work/${name}_$shape
        failed=0
        : >"$work/all_errors"
        run svf --directions 16 "$dem" "$p.svf.tif" || failed=$((failed + 1))
        if [ $shape = flat ]; then
            run svf --directions 16 --definition radiative "$dem" "$p.svfr.tif" ||
                failed=$((failed + 1))
        else
            cp "$p.svf.tif" "$p.svfr.tif"
        fi
        run horizon --directions 8 "$dem" "$p.hor.tif" || failed=$((failed + 1))
        run shadow --time "$noon" --sun-per-cell on "$dem" "$p.sh.tif" || failed=$((failed + 1))
        run hillshade "$dem" "$p.hs.tif" || failed=$((failed + 1))
        run insolation --time 2026-06-21T00:00Z/PT24H --step PT4H --directions 8 \
            --sun-per-cell on "$dem" "$p.ins.tif" || failed=$((failed + 1))
        tap_ok $failed "$name ($xll E, $yll N), $shape: every product runs ($(head -c 200 "$work/all_errors"))"
        [ $failed -eq 0 ] || continue
        bad=$(($(in_range "$p.svf.tif" 1 0 1) + $(in_range "$p.svfr.tif" 1 0 1) +
            $(in_range "$p.sh.tif" 1 0 1) + $(in_range "$p.hs.tif" 1 1 255 0) +
            $(in_range "$p.ins.tif" 1 0 1e5) + $(in_range "$p.ins.tif" 5 0 24)))
        for b in $(seq 1 8); do bad=$((bad + $(in_range "$p.hor.tif" "$b" -90 90))); done
        tap_ok "$bad" "$name, $shape: no NaN, every value in its range ($bad not)"
        if [ $shape = flat ]; then
            # Flat ground: SVF exactly 1; horizons 0 two cells inside the
            # grid; the noon sun, above the horizontal, lights every cell.
            notone=$( (all_values "$p.svf.tif" 1; all_values "$p.svfr.tif" 1) | awk '$1 != 1' | wc -l)
            inner=0
            for b in $(seq 1 8); do
                inner=$((inner + $(gdal_translate -q -of AAIGrid -b "$b" -srcwin 2 2 36 26 \
                    "$p.hor.tif" "$work/in.asc" >/dev/null 2>&1 &&
                    tail -n +7 "$work/in.asc" | tr -s ' ' '\n' | grep -v '^$' | awk '$1 != 0' | wc -l)))
            done
            dark=$(all_values "$p.sh.tif" 1 | awk '$1 != 1' | wc -l)
            [ "$notone" -eq 0 ] && [ "$inner" -eq 0 ] && [ "$dark" -eq 0 ]
            tap_ok $? "$name, flat: SVF exactly 1 ($notone not), inner horizons exactly 0 ($inner not), all lit at local noon $noon ($dark dark)"
        fi
    done
done

# ---- grids one cell thin --------------------------------------------------------------
# One row and one column in UTM 5N, 30 m cells, the sun per cell: its
# lattice then has two nodes on the one row (or column), which once left
# the one-row grid's sun with no lattice rows at all.
for shape in row:40:1 column:1:30; do
    IFS=: read -r name nc nr <<<"$shape"
    ascii_grid "$work/thin.asc" "$nc" "$nr" 254325 2152155 30 -9999 '300 + 7 * c + 5 * r'
    dem=$work/thin_$name.tif
    gdal_translate -q -ot Float32 -a_srs EPSG:32605 "$work/thin.asc" "$dem"
    : >"$work/all_errors"
    failed=0
    run shadow --time 2026-06-21T20:00Z --sun-per-cell on "$dem" "$work/thin_$name.sh.tif" ||
        failed=$((failed + 1))
    run insolation --time 2026-06-21T00:00Z/PT24H --step PT3H --directions 8 --sun-per-cell on \
        "$dem" "$work/thin_$name.ins.tif" || failed=$((failed + 1))
    bad=0
    if [ $failed -eq 0 ]; then
        bad=$(($(in_range "$work/thin_$name.sh.tif" 1 0 1) +
            $(in_range "$work/thin_$name.ins.tif" 1 1 1e5) +
            $(in_range "$work/thin_$name.ins.tif" 5 0 24)))
    fi
    [ $failed -eq 0 ] && [ "$bad" -eq 0 ]
    tap_ok $? "one $name ($nc x $nr), the sun per cell: shadow and insolation run ($(head -c 200 "$work/all_errors")), sunlit in {0, 1}, irradiation > 0, hours of sun <= 24 ($bad outside)"
done

# ---- walls and radius-limited horizons -------------------------------------------------
# Blocks 20 m tall on 1 m cells: lines auto would take box lines for walls,
# but the VAT blend's horizons are radius-limited, which box lines refuse,
# so its plan keeps interpolated lines.
ascii_grid "$work/blocks.asc" 60 60 254325 2152155 1 -9999 '(c % 12 < 6 && r % 12 < 6) ? 20 : 0'
gdal_translate -q -ot Float32 -a_srs EPSG:32605 "$work/blocks.asc" "$work/blocks.tif"
"$SKYSWEEP" hillshade --blend vat "$work/blocks.tif" "$work/blocks_vat.tif" >"$work/stdout" 2>"$work/stderr"
rc=$?
grep -q '^lines .*interpolated lines: radius-limited' "$work/stdout" && [ $rc -eq 0 ] &&
    [ "$(in_range "$work/blocks_vat.tif" 1 0 255)" -eq 0 ]
tap_ok $? "VAT blend on walls: runs with interpolated lines (exit $rc; $(head -c 200 "$work/stderr"))"

tap_done
