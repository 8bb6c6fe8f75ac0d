#!/bin/bash
# A PV year on a city DSM (issue 42's target: <= 10 s on 2 cores): the
# Gothenburg 1 m DSM with the Amsterdam IWEC year and --pv, default options
# (exact box shadows by each cell's own ray, the plan's box lines for the
# sky view), against the same with the box lines' own shadow walks (the way
# before issue 42, --box-shadows lines --box-lines 32), digital lines,
# interpolated shadows, and the default with the CDSM's trees (--canopy:
# crowns met by each cell's own ray too; --old adds them on the families'
# walks, --box-shadows lines). Whole-process wall time and the run's own phases and
# shadow counts, medians of --reps alternated runs, as a markdown table on
# stdout; the load average before and after. OMP_WAIT_POLICY is passive
# unless set: on a shared machine a spinning OpenMP barrier costs a busy
# core's time (doc/performance.md, "Several runs side by side").
# usage: doc/bench/city_year.sh [--reps N] [--old] [--device NAME]
#   --reps N       runs per job (default 3)
#   --old          also the box lines' own walks, without and with trees
#                  (minutes a run, 1 run each)
#   --device NAME  every run on that device (skysweep's --device; default:
#                  skysweep's own, the C twin unless SKYSWEEP_DEVICE says)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
usage() { sed -n 's/^# \{0,1\}//; /^usage:/,/SKYSWEEP_DEVICE says/p' "$0"; }
reps=3 old=0 device=()
while [ $# -gt 0 ]; do
    case $1 in
    --reps) reps=${2:?--reps needs a number} && shift ;;
    --old) old=1 ;;
    --device) device=(--device "${2:?--device needs a name}") && shift ;;
    -h | --help) usage && exit 0 ;;
    *) usage >&2 && exit 2 ;;
    esac
    shift
done
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
SKYSWEEP=${SKYSWEEP:-$top/skysweep}
data=$top/../shared/data
dsm=$data/goteborg_kronenhuset_dsm_1m.tif epw=$data/weather/NLD_Amsterdam062400_IWEC.epw
cdsm=$data/goteborg_kronenhuset_cdsm_1m.tif
for f in "$dsm" "$epw" "$cdsm"; do
    [ -r "$f" ] || { echo "city_year.sh: $f is not here (../shared/data)" >&2 && exit 3; }
done
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-city-year.XXXXXX")
trap 'rm -rf "$work"' EXIT
median() { sort -g | awk '{ v[NR] = $1 } END { if (NR) print v[int((NR + 1) / 2)] }'; }

names=("default (exact, each cell's own ray)" "digital lines, exact" \
    "interpolated shadows, 32 directions" "default, with trees (--canopy)")
args=("" "--lines digital" "--shadow interpolated --directions 32" "--canopy $cdsm")
if [ "$old" = 1 ]; then
    names+=("box lines' own walks (--box-shadows lines --box-lines 32)"
        "the same with trees (--canopy)")
    args+=("--box-shadows lines --box-lines 32" "--box-shadows lines --box-lines 32 --canopy $cdsm")
fi
commit=$(git -C "$top" rev-parse --short HEAD 2>/dev/null || echo '?')
echo "Measured by \`doc/bench/city_year.sh --reps $reps$([ "$old" = 1 ] && echo " --old")${device[*]:+ ${device[*]}}\` on" \
    "$(date -u '+%Y-%m-%d %H:%M') UTC, skysweep $commit, OMP_WAIT_POLICY=$OMP_WAIT_POLICY;" \
    "load average before: $(cut -d' ' -f1-3 /proc/loadavg)."
echo
echo "| run | wall s (median) | runs | sweeps s | the rest s | shadows |"
echo "|---|---|---|---|---|---|"
for rep in $(seq "$reps"); do
    for i in "${!names[@]}"; do
        [ "$rep" -gt 1 ] && [ "$i" -ge $((${#names[@]} - 2)) ] && [ "$old" = 1 ] && continue
        start=$(date +%s.%N)
        # shellcheck disable=SC2086
        "$SKYSWEEP" insolation ${device[@]+"${device[@]}"} --weather "$epw" --weather-far-ok --pv ${args[$i]} "$dsm" \
            "$work/out.tif" >"$work/$i.$rep.txt" 2>&1
        awk -v a="$(date +%s.%N)" -v b="$start" 'BEGIN { print a - b }' >>"$work/$i.wall"
    done
done
for i in "${!names[@]}"; do
    last=$work/$i.1.txt
    phase() { sed -n "s/^phases .* $1 \([0-9.]*\) s.*/\1/p" "$last"; }
    shadows=$(sed -n 's/^shadows \([0-9]*\) steps of box shadows.*: \([0-9]*\) of \([0-9]*\) cell-steps (\([0-9.]*\) %) marched.*/\1 steps by each cell'"'"'s own ray, \4 % of cells marched/p' "$last")
    echo "| ${names[$i]} | $(median <"$work/$i.wall" | xargs printf '%.2f') |" \
        "$(tr '\n' ' ' <"$work/$i.wall" | xargs printf '%.1f ' | sed 's/ $//') |" \
        "$(phase sweeps) | $(phase 'the rest') | ${shadows:--} |"
done
echo
echo "Load average after: $(cut -d' ' -f1-3 /proc/loadavg)."
