#!/bin/bash
# Where issue 17's jobs spend their time, from skysweep's own summary: the
# whole process (wall clock), the libraries' loading (`skysweep --version`),
# and the phases line of each run (doc/cli.md): DEM opened (GDAL, its CRS,
# geodesy), heights read, plan, kernel build, sweeps, outputs finished
# (GDAL's flush and compression, the read-back check, the rename) and the
# rest (per-cell terms, rows handed to GDAL). Medians of --reps runs after one untimed warm-up,
# milliseconds, as a markdown table on stdout.
# usage: doc/bench/phases.sh [--reps N] [--year]
#   --reps N   runs per job (default 7)
#   --year     also the exact-shadow year on the sample (about 30 s a run, 1 run)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
usage() { sed -n 's/^# \{0,1\}//; /^usage:/,/^  --year/p' "$0"; }
reps=7 year=0
while [ $# -gt 0 ]; do
    case $1 in
    --reps) reps=${2:?--reps needs a number} && shift ;;
    --year) year=1 ;;
    -h | --help) usage && exit 0 ;;
    *) usage >&2 && exit 2 ;;
    esac
    shift
done
SKYSWEEP=${SKYSWEEP:-$top/skysweep}
cmd=("$SKYSWEEP")
built=$(dirname "$SKYSWEEP")/.libs
# Time the program, not libtool's wrapper script.
if head -c 2048 "$SKYSWEEP" | grep -q 'temporary wrapper script' && [ -x "$built/skysweep" ]; then
    cmd=(env "LD_LIBRARY_PATH=$built${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$built/skysweep")
fi
sample=$top/samples/kilauea_summit_30m.tif
K=$top/../shared/data/hawaii_kilauea_utm5n_30m.tif
[ -r "$K" ] || K=$sample
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-phases.XXXXXX")
trap 'rm -rf "$work"' EXIT

median() { sort -g | awk '{ v[NR] = $1 } END { if (NR) print v[int((NR + 1) / 2)] }'; }

# ms ARG...: wall milliseconds of one run of skysweep ARG... (stdout kept in $work/out)
ms() {
    local t0 t1
    t0=$(date +%s%N)
    "${cmd[@]}" "$@" >"$work/out" 2>/dev/null
    t1=$(date +%s%N)
    echo $(((t1 - t0) / 1000000))
}

for i in $(seq "$reps"); do ms --version; done | median >"$work/start"
start=$(cat "$work/start")

echo "Measured by \`doc/bench/phases.sh --reps $reps\` on $(date -u '+%Y-%m-%d %H:%M UTC'): $(nproc) cores of $(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -1); skysweep commit $(git -C "$top" rev-parse --short HEAD 2>/dev/null || echo '?'). Milliseconds, medians; loading the libraries (\`skysweep --version\`): $start ms."
echo
echo "| job | whole process | DEM opened | heights read | plan | kernel build | sweeps | outputs finished | the rest |"
echo "|---|---|---|---|---|---|---|---|---|"
row() { # row TITLE ARG...: one row of the table
    local title=$1 i
    shift
    "${cmd[@]}" "$@" >/dev/null 2>&1 || { echo "| $title | failed: skysweep $* |"; return; }
    : >"$work/rows"
    for i in $(seq "$runs"); do
        wall=$(ms "$@")
        awk -v wall="$wall" '/^phases/ {
                n = 0
                for (i = 1; i <= NF; i++) if ($i ~ /^[0-9.]+$/ && $(i + 1) ~ /^s,?$/) v[++n] = $i
                if (n != 8) exit 1 # not the line this script knows: no row
                printf "%s", wall
                for (i = 2; i <= 8; i++) printf " %.0f", 1000 * v[i]
                print ""
            }' "$work/out" >>"$work/rows"
    done
    printf '| %s |' "$title"
    for col in 1 2 3 4 5 6 7 8; do
        printf ' %s |' "$(awk -v c=$col '{ print $c }' "$work/rows" | median)"
    done
    echo
}
runs=$reps
row "\`svf --directions 16\`, Kīlauea" svf --directions 16 "$K" "$work/o.tif"
row "\`horizon --directions 16\`, Kīlauea" horizon --directions 16 "$K" "$work/o.tif"
row "\`hillshade\`, Kīlauea" hillshade "$K" "$work/o.tif"
row "\`svf --radius 3000 --directions 16\`, sample" svf --radius 3000 --directions 16 "$sample" "$work/o.tif"
row "\`insolation\`, a day at 30-min steps, Kīlauea" insolation --time 2026-06-21T00:00-10:00/P1D \
    --step PT30M "$K" "$work/o.tif"
if [ "$year" = 1 ]; then
    runs=1
    row "\`insolation --shadow exact\`, a year hourly, sample" insolation \
        --time 2026-01-01T00:00-10:00/P1Y --step PT1H --shadow exact "$sample" "$work/o.tif"
fi
