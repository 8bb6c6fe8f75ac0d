#!/usr/bin/env bash
# Runs inside `grass --tmp-location DEM --exec`, called by doc/performance.sh:
# imports the DEM, times the GRASS module alone (lib.sh: REPS, TIMEOUT, SLOW
# from the environment), then exports its output maps as GeoTIFFs for the
# numeric comparison.
# usage: grass_peer.sh horizon|sun DEM TIMEDIR OUTDIR MODULE_OPTION...
set -euo pipefail
# shellcheck source=doc/bench/lib.sh
. "$(dirname "$0")/lib.sh"

task=$1 dem=$2 timedir=$3 outdir=$4
shift 4

r.in.gdal --quiet input="$dem" output=dem
g.region raster=dem
case $task in
horizon)
    timed_reps "$timedir" r.horizon --quiet --overwrite elevation=dem output=hor "$@"
    maps=$(g.list type=raster pattern='hor_*')
    ;;
sun)
    # r.sun takes slope and aspect as maps; deriving them is not timed.
    r.slope.aspect --quiet elevation=dem slope=slope aspect=aspect
    timed_reps "$timedir" r.sun --quiet --overwrite elevation=dem slope=slope aspect=aspect \
        glob_rad=glob_rad "$@"
    maps=glob_rad
    ;;
*)
    echo "grass_peer.sh: unknown task '$task'" >&2
    exit 2
    ;;
esac

if [ "$(cat "$timedir/status")" = ok ]; then
    mkdir -p "$outdir"
    for map in $maps; do
        r.out.gdal --quiet -c input="$map" output="$outdir/$map.tif" format=GTiff type=Float32 \
            createopt=COMPRESS=DEFLATE
    done
fi
