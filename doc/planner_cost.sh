#!/bin/bash
# What the planner saves on the sample scenes (doc/planner.md): each scene
# run as planned, and with every effect the planner may switch off forced
# on (curvature, true north, the sun per cell where the product has a sun)
# and 64 directions where the product sweeps the sky (the planner's table
# ends there), the median wall time of 3 runs each; then the largest
# difference between the two outputs' first bands, to set against the
# tolerances the plan allowed. Night steps and high-sun shadow sweeps are
# skipped in both runs: those skips are exact, not approximations.
# Markdown on stdout. Scenes whose DEM is absent (../shared/data) are
# skipped with a line saying so.
#
#   doc/planner_cost.sh          (from the build tree; BUILD=... otherwise)
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
skysweep=${BUILD:-$top}/skysweep
py=/usr/bin/python3
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-plancost.XXXXXX")
trap 'rm -rf "$work"' EXIT
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$work/pocl-cache}

key() { sed -n "s/^$1 *= *//p" "$2" | head -n 1; } # a scene's key

median_time() { # median wall seconds of 3 runs of skysweep ARGS
    for _ in 1 2 3; do
        /usr/bin/time -f %e -o "$work/t" "$skysweep" "$@" -q >/dev/null
        cat "$work/t"
    done | sort -g | sed -n 2p
}

echo "Measured by \`doc/planner_cost.sh\` on $(date -u '+%Y-%m-%d'), $(nproc) cores, PoCL; load average"
echo "before: $(cut -d' ' -f1-3 /proc/loadavg). Wall time of the whole command, median of 3."
echo
echo "| scene | product | planned | s | everything on | s | saved | band 1 \|Δ\|: max | 95th percentile | mean |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for scene in "$top"/samples/scenes/*.ini; do
    name=$(basename "$scene" .ini)
    product=$(key product "$scene")
    dem="$(dirname "$scene")/$(key dem "$scene")"
    if [ ! -r "$dem" ]; then
        echo "| $name | $product | DEM absent ($(key dem "$scene")): not run | | | | | | | |"
        continue
    fi
    case $product in
    svf) forced="--curvature on --north true --directions 64" ;;
    shadow) forced="--curvature on --north true --sun-per-cell on" ;;
    insolation) forced="--curvature on --north true --sun-per-cell on --directions 64" ;;
    *) forced="--curvature on --north true" ;;
    esac
    # The planned settings in one line: the effects it switched off, and the directions.
    planned=$("$skysweep" "$product" --scene "$scene" --plan "$dem" "$work/p.tif" |
        awk '$2 == "OFF" && $1 != "sun_per_cell" {off = off (off ? ", " : "") $1 " off"}
             $1 == "directions" {d = $3 " directions"}
             END {print (d ? d : "") (d && off ? "; " : "") off}')
    "$skysweep" "$product" --scene "$scene" -q "$dem" "$work/warm.tif" # kernels built and cached
    t_plan=$(median_time "$product" --scene "$scene" "$dem" "$work/plan.tif")
    # shellcheck disable=SC2086
    t_all=$(median_time "$product" --scene "$scene" $forced "$dem" "$work/all.tif")
    "$py" - "$work/plan.tif" "$work/all.tif" >"$work/diff" <<'EOF'
import sys
import numpy as np
from osgeo import gdal
ds = [gdal.Open(p) for p in sys.argv[1:3]]  # kept: a band dies with its dataset
a, b = (d.GetRasterBand(1) for d in ds)
x, y = a.ReadAsArray().astype(float), b.ReadAsArray().astype(float)
ok = (x != a.GetNoDataValue()) & (y != b.GetNoDataValue())
d = np.abs(x - y)[ok]
print(f"{d.max():.4g} {np.percentile(d, 95):.3g} {d.mean():.3g}")
EOF
    read -r maxd p95d meand <"$work/diff"
    saved=$(awk -v p="$t_plan" -v a="$t_all" 'BEGIN {printf "%.0f %%", 100 * (a - p) / a}')
    echo "| $name | $product | ${planned:-all on} | $t_plan | $forced | $t_all | $saved | $maxd | $p95d | $meand |"
done
