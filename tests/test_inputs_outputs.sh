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
refuses 2 weather.csv "insolation's --steps (a side output) is its --weather file" -- \
    insolation -q --weather weather.csv --steps weather.csv dem.tif ins.tif
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

# ---- 2. an existing output: its permissions, its mode, its link ---------------------
svf() { run svf -q --directions 4 --device reference dem.tif "$@"; }
svf o.tif
chmod 444 o.tif
refuses 4 o.tif "an output of mode 444 is not replaced, by root either" -- \
    svf -q --directions 4 --device reference dem.tif o.tif
grep -q 'read-only' stderr
tap_ok $? "the refusal says the output is read-only: $(head -c 200 stderr)"
refuses 4 o.tif "horizon's site profiles refuse a read-only output too" -- \
    horizon -q --points sites.csv dem.tif o.tif
chmod 640 o.tif
svf o.tif
mode=$(stat -c %a o.tif)
[ "$rc" -eq 0 ] && [ "$mode" = 640 ]
tap_ok $? "a replaced output keeps its mode: exit $rc, mode $mode (want 640)"
mkdir -p linked
cp -p o.tif linked/target.tif
echo stale >linked/target.tif
ln -s linked/target.tif link.tif
svf link.tif
[ "$rc" -eq 0 ] && [ -L link.tif ] && [ "$(readlink link.tif)" = linked/target.tif ] &&
    gdalinfo linked/target.tif >/dev/null 2>&1 && [ "$(ls -A linked)" = target.tif ]
tap_ok $? "an output that is a link is written through to its target, the link kept: exit $rc, $(ls -l link.tif | cut -c1-10) -> $(readlink link.tif), linked/: $(ls -A linked | tr '\n' ' ')"
ln -s linked/new.tif dangling.tif
svf dangling.tif
[ "$rc" -eq 0 ] && [ -L dangling.tif ] && gdalinfo linked/new.tif >/dev/null 2>&1
tap_ok $? "a link to a file not there yet is written through too: exit $rc"
# As a user other than root, a file the user may not write (though the
# folder is open to all, which lets rename replace it) is refused.
if [ "$(id -u)" -eq 0 ] && command -v setpriv >/dev/null &&
    setpriv --reuid=nobody --regid=nogroup --clear-groups true 2>/dev/null &&
    setpriv --reuid=nobody --regid=nogroup --clear-groups test -x "$SKYSWEEP"; then
    mkdir -m 777 open
    cp dem.tif open/dem.tif
    cp -p o.tif open/o.tif
    chmod 644 open/o.tif
    cp open/o.tif before
    setpriv --reuid=nobody --regid=nogroup --clear-groups timeout -s KILL "$limit" \
        "$SKYSWEEP" svf -q --directions 4 --device reference open/dem.tif open/o.tif \
        >stdout 2>stderr
    rc=$?
    lines=$(wc -l <stderr)
    [ "$rc" -eq 4 ] && [ "$lines" -eq 1 ] && cmp -s open/o.tif before &&
        [ "$(stat -c %U open/o.tif)" = root ]
    tap_ok $? "as nobody, root's output of mode 644 in a folder open to all is not replaced: exit $rc, $lines line(s): $(head -c 200 stderr)"
else
    tap_skip "as nobody, a file the user may not write is not replaced" \
        "not root, or setpriv cannot switch to nobody"
fi

# ---- 8. SIGPIPE and SIGHUP stop a run as SIGINT does ---------------------------------
gdal_translate -q -outsize 400 400 "$top/samples/kilauea_summit_30m.tif" big.tif
mkdir stop
# The reader of standard output has gone: the progress (or summary) written
# there raises SIGPIPE.
(
    timeout -s KILL "$limit" "$SKYSWEEP" svf --device reference --directions 200000 big.tif \
        stop/o.tif 2>stderr
    echo $? >rc
) | true
rc=$(cat rc)
lines=$(wc -l <stderr)
[ "$rc" -eq 141 ] && [ "$lines" -eq 1 ] && grep -q 'signal 13' stderr && [ -z "$(ls -A stop)" ]
tap_ok $? "svf | (a reader that has gone): exit $rc (want 141), $lines line(s) on stderr, files left: $(ls -A stop | tr '\n' ' '): $(head -c 200 stderr)"
for sig in HUP PIPE; do
    # Not under timeout, which would take the signal itself.
    "$SKYSWEEP" svf -q --device reference --directions 200000 big.tif stop/o.tif \
        >stdout 2>stderr &
    pid=$!
    sleep 1.5
    kill -"$sig" "$pid"
    for _ in $(seq 100); do kill -0 "$pid" 2>/dev/null && sleep 0.05; done
    kill -KILL "$pid" 2>/dev/null
    wait "$pid"
    rc=$?
    want=$((128 + $(kill -l "$sig")))
    lines=$(wc -l <stderr)
    [ "$rc" -eq "$want" ] && [ "$lines" -eq 1 ] && grep -q interrupted stderr &&
        [ -z "$(ls -A stop)" ]
    tap_ok $? "SIG$sig in the middle of svf: exit $rc (want $want), $lines line(s), files left: $(ls -A stop | tr '\n' ' '): $(head -c 200 stderr)"
done

# ---- 10. the scratch files of a run in bands follow TMPDIR; a full one is named -----
gdal_translate -q -outsize 1800 1800 "$top/samples/kilauea_summit_30m.tif" banded.tif
# 110M bands it; a sanitizer build's process is larger (AddressSanitizer's
# shadow memory), so there the least budget it names, and 4 MiB more.
budget=110M
if "$SKYSWEEP" info | grep -q 'sanitizers yes'; then
    least=$("$SKYSWEEP" svf -q --device reference --directions 8 --memory 1M banded.tif stop/o.tif 2>&1 |
        sed -n 's/.*at least --memory \([0-9]*\)M.*/\1/p')
    budget=$((${least:-106} + 4))M
fi
banded() { # a run in bands, which keeps its cells in a scratch file between bands
    TMPDIR=$1 timeout -s KILL "$limit" "$SKYSWEEP" svf -q --device reference --directions 8 \
        --memory "$budget" banded.tif stop/o.tif >stdout 2>stderr
    rc=$?
    lines=$(wc -l <stderr)
}
banded "$work/nowhere"
[ "$rc" -eq 4 ] && [ "$lines" -eq 1 ] && grep -q "'$work/nowhere'" stderr && [ -z "$(ls -A stop)" ]
tap_ok $? "TMPDIR is where the scratch file goes (a folder that is not there): exit $rc (want 4), $lines line(s): $(head -c 200 stderr)"
mkdir scratch
banded "$work/scratch"
[ "$rc" -eq 0 ] && [ -s stop/o.tif ] && [ -z "$(ls -A scratch)" ]
tap_ok $? "a run in bands with TMPDIR set: exit $rc, nothing left in TMPDIR"
rm -f stop/o.tif
# A folder that fills up: a tmpfs of 64 KiB in a mount namespace of its own.
mkdir small
export SKYSWEEP work limit budget
if unshare -m sh -c 'mount -t tmpfs -o size=64k tmpfs "$work/small"' 2>/dev/null; then
    unshare -m sh -c 'mount -t tmpfs -o size=64k tmpfs "$work/small" &&
        TMPDIR=$work/small timeout -s KILL "$limit" "$SKYSWEEP" svf -q --device reference \
            --directions 8 --memory "$budget" banded.tif stop/o.tif >stdout 2>stderr; echo $? >rc'
    rc=$(cat rc)
    lines=$(wc -l <stderr)
    [ "$rc" -eq 4 ] && [ "$lines" -eq 1 ] && grep -q "'$work/small' is full" stderr &&
        [ -z "$(ls -A stop)" ]
    tap_ok $? "a full TMPDIR is named: exit $rc (want 4), $lines line(s), nothing left: $(head -c 240 stderr)"
else
    tap_skip "a full TMPDIR is named" "cannot mount a tmpfs in a mount namespace here"
fi

# The option tables declare every file option as read or written, and
# --help-json says which: the QGIS provider and the Python package tell
# outputs from inputs by these flags alone.
undeclared="" flags=""
for command in svf openness horizon shadow hillshade insolation render quicklook sun weather; do
    "$SKYSWEEP" "$command" --help-json >"help-$command.json" 2>/dev/null || continue
    found=$(python3 - "help-$command.json" <<'PY'
import json, sys
table = json.load(open(sys.argv[1]))
for o in table["options"]:
    file_like = (o.get("metavar") or "").startswith("FILE")
    kind = "output" if o.get("output") else "input" if o.get("input") else ""
    if file_like and not kind:
        print("undeclared:" + table["command"] + ":" + o["name"])
    elif kind:
        print(kind + ":" + o["name"])
PY
)
    undeclared="$undeclared $(echo "$found" | grep '^undeclared:' | tr '\n' ' ')"
    flags="$flags $(echo "$found" | grep -v '^undeclared:' | tr '\n' ' ')"
done
undeclared=$(echo $undeclared)
expected_ok=1
for want in output:distance output:cast-height output:steps output:export input:weather \
    input:points input:drape input:horizon-from input:scene; do
    case " $flags " in *" $want "*) ;; *) expected_ok=0 ;; esac
done
[ -z "$undeclared" ] && [ "$expected_ok" -eq 1 ]
tap_ok $? "--help-json flags every file option as input or output${undeclared:+ (undeclared:$undeclared)}"
for command in shadow svf; do
    python3 - "help-$command.json" <<'PY'
import json, sys
options = {o["name"]: o for o in json.load(open(sys.argv[1]))["options"]}
sys.exit(not all(options.get(n, {}).get("input") for n in ("canopy", "trunk")))
PY
    tap_ok $? "$command --help-json flags --canopy and --trunk as inputs"
done

tap_done
