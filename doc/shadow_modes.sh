#!/usr/bin/env bash
# Insolation's shadow modes against exact shadows: the error per cell of a
# weather run's sums and the time, for the planner's choice of mode and
# directions (--shadow auto, doc/planner.md). Writes doc/shadow_modes.md and
# the generated part of src/core/shadow_table.c.
#
# Two scenes, each on its planner-chosen line model:
#   city     Gothenburg's 1 m DSM (../shared/data; box lines, 32 per cell),
#            Amsterdam's IWEC year (the nearest weather file at hand);
#   terrain  the Kilauea sample DEM moved to 45 N, 8 E (UTM 32N; interpolated
#            lines), the PVGIS typical year of that site (samples/weather/).
# The year is thinned to bound the cost on 2 cores: the records of every
# ${THIN:-21}st day are kept, in a plain CSV of them as the reader reads the
# file. The sums compared are thus the year's and each month's over the
# days kept: a month's sum is one or two days, a stricter test than a whole
# month's.
# The reference is exact shadows (a sweep per record) with 64 directions
# for the sky; each row is a run with --shadow interpolated at D directions
# or --shadow cumulative at D (1 degree bins), all with --pv but the
# cumulative sky's, which gives no PV yield. Errors are
# |run - reference| / reference per cell, over cells with light: the
# annual global, the monthly globals (pooled, cells with at least 1 % of the
# scene's mean month) and the annual PV yield (DC); mean and p95.
# Usage: doc/shadow_modes.sh [--quick] (--quick: 60 x 60 crops, two rows
# per scene, CI's check that it runs; doc/ and src/ are left alone).
# Environment: SKYSWEEP (default ./skysweep), PYTHON with numpy (default
# tests/pyvenv's), DATA (default ../shared/data), THIN (default 21).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
top=$(dirname "$here")
skysweep=${SKYSWEEP:-$top/skysweep}
python=${PYTHON:-$top/tests/pyvenv/bin/python}
data=${DATA:-$top/../shared/data}
thin=${THIN:-21}
quick=0
[ "${1:-}" = --quick ] && quick=1
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-shadow-modes.XXXXXX")
trap 'rm -rf "$work"' EXIT
started=$(date +%s)
load_before=$(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo "?")

# thin FILE OUT: the records of every $thin-th day of a weather file, as the
# reader reads them (skysweep weather), in a plain CSV stamped where the sun
# is taken, in one year (a typical year's months come from several); a
# plain CSV counts no gaps between the days kept.
thin() {
    "$skysweep" weather "$1" | "$python" -c '
import sys, datetime
every = int(sys.argv[1])
print("time,ghi,dni,dhi,temp_air,wind_speed,pressure")
for line in sys.stdin:
    if line.startswith("#") or line.startswith("stamp,"):
        continue
    stamp, sun, _, ghi, dni, dhi, temp, wind, _, pressure = line.rstrip("\n").split(",")
    day = datetime.date(2001, int(stamp[5:7]), int(stamp[8:10])).timetuple().tm_yday
    if day % every == every // 2:  # a typical year mixes years: all in one
        print(",".join(("2001" + sun[4:], ghi, dni, dhi, temp, wind, pressure)))
' "$thin" >"$2"
}

city_dem=$data/goteborg_kronenhuset_dsm_1m.tif
city_weather=$data/weather/NLD_Amsterdam062400_IWEC.epw
terrain_weather=$top/samples/weather/pvgis_tmy_45N_8E.csv
if [ $quick -eq 1 ]; then
    crop=(-srcwin 240 100 60 60) ullr=(421000 4990000 422800 4988200)
    city_crop=(-srcwin 100 100 60 60)
    city_rows="interpolated:16 interpolated:64" terrain_rows="interpolated:16 cumulative:32"
else
    crop=() ullr=(421000 4990000 436360 4970710) city_crop=()
    city_rows="interpolated:16 interpolated:32 interpolated:64 interpolated:128 cumulative:32"
    terrain_rows="interpolated:16 interpolated:32 interpolated:64 cumulative:32 cumulative:64"
fi
gdal_translate -q "${crop[@]}" -a_srs EPSG:32632 -a_ullr "${ullr[@]}" \
    "$top/samples/kilauea_summit_30m.tif" "$work/terrain.tif"
thin "$terrain_weather" "$work/terrain.csv"
scenes=terrain
if [ -r "$city_dem" ] && [ -r "$city_weather" ]; then
    gdal_translate -q "${city_crop[@]}" "$city_dem" "$work/city.tif"
    thin "$city_weather" "$work/city.csv"
    scenes="city terrain"
else
    echo "shadow_modes: no $city_dem or $city_weather: the city scene is left out" >&2
fi

# run SCENE MODE:DIRECTIONS: one insolation run, its wall time into NAME.time
run() {
    local scene=$1 mode directions
    IFS=: read -r mode directions <<<"$2"
    local name=$scene-$mode-$directions weather=$work/terrain.csv pv=(--pv)
    [ "$scene" = city ] && weather=$work/city.csv
    [ "$mode" = cumulative ] && pv=() # the cumulative sky gives no PV yield
    local t0 t1
    t0=$(date +%s.%N)
    "$skysweep" insolation -q --device reference --weather "$weather" "${pv[@]}" \
        --directions "$directions" --curvature off --shadow "$mode" "$work/$scene.tif" \
        "$work/$name.tif"
    t1=$(date +%s.%N)
    echo "$t1 - $t0" | bc >"$work/$name.time"
    gdal_translate -q -of ENVI "$work/$name.tif" "$work/$name.raw"
}
args=()
for scene in $scenes; do
    run "$scene" exact:64
    rows=$city_rows
    [ "$scene" = terrain ] && rows=$terrain_rows
    for r in $rows; do
        run "$scene" "$r"
        args+=("$scene:${r/:/-}")
    done
done
kept=$("$python" -c "print(sum(1 for d in range(1, 366) if d % $thin == $thin // 2))")
"$python" - "$work" "$kept" "${args[@]}" >"$work/rows.txt" <<'PY'
import sys
import numpy as np
work, kept, *rows = sys.argv[1:]

def load(name):
    a = np.fromfile(f"{work}/{name}.raw", dtype=np.float32)
    a = a.reshape(-1, refs["cells"]) if "cells" in refs else a.reshape(19, -1)
    return a, float(open(f"{work}/{name}.time").read())

refs = {}
for row in rows:
    scene, name = row.split(":")
    if scene not in refs:
        refs.pop("cells", None)
        refs[scene] = load(f"{scene}-exact-64")
        refs["cells"] = refs[scene][0].shape[1]
    ref, ref_time = refs[scene]
    run, seconds = load(f"{scene}-{name}")
    lit = ref[0] > 0
    def rel(b):
        ok = lit & (ref[b] > 0)
        return np.abs(run[b] - ref[b])[ok] / ref[b][ok] * 100
    months = ref[5:17]
    floor = 0.01 * months[:, lit].mean()
    m = np.concatenate([np.abs(run[5 + k] - ref[5 + k])[lit & (ref[5 + k] > floor)] /
                        ref[5 + k][lit & (ref[5 + k] > floor)] * 100 for k in range(12)])
    g = rel(0)
    pv = rel(17) if run.shape[0] > 17 else np.array([np.nan])  # cumulative: no PV yield
    mode, d = name.split("-")
    # scene mode directions kept-days | global mean p95 | months mean p95 | pv mean p95 | s, exact s
    print(scene, mode, d, kept, f"{g.mean():.3g}", f"{np.percentile(g, 95):.3g}",
          f"{m.mean():.3g}", f"{np.percentile(m, 95):.3g}", f"{pv.mean():.3g}",
          f"{np.percentile(pv, 95):.3g}", f"{seconds:.3g}", f"{ref_time:.3g}")
PY
elapsed=$(($(date +%s) - started))
load_after=$(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo "?")
table() { # the markdown table
    echo "| scene | run | time (s) | exact (s) | annual global: mean / p95 (%) | monthly globals: mean / p95 (%) | annual PV yield: mean / p95 (%) |"
    echo "|---|---|---|---|---|---|---|"
    while read -r scene mode d kept gm gp mm mp pm pp s es; do
        pv="$pm / $pp"
        [ "$pm" = nan ] && pv="—"
        echo "| $scene | $mode, $d directions | $s | $es | $gm / $gp | $mm / $mp | $pv |"
    done <"$work/rows.txt"
}
if [ $quick -eq 1 ]; then
    table
    exit 0
fi
size() { gdalinfo "$1" | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1 × \2/p'; }
{
    cat <<HEAD
# Shadow modes: measured error against exact shadows, and time

Generated by \`doc/shadow_modes.sh\` on $(date -u +%Y-%m-%d) in ${elapsed} s, $(nproc) cores, the
C twin (\`--device reference\`); load average $load_before before, $load_after after (the
machine was shared: the times are a guide, the errors are not affected). The planner reads the
errors from \`src/core/shadow_table.c\`, which the same run wrote (doc/planner.md, \`shadow_mode\`).

- **city**: Gothenburg's 1 m DSM ($(size "$work/city.tif") cells; box lines, 32 per cell, as the
  planner picks them), Amsterdam's IWEC year (the nearest weather file at hand).
- **terrain**: the Kīlauea sample DEM ($(size "$work/terrain.tif") cells of 30 m; interpolated
  lines), moved to 45° N, 8° E, with the PVGIS typical year of that site.

Every run but the cumulative sky's (which gives no PV yield) has \`--pv\`; a Perez sky, albedo 0.2, curvature off. To bound the cost, the year is
thinned: the records of every ${thin}st day are kept ($kept days of 365), as the reader reads
them, in a plain CSV. The sums compared are the year's and each month's over those days, so a
month's is one or two days: shorter than a month, a stricter test than a whole month's. The reference is exact shadows with 64 directions
(for the sky as well); each row is one run of the mode at D directions (which also set the sky's
directions; cumulative: 1° bins), with errors per cell of |run − reference| / reference over
lit cells (monthly: pooled over the twelve months, cells above 1 % of the scene's mean month).
Times are whole processes.

HEAD
    table
} >"$here/shadow_modes.md"
"$python" - "$top/src/core/shadow_table.c" "$work/rows.txt" "$thin" <<'PY'
import sys
path, rows, thin = sys.argv[1], sys.argv[2], sys.argv[3]
text = open(path).read()
begin = text.index("/* BEGIN GENERATED")
end = text.index("/* END GENERATED */")
lines = ["/* BEGIN GENERATED by doc/shadow_modes.sh: do not edit by hand */",
         "/* clang-format off */",
         f"const int ss_shadow_mode_thin = {thin};",
         "const ss_shadow_mode_row ss_shadow_mode_rows[] = {"]
for r in open(rows):
    scene, mode, d, kept, gm, gp, mm, mp, pm, pp, s, es = r.split()
    pm, pp = ("NAN" if v == "nan" else v for v in (pm, pp))
    lines.append(f"    {{SS_SHADOW_SCENE_{scene.upper()}, SS_SHADOW_{mode.upper()}, {d}, "
                 f"{gm}, {gp}, {mm}, {mp}, {pm}, {pp}, {s}, {es}}},")
lines += ["};",
          "const int ss_shadow_mode_n_rows = (int)(sizeof ss_shadow_mode_rows / sizeof ss_shadow_mode_rows[0]);",
          "/* clang-format on */", ""]
open(path, "w").write(text[:begin] + "\n".join(lines) + text[end:])
PY
echo "shadow_modes: $(wc -l <"$work/rows.txt") rows in ${elapsed} s -> $here/shadow_modes.md, src/core/shadow_table.c"
