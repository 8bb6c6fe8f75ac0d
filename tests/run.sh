#!/bin/sh
# Set-up command 2 (README): installs what is needed, builds skysweep with
# warnings as errors and runs the whole test suite, then the core-only
# build's (configure --enable-core-only); then, under CI (CI=true)
# or with --sanitizers, builds a copy with AddressSanitizer and
# UndefinedBehaviorSanitizer and runs the suite again there. The last line
# is "N passed, N failed" over everything that ran.
set -u
cd "$(dirname "$0")/.."
sanitizers=0
[ "${CI:-}" = true ] && sanitizers=1
[ "${1:-}" = --sanitizers ] && sanitizers=1
# Seconds since $1 (date +%s), for the phases' lines: what CI prints is
# all a later reader has of where its time went.
since() { echo "$(($(date +%s) - $1)) s"; }
started=$(date +%s)
build-aux/deps.sh || exit 1

# Builds the OpenCL kernels once into the suite's kernel cache, so that the
# tests, which run in parallel, do not all compile them at once at their
# start: under the sanitizer build, processes that had just compiled kernels
# beside each other were where LeakSanitizer's tracer crashed at exit
# ("Tracer caught signal 11", google/sanitizers#1353). What it prints or
# returns does not count; the tests check the kernels themselves.
warm_kernel_cache() {
    dem=samples/kilauea_summit_30m.tif out=$(mktemp -d "${TMPDIR:-/tmp}/ss-warm.XXXXXX")
    for args in "svf" "svf --definition radiative" "svf --radius 300" \
        "horizon --distance $out/d.tif --cast-height $out/c.tif"; do
        # shellcheck disable=SC2086
        POCL_CACHE_DIR=$PWD/tests/pocl-cache ASAN_OPTIONS=detect_leaks=0 \
            ./skysweep $args -q --directions 4 "$dem" "$out/o.tif" >/dev/null 2>&1
    done
    rm -rf "$out"
}

# Runs make check in the current directory (under Xvfb: VTK renders need an
# X server, reference/toolchain.md); prints the failures; sets pass, failed.
check() {
    warm_kernel_cache
    if command -v xvfb-run >/dev/null 2>&1 && [ -z "${DISPLAY:-}" ]; then
        xvfb-run -a make -j"$(nproc)" check >tests/check.out 2>&1
    else
        make -j"$(nproc)" check >tests/check.out 2>&1
    fi
    status=$?
    grep -E '^(FAIL|ERROR|XPASS):' tests/check.out
    # The end of each failing test's log: CI keeps only what is printed.
    grep -E '^(FAIL|ERROR|XPASS):' tests/check.out | awk '!seen[$2]++ { print $2 }' |
        while read -r name; do
            # automake's log of tests/x.sh is tests/x.log
            echo "--- the end of ${name%.sh}.log:"
            tail -n 20 "${name%.sh}.log" 2>/dev/null | sed 's/^/    /'
        done
    summary=$(cat test-suite.log 2>/dev/null)
    count() { echo "$summary" | sed -n "s/^# $1: *//p" | head -n1; }
    pass=$(count PASS) fail=$(count FAIL) error=$(count ERROR) xpass=$(count XPASS)
    failed=$(( ${fail:-0} + ${error:-0} + ${xpass:-0} ))
    [ "$status" -ne 0 ] && [ "$failed" -eq 0 ] && failed=1 && tail -n 30 tests/check.out
    pass=${pass:-0}
}

# pvlib, the independent reference of the solar tests, and what the Python
# package builds and tests with (cffi, wheel, pytest; xarray and rasterio
# for the objects it takes), in a venv of its own (reference/toolchain.md: its numpy 2
# must not meet Debian's); the tests that need them skip, saying why, where
# they cannot be installed.
setup_pvlib() {
    venv=$PWD/tests/pyvenv
    "$venv/bin/python" -c "import pvlib, cffi, wheel, pytest, xarray, rasterio" 2>/dev/null && return
    [ -x "$venv/bin/pip" ] || python3 -m venv "$venv" >tests/pyvenv.log 2>&1
    "$venv/bin/pip" install -q --disable-pip-version-check pvlib==0.16.1 cffi==2.1.1 \
        wheel==0.48.0 pytest==9.2.0 xarray==2026.9.0 rasterio==1.4.4 >>tests/pyvenv.log 2>&1 ||
        echo "the test venv could not be installed (tests/pyvenv.log): its comparisons skip"
}
setup_pvlib

# Debian's QGIS 3.22, for the Processing provider's tests (a few minutes, as
# root); they skip, saying why, where it cannot be installed.
setup_qgis() {
    [ -x /usr/bin/qgis_process.bin ] && return
    [ "$(id -u)" -eq 0 ] || { echo "not root: QGIS is not installed and its tests skip"; return; }
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq qgis python3-qgis qgis-providers \
        >tests/qgis-install.log 2>&1 ||
        echo "QGIS could not be installed (tests/qgis-install.log): its tests skip"
}
setup_qgis
SKYSWEEP_PVLIB_PYTHON=$PWD/tests/pyvenv/bin/python
export SKYSWEEP_PVLIB_PYTHON

echo "set-up (packages, test venv, QGIS): $(since "$started")"
started=$(date +%s)
build-aux/build.sh --enable-werror || exit 1
check
total_pass=$pass total_failed=$failed
echo "tests: $pass passed, $failed failed (build and suite: $(since "$started"))"

# `make install prefix=DIR` into a folder of its own, after the build above was
# made for another prefix: the libraries relink for DIR and the installed CLI
# runs with its modules from DIR/lib/skysweep. One test, counted in the totals;
# outside the suite, which it would relink under.
# The Python package built over that installed library, found with pkg-config
# (python/setup.py's third way): from a copy of python/ away from the tree, it
# uses DIR's library and command line. One test, counted in the totals.
check_python_over_install() {
    py=$SKYSWEEP_PVLIB_PYTHON top=$PWD
    if ! "$py" -c "import cffi, numpy, wheel" 2>/dev/null; then
        echo "skip: the Python package over make install (no test venv)"
        return
    fi
    cp -r python "$1/python" && rm -rf "$1/python/build" "$1"/python/*.egg-info
    if PKG_CONFIG_PATH=$1/lib/pkgconfig "$py" -m pip install -q --disable-pip-version-check \
        --no-build-isolation --no-deps --target "$1/site" "$1/python" >tests/install-python.log 2>&1 &&
        (cd "$1" && PYTHONPATH=$1/site "$py" -c "
import numpy as np, skysweep
from skysweep._lib import BUILD, CLI
assert BUILD['library'] == '$1/lib/libskysweep.so.0' and CLI == '$1/bin/skysweep', BUILD
assert skysweep.svf(np.add.outer(np.arange(9.0), np.arange(7.0)) ** 2, 10).shape == (9, 7)
skysweep.svf_file('$top/samples/kilauea_summit_30m.tif', 'svf.tif', directions=4)") \
            >>tests/install-python.log 2>&1; then
        echo "ok: the Python package installs over make install prefix=DIR, found with pkg-config"
        total_pass=$((total_pass + 1))
    else
        echo "not ok: the Python package over make install prefix=DIR (tests/install-python.log):"
        tail -n 5 tests/install-python.log | sed 's/^/    /'
        total_failed=$((total_failed + 1))
    fi
}

check_install_prefix() {
    prefix=$(mktemp -d "${TMPDIR:-/tmp}/ss-prefix.XXXXXX")
    if make install prefix="$prefix" >tests/install-prefix.log 2>&1 &&
        "$prefix/bin/skysweep" info >"$prefix/info.out" 2>&1 &&
        grep -q "^module   skysweep-images.so: $prefix/lib/skysweep/" "$prefix/info.out" &&
        "$prefix/bin/skysweep" svf -q --directions 4 samples/kilauea_summit_30m.tif "$prefix/svf.tif"; then
        echo "ok: make install prefix=DIR installs a CLI that runs with its modules from DIR"
        total_pass=$((total_pass + 1))
    else
        echo "not ok: make install prefix=DIR (tests/install-prefix.log):"
        tail -n 5 tests/install-prefix.log "$prefix/info.out" 2>/dev/null | sed 's/^/    /'
        total_failed=$((total_failed + 1))
    fi
    check_python_over_install "$prefix"
    rm -rf "$prefix"
    # Back to the prefix the build was configured for.
    make -j"$(nproc)" >/dev/null 2>&1
}
check_install_prefix

# Builds a copy of the tracked files with configure options $2..., so the
# tree above keeps its build, runs the suite there, and adds its counts to
# the totals under the label $1.
check_copy() {
    label=$1 started=$(date +%s)
    shift
    copy=$(mktemp -d "${TMPDIR:-/tmp}/skysweep-copy.XXXXXX")
    if git ls-files -z | xargs -0 cp --parents -t "$copy" 2>/dev/null &&
        (cd "$copy" && build-aux/build.sh "$@" --enable-werror); then
        (cd "$copy" && check && echo "$pass $failed" >tests/counts)
        read -r pass failed <"$copy/tests/counts" 2>/dev/null || { pass=0 failed=1; }
    else
        echo "the build $label failed"
        pass=0 failed=1
    fi
    echo "tests $label: $pass passed, $failed failed (build and suite: $(since "$started"))"
    total_pass=$((total_pass + pass)) total_failed=$((total_failed + failed))
    rm -rf "$copy"
}

# The core alone (the library, ss-bench and the core's tests with nothing
# but OpenCL), as a machine without GDAL builds it.
check_copy "of the core-only build" --enable-core-only
[ "$sanitizers" -eq 1 ] && check_copy "with sanitizers" --enable-sanitizers
echo "$total_pass passed, $total_failed failed"
[ "$total_failed" -eq 0 ]
