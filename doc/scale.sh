#!/bin/bash
# The figures of doc/scale.md: the banded sweep (ss-scale) on synthetic
# fractal DEMs up to 16384 x 16384 cells (and larger with --large) under
# --memory 256M, next to the whole-grid sweep where it fits; then the CLI
# on a 4096 x 4096 GeoTIFF alone and under mpirun with 2 and 4 processes,
# whole and banded. Prints Markdown tables on stdout (doc/scale.md quotes
# them), with the machine and the load.
#
#   doc/scale.sh [--quick] [--large] [--directions D] [--products "svf horizon"] [--no-cli]
#
# --quick: 2048 and 4096 only (a few minutes); --large adds 24576 x 24576;
# --products: which banded products to time (default both); --no-cli skips
# the CLI and MPI table.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD:-$top}
scale=$build/ss-scale
skysweep=$build/skysweep
directions=16
sizes="4096 8192 16384"
products="svf horizon"
cli=1
while [ $# -gt 0 ]; do
    case $1 in
    --quick) sizes="2048 4096" ;;
    --large) sizes="$sizes 24576" ;;
    --directions) directions=$2 && shift ;;
    --products) products=$2 && shift ;;
    --no-cli) cli=0 ;;
    *) echo "usage: doc/scale.sh [--quick] [--large] [--directions D] [--products LIST] [--no-cli]" >&2 && exit 2 ;;
    esac
    shift
done
[ -x "$scale" ] && [ -x "$skysweep" ] || { echo "build first (make): $scale" >&2; exit 2; }
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-scale.XXXXXX")
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_btl_vader_single_copy_mechanism=none

field() { sed -n "s/^$1 *//p" "$2"; }

echo "Machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores, $(free -g | awk '/Mem:/ {print $2}') GiB; load average before: $(cut -d' ' -f1-3 /proc/loadavg). $(date -u +%Y-%m-%d)."
echo
echo "| product | grid | path | wall s | M cell-dir/s | peak RSS MiB | band rows | hulls handed on | mean / max points |"
echo "|---|---|---|---|---|---|---|---|---|"
for product in $products; do
flag=""
[ "$product" = horizon ] && flag=--horizon
for n in $sizes; do
    runs="banded"
    # The whole grid holds about 20 bytes a cell (plus OpenCL's copies).
    if [ $((n * n / 1048576 * 20)) -lt $(( $(free -m | awk '/Mem:/ {print $7}') / 2 )) ]; then
        runs="$runs whole-pocl"
    fi
    for run in $runs; do
        case $run in
        banded) "$scale" --size "$n" --directions "$directions" --memory 256 $flag >"$work/out" ;;
        whole-pocl) "$scale" --size "$n" --directions "$directions" --whole --device 0:0 $flag >"$work/out" ;;
        esac
        wall=$(field time "$work/out" | awk '{print $1}')
        rate=$(field time "$work/out" | awk '{print $4}')
        rss=$(field "peak RSS" "$work/out" | awk '{print $1}')
        rows=$(field bands "$work/out" | awk '{print $1}')
        hulls=$(field hulls "$work/out")
        handed=$(echo "$hulls" | awk '{print $1}')
        points=$(echo "$hulls" | sed -n 's/.*mean \([0-9.]*\) points, max \([0-9]*\).*/\1 \/ \2/p')
        echo "| $product | ${n}² | $run | $wall | $rate | $rss | ${rows:--} | ${handed:--} | ${points:--} |"
    done
done
done
echo
[ "$cli" = 1 ] || exit 0

# The CLI on a GeoTIFF: 4096 x 4096 cells of fractal terrain, whole and banded,
# 1, 2 and 4 MPI processes (the same octaves of value noise as ss-scale).
n=4096
# (Needs Python with GDAL and NumPy: apt-get install python3-gdal python3-numpy.)
/usr/bin/python3 - "$work/dem.tif" "$n" <<'EOF'
import sys
from osgeo import gdal, osr
import numpy as np
path, n = sys.argv[1], int(sys.argv[2])
rng = np.random.default_rng(7)
z = np.zeros((n, n), np.float32)
amp, wl = 1200.0, 2048
while wl >= 4:
    k = n // wl + 2
    lat = rng.random((k, k)).astype(np.float32)
    y = np.arange(n) / wl
    y0 = np.floor(y).astype(int); t = y - y0; t = t * t * (3 - 2 * t)
    rows = lat[y0] * (1 - t)[:, None] + lat[y0 + 1] * t[:, None]
    z += amp * (rows[:, y0] * (1 - t)[None, :] + rows[:, y0 + 1] * t[None, :])
    amp *= 0.5; wl //= 2
d = gdal.GetDriverByName("GTiff").Create(path, n, n, 1, gdal.GDT_Float32, ["TILED=YES", "COMPRESS=DEFLATE"])
d.SetGeoTransform([500000, 30, 0, 2200000, 0, -30])
s = osr.SpatialReference(); s.ImportFromEPSG(32605); d.SetProjection(s.ExportToWkt())
d.GetRasterBand(1).WriteArray(z)
EOF
echo "| ${n}² GeoTIFF, CLI | processes | wall s (whole command) | peak RSS MiB (largest process) |"
echo "|---|---|---|---|"
for memory in "" "--memory 256M"; do
    for np in 1 2 4; do
        cmd=("$skysweep" svf -q --directions "$directions" $memory "$work/dem.tif" "$work/svf.tif")
        [ "$np" -gt 1 ] && cmd=(mpirun --oversubscribe -np "$np" "${cmd[@]}")
        rm -f "$work/svf.tif"
        /usr/bin/time -f "%e %M" -o "$work/time" "${cmd[@]}" >/dev/null
        read -r wall kb <"$work/time"
        echo "| ${memory:-whole grid} | $np | $wall | $((kb / 1024)) |"
    done
done
echo
echo "Load average after: $(cut -d' ' -f1-3 /proc/loadavg)."
