#!/bin/bash
# Files in and out (issue 40): no output may replace a file the run reads
# (DEM, weather, sites, scene) or another of its outputs; an existing output
# keeps its permissions, its mode and its links; SIGPIPE and SIGHUP stop a
# run as SIGINT does; temporaries outside the output's folder follow TMPDIR.
# Each refusal: one line on stderr, the documented exit code, the files
# untouched. doc/reliability.md lists the cases.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
SKYSWEEP=$(cd "$(dirname "$SKYSWEEP")" && pwd)/$(basename "$SKYSWEEP")
top=$(cd "${TOP_SRCDIR:-.}" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-io.XXXXXX")
chmod 755 "$work"
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
limit=${SS_FAULT_TIMEOUT:-120}

gdal_translate -q -srcwin 0 0 40 40 "$top/samples/kilauea_summit_30m.tif" dem.tif
cp "$top/samples/weather/pvgis_tmy_45N_8E.csv" weather.csv
printf 'id,lon,lat\na,-155.3137,19.4138\n' >sites.csv

run() { # runs skysweep with a time limit; sets $rc, $lines
    timeout -s KILL "$limit" "$SKYSWEEP" "$@" >stdout 2>stderr
    rc=$?
    lines=$(wc -l <stderr)
}

# refuses CODE FILE DESCRIPTION -- ARGS...: exit CODE, one line, FILE as it was.
refuses() {
    local code=$1 file=$2 what=$3
    shift 4
    cp -p "$file" before
    run "$@"
    cmp -s "$file" before
    local same=$?
    [ "$rc" -eq "$code" ] && [ "$lines" -eq 1 ] && [ "$same" -eq 0 ]
    tap_ok $? "$what: exit $rc (want $code), $lines line(s), '$file' $([ $same -eq 0 ] && echo untouched || echo CHANGED): $(head -c 200 stderr)"
    cp -p before "$file" # the next case starts from the file as it was
}

# ---- 1. an output that is a file the run reads, or another output --------------------
refuses 2 weather.csv "insolation's OUTPUT is its --weather file" -- \
    insolation -q --weather weather.csv dem.tif weather.csv
refuses 2 sites.csv "horizon's OUTPUT is its --points file" -- \
    horizon -q --points sites.csv dem.tif sites.csv
refuses 2 sites.csv "horizon's OUTPUT is its --points file by another name" -- \
    horizon -q --points sites.csv dem.tif ./sites.csv
ln -s weather.csv weather-link.csv
refuses 2 weather.csv "insolation's OUTPUT is a link to its --weather file" -- \
    insolation -q --weather weather.csv dem.tif weather-link.csv
refuses 2 dem.tif "svf's OUTPUT is its DEM by another name" -- svf -q dem.tif ../"$(basename "$work")"/dem.tif
printf 'product = svf\ndem = dem.tif\noutput = scene.ini\n' >scene.ini
refuses 2 scene.ini "skysweep run: the scene's output is the scene file" -- run scene.ini -q
refuses 2 scene.ini "--scene: the scene's output is the scene file" -- svf --scene scene.ini -q
refuses 2 scene.ini "--scene: OUTPUT on the command line is the scene file" -- \
    svf --scene scene.ini -q dem.tif ./scene.ini
run horizon -q --directions 4 --distance ./d.tif dem.tif d.tif
[ "$rc" -eq 2 ] && [ "$lines" -eq 1 ] && [ ! -e d.tif ] && grep -q 'same output' stderr
tap_ok $? "horizon's OUTPUT and --distance name one file two ways: exit $rc, $lines line(s): $(head -c 200 stderr)"
run svf -q --directions 4 --plan dem.tif dem.tif
[ "$rc" -eq 2 ] && [ "$lines" -eq 1 ]
tap_ok $? "even --plan refuses an OUTPUT that is the DEM: exit $rc"
run svf -q --directions 4 dem.tif svf.tif
[ "$rc" -eq 0 ] && [ -s svf.tif ]
tap_ok $? "distinct files still run: exit $rc"

tap_done
