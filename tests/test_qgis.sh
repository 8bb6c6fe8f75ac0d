#!/bin/bash
# The QGIS Processing provider (qgis/skysweep, doc/qgis.md), headless with
# Debian's QGIS 3.22: qgis_process finds and lists its algorithms, each
# algorithm's help lists the parameters --help lists, the README's example
# runs, and PyQGIS runs (tests/qgis/check_provider.py) equal the CLI's
# outputs cell for cell, load as layers with their band names, report
# progress, and stop and leave nothing when cancelled. Skips, saying so,
# where QGIS is not installed (tests/run.sh installs it where it can).
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
top=$(realpath "${TOP_SRCDIR:-.}")
SKYSWEEP=$(realpath "${SKYSWEEP:-./skysweep}")
qgis=/usr/bin/qgis_process.bin
if [ ! -x "$qgis" ] || ! /usr/bin/python3 -c "import qgis.core, osgeo.gdal" 2>/dev/null; then
    tap_skip "the QGIS provider" "QGIS is not installed (apt-get install qgis python3-qgis qgis-providers)"
    tap_done
    exit
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-qgis.XXXXXX")
trap 'rm -rf "$work"' EXIT
# A QGIS profile of the test's own; the kernel cache stays where it was.
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$HOME/.cache/pocl/kcache}
export HOME=$work QT_QPA_PLATFORM=offscreen XDG_RUNTIME_DIR=$work
export QGIS_PLUGINPATH=$top/qgis SKYSWEEP_CLI=$SKYSWEEP
# QGIS would write statistics beside the sample (an .aux.xml in the source tree).
export GDAL_PAM_ENABLED=NO
export ASAN_OPTIONS=detect_leaks=0:${ASAN_OPTIONS:-}

"$qgis" plugins enable skysweep >"$work/enable.out" 2>&1
tap_ok $? "qgis_process enables the plugin: $(grep -c skysweep "$work/enable.out") mentions"
"$qgis" list >"$work/list.out" 2>&1
algorithms="svf openness horizon hillshade shadow insolation roofs"
missing=""
for a in $algorithms; do grep -q "skysweep:$a" "$work/list.out" || missing="$missing $a"; done
tap_ok "$([ -z "$missing" ]; echo $?)" "qgis_process lists skysweep's algorithms${missing:+, missing:$missing}"

# What the provider leaves to the CLI (doc/qgis.md): --help, its output format and
# quiet switch, scenes, plans and heightmaps, the rule for overlapping tiles (a
# layer is one DEM), and horizon's site profiles.
not_parameters=" help q of scene plan plan-format heightmap z-scale overlap "
for a in $algorithms; do
    "$qgis" help "skysweep:$a" >"$work/help.out" 2>&1
    skip=$not_parameters
    [ "$a" = horizon ] && skip="$skip point points point-crs format step height far "
    missing=""
    for option in $("$SKYSWEEP" "$a" --help | sed -n 's/^  -\{1,2\}\([a-z][-a-z0-9]*\).*/\1/p'); do
        case $skip in *" $option "*) continue ;; esac
        name=$(echo "$option" | tr 'a-z-' 'A-Z_')
        grep -q "^$name: " "$work/help.out" || missing="$missing $name"
    done
    grep -q "^INPUT: " "$work/help.out" && grep -q "^OUTPUT: " "$work/help.out" && [ -z "$missing" ]
    tap_ok $? "skysweep:$a's help lists INPUT, OUTPUT and every option of skysweep $a --help${missing:+; missing:$missing}"
done

# The README's example, as a reader would run it beside the samples.
sed -n '/^<!-- qgis-example -->$/,/^```$/p' "$top/README.md" | sed '1,2d;$d' >"$work/example.sh"
ln -s "$top/samples" "$work/samples"
ln -s "$top/qgis" "$work/qgis"
(cd "$work" && PATH=$(dirname "$SKYSWEEP"):$PATH sh example.sh) >"$work/example.out" 2>&1
rc=$?
[ "$rc" -eq 0 ] && [ -s "$work/example.sh" ] && [ -s "$work/svf_qgis.tif" ]
tap_ok $? "the README's QGIS example runs (exit $rc) $(tail -n 2 "$work/example.out" | tr '\n' ' ')"

mkdir "$work/runs"
/usr/bin/python3 "$top/tests/qgis/check_provider.py" "$top/qgis" "$work/runs" >"$work/check.out" 2>&1
rc=$?
n=0
while read -r outcome description; do
    n=$((n + 1))
    tap_ok "$([ "$outcome" = PASS ]; echo $?)" "$description"
done < <(grep -E '^(PASS|FAIL) ' "$work/check.out")
[ "$rc" -eq 0 ] && [ "$n" -ge 15 ]
tap_ok $? "the PyQGIS checks ran to the end ($n checks, exit $rc) $( [ "$rc" -eq 0 ] || tail -n 5 "$work/check.out" | tr '\n' ' ')"
tap_done
