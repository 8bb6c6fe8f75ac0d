#!/bin/sh
# Set-up command 2 (README): installs what is needed, builds skysweep with
# warnings as errors and runs the whole test suite; then, under CI (CI=true)
# or with --sanitizers, builds a copy with AddressSanitizer and
# UndefinedBehaviorSanitizer and runs the suite again there. The last line
# is "N passed, N failed" over everything that ran.
set -u
cd "$(dirname "$0")/.."
sanitizers=0
[ "${CI:-}" = true ] && sanitizers=1
[ "${1:-}" = --sanitizers ] && sanitizers=1
build-aux/deps.sh || exit 1

# Runs make check in the current directory (under Xvfb: VTK renders need an
# X server, reference/toolchain.md); prints the failures; sets pass, failed.
check() {
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
    pass=${pass:-0}
}

build-aux/build.sh --enable-werror || exit 1
check
total_pass=$pass total_failed=$failed
echo "tests: $pass passed, $failed failed"

if [ "$sanitizers" -eq 1 ]; then
    # A copy of the tracked files, so the tree above keeps its build.
    san=$(mktemp -d "${TMPDIR:-/tmp}/skysweep-san.XXXXXX")
    if git ls-files -z | xargs -0 cp --parents -t "$san" 2>/dev/null &&
        (cd "$san" && build-aux/build.sh --enable-sanitizers --enable-werror); then
        (cd "$san" && check && echo "$pass $failed" >tests/counts)
        read -r pass failed <"$san/tests/counts" 2>/dev/null || { pass=0 failed=1; }
    else
        echo "sanitizer build failed"
        pass=0 failed=1
    fi
    echo "tests with sanitizers: $pass passed, $failed failed"
    total_pass=$((total_pass + pass)) total_failed=$((total_failed + failed))
    rm -rf "$san"
fi
echo "$total_pass passed, $total_failed failed"
[ "$total_failed" -eq 0 ]
