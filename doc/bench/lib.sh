# shellcheck shell=bash
# Timing helpers, sourced by doc/performance.sh and doc/bench/grass_peer.sh.
# The latter runs inside a GRASS session, so that what is timed there is the
# GRASS module alone, not the session start, the import or the export.
# Settings come from the environment: REPS, TIMEOUT and SLOW (seconds).

# Seconds of wall time in a `/usr/bin/time -v` report ("h:mm:ss" or "m:ss.ss").
wall_seconds() {
    awk -F': ' '/Elapsed \(wall clock\)/ {
        n = split($2, t, ":"); s = 0
        for (i = 1; i <= n; i++) s = s * 60 + t[i]
        print s
    }' "$1"
}

# Peak resident set size in MB from a `/usr/bin/time -v` report.
rss_mb() {
    awk -F': ' '/Maximum resident set size/ {printf "%.0f\n", $2 / 1024}' "$1"
}

# The median of the numbers on stdin, one a line (empty input: no output).
median() {
    sort -g | awk '{v[NR] = $1} END {
        if (NR) print (NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2)
    }'
}

# timed_reps DIR CMD...: runs CMD under `/usr/bin/time -v` $REPS times, each
# run limited to $TIMEOUT s; a run longer than $SLOW s is not repeated (its
# median would cost hours and tell little more). DIR receives one report per
# run (time.1, time.2, ...), the command's output (log) and a one-line
# status: ok, timeout or "failed (exit N)".
timed_reps() {
    local dir=$1 i rc
    shift
    mkdir -p "$dir"
    for ((i = 1; i <= REPS; i++)); do
        rc=0
        /usr/bin/time -v -o "$dir/time.$i" timeout "$TIMEOUT" "$@" >>"$dir/log" 2>&1 || rc=$?
        if [ "$rc" -ne 0 ]; then
            rm -f "$dir/time.$i"
            if [ "$rc" -eq 124 ]; then echo timeout; else echo "failed (exit $rc)"; fi >"$dir/status"
            return 0
        fi
        if awk -v w="$(wall_seconds "$dir/time.$i")" -v s="$SLOW" 'BEGIN {exit !(w > s)}'; then
            break
        fi
    done
    echo ok >"$dir/status"
}
