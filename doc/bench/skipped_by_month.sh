#!/bin/bash
# The share of shadow work the proven per-cell bounds skip, month by month
# (issue 42: "the share of line-steps skipped, per month"), as a markdown
# table on stdout:
# - terrain: the whole Kilauea DEM, a month of hourly clear sky with exact
#   shadows (interpolated lines): the share of the shadow walks' samples
#   not walked, from the run's own `shadows` line (the C twin counts them:
#   "-" on an OpenCL device, or where the plan made no bounds);
# - a city: the Gothenburg 1 m DSM with the Amsterdam IWEC year and --pv,
#   the month's records (exact box shadows by each cell's own ray): the
#   share of cell-steps marched, the rest settled by the bounds.
# One run a month each, with the wall time and the sweeps' time from the
# run's own phases. OMP_WAIT_POLICY is passive unless set (a spinning
# barrier costs a shared machine's busy core).
# usage: doc/bench/skipped_by_month.sh [--device NAME]
#   --device NAME  every run on that device (skysweep's --device; default:
#                  skysweep's own, the C twin unless SKYSWEEP_DEVICE says)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
usage() { sed -n 's/^# \{0,1\}//; /^usage:/,/SKYSWEEP_DEVICE says/p' "$0"; }
device=()
while [ $# -gt 0 ]; do
    case $1 in
    --device) device=(--device "${2:?--device needs a name}") && shift ;;
    -h | --help) usage && exit 0 ;;
    *) usage >&2 && exit 2 ;;
    esac
    shift
done
export OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-passive}
SKYSWEEP=${SKYSWEEP:-$top/skysweep}
data=$top/../shared/data
dem=$data/hawaii_kilauea_utm5n_30m.tif
dsm=$data/goteborg_kronenhuset_dsm_1m.tif epw=$data/weather/NLD_Amsterdam062400_IWEC.epw
for f in "$dem" "$dsm" "$epw"; do
    [ -r "$f" ] || { echo "skipped_by_month.sh: $f is not here (../shared/data)" >&2 && exit 3; }
done
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-skipped.XXXXXX")
trap 'rm -rf "$work"' EXIT

# timed LOG ARGS...: runs skysweep insolation, its summary into LOG; prints
# the wall seconds.
timed() {
    local log=$1 start
    shift
    start=$(date +%s.%N)
    "$SKYSWEEP" insolation ${device[@]+"${device[@]}"} "$@" >"$log" 2>&1 ||
        { echo "skipped_by_month.sh: skysweep insolation $* failed: $(tail -1 "$log")" >&2 && exit 1; }
    awk -v a="$(date +%s.%N)" -v b="$start" 'BEGIN { printf "%.2f", a - b }'
}
sweeps() { sed -n 's/^phases .* sweeps \([0-9.]*\) s.*/\1/p' "$1"; }
daylight() { sed -n 's/^steps *[0-9]*: \([0-9]*\) in daylight.*/\1/p' "$1"; }

commit=$(git -C "$top" rev-parse --short HEAD 2>/dev/null || echo '?')
echo "Measured by \`doc/bench/skipped_by_month.sh${device[*]:+ ${device[*]}}\` on" \
    "$(date -u '+%Y-%m-%d %H:%M') UTC, skysweep $commit, OMP_WAIT_POLICY=$OMP_WAIT_POLICY;" \
    "load average before: $(cut -d' ' -f1-3 /proc/loadavg). One run each."
echo
echo "| month | Kīlauea: daylight steps | samples not walked | sweeps s | wall s |" \
    "Gothenburg: steps by each cell's ray | cell-steps marched | sweeps s | wall s |"
echo "|---|---|---|---|---|---|---|---|---|"
for m in 01 02 03 04 05 06 07 08 09 10 11 12; do
    t=$(timed "$work/k.txt" --time "2026-$m-01T00:00Z/P1M" --step PT1H --shadow exact "$dem" "$work/k.tif")
    walked=$(sed -n 's/^shadows [0-9]* of .* samples (\([0-9.]*\) %) not walked.*/\1 %/p' "$work/k.txt")
    row="| $m | $(daylight "$work/k.txt") | ${walked:--} | $(sweeps "$work/k.txt") | $t |"
    # A typical year's months come from different years: the month's own.
    year=$(awk -F, -v m=$((10#$m)) 'NR > 8 && $2 == m { print $1; exit }' "$epw")
    [ -n "$year" ] || { echo "skipped_by_month.sh: $epw has no record in month $m" >&2 && exit 3; }
    t=$(timed "$work/c.txt" --weather "$epw" --weather-far-ok --pv --time "$year-$m-01/P1M" "$dsm" "$work/c.tif")
    marched=$(sed -n 's/^shadows \([0-9]*\) steps of box shadows.*(\([0-9.]*\) %) marched.*/\1 | \2 %/p' "$work/c.txt")
    echo "$row ${marched:-0 | none} | $(sweeps "$work/c.txt") | $t |"
done
echo
echo "Load average after: $(cut -d' ' -f1-3 /proc/loadavg)."
