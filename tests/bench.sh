#!/bin/sh
# make bench: the sweep's speed on this machine's default OpenCL device, and
# the C reference for comparison. For the Kilauea DEM (the full one from
# ../shared/data when present, else the bundled crop) and a synthetic
# 1024 x 1024 grid, at 16 and 64 directions: cell-directions per second of
# the sweep and of the bare pass over the same lines, their ratio, peak
# memory; then the whole `skysweep svf --directions 16` process, median of 5.
# Not a test: figures depend on the machine and its load (say which).
set -eu
top=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD_DIR:-$top}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-bench.XXXXXX")
trap 'rm -rf "$work"' EXIT
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$build/tests/pocl-cache}

dem=$top/../shared/data/hawaii_kilauea_utm5n_30m.tif
[ -r "$dem" ] || dem=$top/samples/kilauea_summit_30m.tif
size=$(gdalinfo "$dem" | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1 \2/p')
gdal_translate -q -of ENVI -ot Float32 -a_nodata -3.4e38 "$dem" "$work/dem.raw"

echo "== machine: $(nproc) cores, $(sed -n 's/^model name\t: //p' /proc/cpuinfo | head -n1)"
for lines in interpolated digital; do
    for d in 16 64; do
        echo "== $(basename "$dem") ($size), $d directions, $lines lines"
        # shellcheck disable=SC2086
        "$build/ss-bench" --raw "$work/dem.raw" $size --cell 30 --directions "$d" \
            --lines "$lines" --reps 5
    done
    echo "== synthetic 1024 x 1024, 16 directions, $lines lines"
    "$build/ss-bench" --synthetic 1024 --directions 16 --lines "$lines" --reps 5
done
echo "== synthetic 1024 x 1024, 16 directions, C reference"
"$build/ss-bench" --synthetic 1024 --directions 16 --device reference --reps 3

echo "== whole process: skysweep svf --directions 16 $(basename "$dem"), median of 5"
"$build/skysweep" svf -q --directions 16 "$dem" "$work/warm.tif" # warms the kernel cache
for i in 1 2 3 4 5; do
    start=$(date +%s.%N)
    "$build/skysweep" svf -q --directions 16 "$dem" "$work/svf$i.tif"
    end=$(date +%s.%N)
    echo "$end - $start" | bc
done | sort -n | sed -n 3p | sed 's/^/median seconds: /'
