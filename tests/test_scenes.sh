#!/bin/bash
# Scene files and the planner from the command line: the sample scenes
# plan and run; every bad scene (unknown key, wrong type, missing DEM, a
# backwards time range, a tolerance <= 0) gives one line naming the file
# and line, exit 2, and no output; the command line overrides the scene;
# --plan prints the decisions and writes nothing.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
top=${TOP_SRCDIR:-.}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-scene.XXXXXX")
trap 'rm -rf "$work"' EXIT
cp "$top/samples/kilauea_summit_30m.tif" "$work/dem.tif"

run() {
    "$SKYSWEEP" "$@" >"$work/stdout" 2>"$work/stderr"
    rc=$?
}

cat >"$work/good.ini" <<'EOF'
[scene]
product = insolation
dem = dem.tif
output = out.tif
[time]
time = 2026-06-21T06:00:00-10:00/PT2H
step = PT1H
[site]
linke = 3
EOF

run plan "$work/good.ini"
[ $rc -eq 0 ] && grep -q '^night_steps *ON' "$work/stdout" && [ ! -e "$work/out.tif" ]
tap_ok $? "skysweep plan SCENE prints the decisions and writes nothing (exit $rc)"
run plan "$work/good.ini" --plan-format json
[ $rc -eq 0 ] && grep -q '"effect": "curvature"' "$work/stdout"
tap_ok $? "--plan-format json"
run run "$work/good.ini" -q
[ $rc -eq 0 ] && [ -s "$work/out.tif" ] && gdalinfo "$work/out.tif" | grep -q 'PLAN={"directions"'
tap_ok $? "skysweep run SCENE writes the output with the plan in its metadata (exit $rc)"
run run "$work/good.ini" -q --directions 8 --curvature off
[ $rc -eq 0 ] && gdalinfo "$work/out.tif" | grep -q 'DIRECTIONS=8' &&
    gdalinfo "$work/out.tif" | grep -q 'EARTH_CURVATURE=off'
tap_ok $? "options on the command line override the scene"

bad_scene() { # CODE DESCRIPTION LINE: the scene in $work/bad.ini must fail at LINE
    local code=$1 what=$2 line=$3
    rm -f "$work/bad_out.tif"
    run run "$work/bad.ini"
    local lines
    lines=$(wc -l <"$work/stderr")
    grep -q "bad.ini:$line:" "$work/stderr" && [ "$rc" -eq "$code" ] && [ "$lines" -eq 1 ] &&
        [ ! -e "$work/bad_out.tif" ]
    tap_ok $? "$what: exit $rc, line $line named: $(head -c 200 "$work/stderr")"
}

printf '[scene]\nproduct = svf\ndem = dem.tif\noutput = bad_out.tif\nfrobnicate = 3\n' >"$work/bad.ini"
bad_scene 2 "unknown key" 5
printf '[scene]\nproduct = svf\ndem = dem.tif\noutput = bad_out.tif\ndirections = many\n' >"$work/bad.ini"
bad_scene 2 "wrong type" 5
printf '[scene]\nproduct = svf\ndem = nowhere.tif\noutput = bad_out.tif\n' >"$work/bad.ini"
bad_scene 2 "missing DEM" 3
printf '[scene]\nproduct = insolation\ndem = dem.tif\noutput = bad_out.tif\ntime = 2026-06-22T00:00Z/2026-06-21T00:00Z\n' >"$work/bad.ini"
bad_scene 2 "time range backwards" 5
printf '[scene]\nproduct = svf\ndem = dem.tif\noutput = bad_out.tif\nsvf-tolerance = 0\n' >"$work/bad.ini"
bad_scene 2 "tolerance <= 0" 5
printf '[scene]\nproduct = svf\ndem = dem.tif\noutput = bad_out.tif\nthis is not ini\n' >"$work/bad.ini"
bad_scene 2 "a line that is not INI" 5
printf '[scene]\nproduct = svf\ndem = dem.tif\noutput = bad_out.tif\nproduct = svf\n' >"$work/bad.ini"
bad_scene 2 "product given twice (the last once won)" 5
printf '[scene]\ndem = dem.tif\n' >"$work/bad.ini"
run plan "$work/bad.ini"
[ $rc -eq 2 ] && grep -q "no 'product' key" "$work/stderr"
tap_ok $? "a scene without a product: $(head -c 200 "$work/stderr")"
for verb in plan run; do
    run "$verb" --help
    [ $rc -eq 0 ] && grep -q "Usage: skysweep $verb SCENE" "$work/stdout" && [ ! -s "$work/stderr" ]
    tap_ok $? "$verb --help prints its usage, exit $rc"
done
# A key is checked as its own command's option: horizon's `step` is
# degrees (site profiles), insolation's a duration.
printf '[scene]\nproduct = horizon\ndem = dem.tif\noutput = h.tif\nstep = 45\n' >"$work/h.ini"
run plan "$work/h.ini"
tap_ok $rc "a horizon scene with step = 45 (degrees) plans: exit $rc $(head -c 200 "$work/stderr")"
printf '[scene]\nproduct = insolation\ndem = dem.tif\noutput = bad_out.tif\nstep = 45\n' >"$work/bad.ini"
bad_scene 2 "an insolation step that is not a duration" 5
# Files that cannot be scenes are refused before they are read: an endless
# device, a folder, and a file over 1 MiB (each once hung or read it all).
{ printf '[scene]\nproduct = svf\n'; head -c 2000000 /dev/zero | tr '\0' '#'; } >"$work/huge.ini"
for s in /dev/zero "$work" "$work/huge.ini"; do
    for cmd in run plan; do
        run "$cmd" "$s"
        lines=$(wc -l <"$work/stderr")
        [ $rc -eq 2 ] && [ "$lines" -eq 1 ] && grep -q "scene file" "$work/stderr"
        tap_ok $? "$cmd $s: exit $rc, $lines line: $(head -c 200 "$work/stderr")"
    done
done

for s in "$top"/samples/scenes/*.ini; do
    run plan "$s"
    if [ $rc -eq 0 ]; then
        tap_ok 0 "sample scene $(basename "$s") plans"
    elif grep -q "not found" "$work/stderr"; then
        tap_skip "sample scene $(basename "$s")" "its DEM in ../shared/data is absent"
    else
        tap_ok 1 "sample scene $(basename "$s"): $(head -c 200 "$work/stderr")"
    fi
done
tap_done
