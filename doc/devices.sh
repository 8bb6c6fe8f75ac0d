#!/bin/bash
# The measurements behind --device auto's cost model (doc/devices.md):
# whole-process medians of 5 runs of each job on PoCL, the C twin and auto.
# usage: doc/devices.sh [KILAUEA_TIF]  (default ../shared/data/hawaii_kilauea_utm5n_30m.tif)
set -eu
top=$(cd "$(dirname "$0")/.." && pwd)
S=$top/skysweep
K=${1:-$top/../shared/data/hawaii_kilauea_utm5n_30m.tif}
sample=$top/samples/kilauea_summit_30m.tif
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-devices.XXXXXX")
trap 'rm -rf "$work"' EXIT
gdal_translate -q -srcwin 0 0 64 64 "$sample" "$work/d64.tif"
median() { sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
row() {
    local label=$1
    shift
    printf "| %s |" "$label"
    for device in Portable reference auto; do
        t=$(for _ in 1 2 3 4 5; do
            /usr/bin/time -f %e "$S" "$@" --device "$device" -q 2>&1 >/dev/null | tail -n 1
        done | median)
        printf " %s s |" "$t"
    done
    printf "\n"
}
echo "| job | PoCL | C twin | auto |"
echo "|---|---|---|---|"
row "svf --directions 16, 64 x 64" svf --directions 16 "$work/d64.tif" "$work/o.tif"
row "svf --directions 16, Kīlauea" svf --directions 16 "$K" "$work/o.tif"
row "horizon --directions 16, Kīlauea" horizon --directions 16 "$K" "$work/o.tif"
row "svf --radius 3000 --directions 16, sample" svf --radius 3000 --directions 16 "$sample" "$work/o.tif"
row "insolation, a day of 30-min steps, Kīlauea" insolation --time 2026-06-21T00:00-10:00/P1D \
    --step PT30M "$K" "$work/o.tif"
row "hillshade --cast-shadows, Kīlauea" hillshade --cast-shadows "$K" "$work/o.tif"
row "hillshade, Kīlauea" hillshade "$K" "$work/o.tif"
