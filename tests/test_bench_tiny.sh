#!/bin/bash
# The peer benchmark's CI mode (doc/performance.sh --tiny): one 128 x 128
# synthetic DEM, 16 directions, every product, absent peers skipped, under
# a minute. Passes when the script exits 0, every skysweep measurement in its
# table succeeded, and every peer that ran was compared with skysweep; skips
# when the benchmark's own prerequisites (/usr/bin/time, gdal_translate,
# python3-gdal) are missing, as the script itself does. Then the cumulative
# sky's and the shadow modes' error tables in their quick modes, and the phases of issue 17's jobs
# (doc/bench/phases.sh) once each.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
bench="${TOP_SRCDIR:-.}/doc/performance.sh"
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-bench-tiny.XXXXXX")
trap 'rm -rf "$work"' EXIT

start=$(date +%s)
# A hang must not stall the suite: 5 minutes, five times what it needs.
SKYSWEEP=$(realpath "$SKYSWEEP") TMPDIR=$work timeout 300 bash "$bench" --tiny \
    >"$work/report.md" 2>"$work/stderr"
rc=$?
elapsed=$(($(date +%s) - start))

if [ "$rc" -eq 0 ] && grep -q 'performance.sh --tiny: skipped' "$work/stderr"; then
    tap_skip "doc/performance.sh --tiny" "$(grep -m 1 'missing:' "$work/stderr")"
    tap_done
    exit
fi

# The timing table's skysweep rows: tool in column 5 of the Markdown row,
# wall time in column 7 (a number when the run succeeded).
problems=$(awk -F' [|] ' '
    /^[|] synthetic/ && $4 == "skysweep" && $6 !~ /^[0-9.]+$/ { print "skysweep " $2 " " $3 ": " $6 }
    /^[|] synthetic/ && NF >= 12 && $6 ~ /comparison failed/ { print $4 ": " $6 }
' "$work/report.md")
ours=$(grep -c '^| synthetic (128 x 128) | [a-z]* | [0-9-]* | skysweep |' "$work/report.md")
peers=$(awk -F' [|] ' '/^[|] synthetic/ && NF < 12 && $4 != "skysweep" && $6 ~ /^[0-9.]+$/' \
    "$work/report.md" | grep -c .)
compared=$(awk -F' [|] ' '/^[|] synthetic/ && NF >= 12' "$work/report.md" | grep -c .)
tap_diag "exit $rc after $elapsed s; skysweep rows: $ours; peer runs: $peers; comparisons: $compared"
[ -z "$problems" ] || tap_diag "$problems"
[ "$rc" -eq 0 ] || tap_diag "$(tail -n 3 "$work/stderr")"
grep '^note:' "$work/stderr" | while read -r line; do tap_diag "$line"; done
[ "$rc" -eq 0 ] && [ -z "$problems" ] && [ "$ours" -ge 5 ]
tap_ok $? "doc/performance.sh --tiny runs every product and compares the peers present ($elapsed s)"

# The phases of issue 17's jobs (doc/bench/phases.sh --reps 1): every row
# measured, and no phase longer than its whole process.
SKYSWEEP=$(realpath "$SKYSWEEP") TMPDIR=$work timeout 300 \
    bash "${TOP_SRCDIR:-.}/doc/bench/phases.sh" --reps 1 >"$work/phases.md" 2>"$work/stderr"
rc=$?
bad=$(awk -F' [|] ' '/^[|] `/ { ok = NF == 9
        for (i = 2; i <= 9; i++) { sub(/ [|]$/, "", $i); if ($i !~ /^[0-9]+$/ || (i > 2 && $i + 0 > $2 + 0)) ok = 0 }
        if (!ok) print }' "$work/phases.md")
rows=$(grep -c '^| `' "$work/phases.md")
[ "$rc" -eq 0 ] && [ "$rows" -eq 5 ] && [ -z "$bad" ]
tap_ok $? "doc/bench/phases.sh --reps 1: exit $rc, $rows rows measured $(echo "$bad" | head -c 300)"

# The cumulative sky's error table (doc/cumulative_sky.sh --quick): every
# row measured, its reference row exact. Needs numpy (tests/pyvenv).
python=${SKYSWEEP_PVLIB_PYTHON:-${TOP_SRCDIR:-.}/tests/pyvenv/bin/python}
if "$python" -c "import numpy" 2>/dev/null; then
    SKYSWEEP=$(realpath "$SKYSWEEP") PYTHON=$python TMPDIR=$work timeout 300 \
        bash "${TOP_SRCDIR:-.}/doc/cumulative_sky.sh" --quick >"$work/cumulative.md" 2>"$work/stderr"
    rc=$?
    rows=$(grep -c '^| cumulative' "$work/cumulative.md")
    [ "$rc" -eq 0 ] && [ "$rows" -ge 2 ] && ! grep -q 'nan' "$work/cumulative.md"
    tap_ok $? "doc/cumulative_sky.sh --quick: exit $rc, $rows cumulative rows $(tail -n 2 "$work/stderr" | head -c 200)"
    # The shadow modes' table (doc/shadow_modes.sh --quick): every row
    # measured on terrain (and the city where ../shared/data has it).
    SKYSWEEP=$(realpath "$SKYSWEEP") PYTHON=$python TMPDIR=$work timeout 300 \
        bash "${TOP_SRCDIR:-.}/doc/shadow_modes.sh" --quick >"$work/modes.md" 2>"$work/stderr"
    rc=$?
    rows=$(grep -c '^| terrain' "$work/modes.md")
    [ "$rc" -eq 0 ] && [ "$rows" -eq 2 ] && ! grep -q 'nan' "$work/modes.md"
    tap_ok $? "doc/shadow_modes.sh --quick: exit $rc, $rows terrain rows $(tail -n 2 "$work/stderr" | head -c 200)"
else
    tap_skip "doc/cumulative_sky.sh --quick" "no numpy at $python (tests/run.sh installs it)"
    tap_skip "doc/shadow_modes.sh --quick" "no numpy at $python (tests/run.sh installs it)"
fi
tap_done
