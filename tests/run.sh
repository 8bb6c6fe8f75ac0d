#!/bin/sh
# Set-up command 2 (README): installs what is needed, builds skysweep with
# warnings as errors and runs the whole test suite; the last line is
# "N passed, N failed".
set -u
cd "$(dirname "$0")/.."
build-aux/deps.sh || exit 1
build-aux/build.sh --enable-werror || exit 1
# VTK renders need an X server (reference/toolchain.md): run under Xvfb.
if command -v xvfb-run >/dev/null 2>&1 && [ -z "${DISPLAY:-}" ]; then
    xvfb-run -a make -j"$(nproc)" check >tests/check.out 2>&1
else
    make -j"$(nproc)" check >tests/check.out 2>&1
fi
status=$?
grep -E '^(FAIL|ERROR|XPASS):' tests/check.out
summary=$(cat test-suite.log 2>/dev/null)
count() { echo "$summary" | sed -n "s/^# $1: *//p" | head -n1; }
pass=$(count PASS) fail=$(count FAIL) error=$(count ERROR) xpass=$(count XPASS)
failed=$(( ${fail:-0} + ${error:-0} + ${xpass:-0} ))
[ "$status" -ne 0 ] && [ "$failed" -eq 0 ] && failed=1 && tail -n 30 tests/check.out
echo "${pass:-0} passed, $failed failed"
[ "$failed" -eq 0 ]
