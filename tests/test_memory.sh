#!/bin/bash
# Bounded memory: a DEM whose whole-grid sweep needs several times --memory
# is swept in bands (exactly: its SVF equals the whole-grid run's), and
# the peak resident memory the process reports (getrusage) stays within
# --memory plus a stated constant: the resident size of the same command on
# a 40 x 40 DEM on the same host device (the program, its libraries and
# their buffers). Bad sizes
# and products that cannot band are refused in one line.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-memory.XXXXXX")
trap 'rm -rf "$work"' EXIT

# 2400 x 2000 cells of rolling hills (UTM 5N, 10 m): a whole-grid sweep
# holds up to 24 bytes a cell (110 MiB) and 48 MiB of buffers, against --memory 64M.
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
rm -f "$work/dem.asc"
gdal_translate -q -srcwin 0 0 40 40 "$work/dem.tif" "$work/tiny.tif"

peak() { sed -n 's/^memory  peak resident \([0-9]*\) MiB.*/\1/p' "$1"; }

"$SKYSWEEP" svf --directions 8 --device reference "$work/tiny.tif" "$work/tiny_svf.tif" >"$work/tiny.out"
base=$(peak "$work/tiny.out")
"$SKYSWEEP" svf --directions 8 --memory 64M "$work/dem.tif" "$work/banded.tif" >"$work/banded.out"
rc=$?
used=$(peak "$work/banded.out")
grep -q '^bands ' "$work/banded.out"
tap_ok $? "a DEM needing ~140 MiB whole is swept in bands under --memory 64M (exit $rc): $(grep '^bands ' "$work/banded.out" | cut -c1-80)"
if "$SKYSWEEP" info | grep -q 'sanitizers yes'; then
    tap_skip "peak resident memory within the bound" "AddressSanitizer's shadow memory and quarantine inflate it"
else
    [ -n "$base" ] && [ -n "$used" ] && [ "$used" -le $((base + 64)) ]
    tap_ok $? "peak resident ${used:-?} MiB <= ${base:-?} MiB (the program on a 40x40 DEM) + 64 MiB"
fi

"$SKYSWEEP" svf --directions 8 --device reference -q "$work/dem.tif" "$work/whole.tif"
gdal_translate -q -of AAIGrid "$work/whole.tif" "$work/a.asc"
gdal_translate -q -of AAIGrid "$work/banded.tif" "$work/b.asc"
worst=$(paste -d '\n' <(tail -n +7 "$work/a.asc") <(tail -n +7 "$work/b.asc") | awk '
    NR % 2 == 1 { n = split($0, a, " "); next }
    { split($0, b, " "); for (i = 1; i <= n; i++) { d = a[i] - b[i]; if (d < 0) d = -d; if (d > w) w = d } }
    END { printf "%.3g", w }')
awk -v w="$worst" 'BEGIN { exit !(w <= 1e-6) }'
tap_ok $? "banded SVF == whole-grid SVF (worst $worst)"

# A window of the banded run equals the same window of the whole-grid run.
win="260325 2155000 272325 2146000"
"$SKYSWEEP" svf --directions 8 --memory 64M -q -projwin $win "$work/dem.tif" "$work/bwin.tif"
gdal_translate -q -projwin $win "$work/whole.tif" "$work/wcut.tif"
gdal_translate -q -of AAIGrid "$work/bwin.tif" "$work/a.asc"
gdal_translate -q -of AAIGrid "$work/wcut.tif" "$work/b.asc"
size=$(gdalinfo "$work/bwin.tif" | grep 'Size is')
worst=$(paste -d '\n' <(tail -n +7 "$work/a.asc") <(tail -n +7 "$work/b.asc") | awk '
    NR % 2 == 1 { n = split($0, a, " "); next }
    { split($0, b, " "); for (i = 1; i <= n; i++) { d = a[i] - b[i]; if (d < 0) d = -d; if (d > w) w = d } }
    END { printf "%.3g", w }')
[ "$size" = "Size is 1200, 900" ] && awk -v w="$worst" 'BEGIN { exit !(w <= 1e-6) }'
tap_ok $? "banded -projwin window == the whole-grid output's window ($size, worst $worst)"

"$SKYSWEEP" svf --memory 20M "$work/dem.tif" "$work/x.tif" 2>"$work/err"
rc=$?
[ "$rc" -eq 6 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && [ ! -e "$work/x.tif" ]
tap_ok $? "--memory too small for one band: exit $rc, $(head -c 120 "$work/err")"
"$SKYSWEEP" horizon --directions 4 --memory 64M "$work/dem.tif" "$work/x.tif" 2>"$work/err"
rc=$?
[ "$rc" -eq 6 ] && [ "$(wc -l <"$work/err")" -eq 1 ] && [ ! -e "$work/x.tif" ]
tap_ok $? "horizon cannot band: exit $rc, $(head -c 120 "$work/err")"
"$SKYSWEEP" svf --memory lots "$work/tiny.tif" "$work/x.tif" 2>"$work/err"
rc=$?
[ "$rc" -eq 2 ] && [ "$(wc -l <"$work/err")" -eq 1 ]
tap_ok $? "--memory lots: exit $rc, $(head -c 120 "$work/err")"
tap_done
