#!/bin/bash
# The core-only build (configure --enable-core-only, doc/scale.md's and
# doc/gpu.md's machines without GDAL): the library and the benchmark
# drivers link nothing but OpenCL and the C runtime, and ss-bench sweeps on
# the C twin and, where there is one, an OpenCL device. The core's tests
# themselves run beside this script.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
build=$(dirname "$(realpath "${SKYSWEEP:-./skysweep}")")
for f in .libs/libskysweep.so.0 .libs/ss-bench ss-bench .libs/ss-scale ss-scale; do
    [ -e "$build/$f" ] || continue
    case $f in */ss-bench | ss-bench) bench=$build/$f ;; esac
    foreign=$(ldd "$build/$f" 2>/dev/null | grep -E -i 'gdal|geographic|proj|inih|json-c|mpi|OpenImageIO|vtk' | awk '{print $1}' | tr '\n' ' ')
    [ -z "$foreign" ]
    tap_ok $? "$f links no adapter library${foreign:+: $foreign}"
done
[ ! -e "$build/skysweep" ] && [ ! -e "$build/.libs/libssadapt.a" ] && [ ! -e "$build/libssadapt.la" ]
tap_ok $? "no command line and no adapters are built"
[ -n "${bench:-}" ] && "$bench" --synthetic 128 --directions 4 --reps 1 --device reference >"$build/tests/core_bench.out" 2>&1
tap_ok $? "ss-bench sweeps on the C twin: $(tail -n 1 "$build/tests/core_bench.out" 2>/dev/null | head -c 200)"
# ss-scale in bands gives the whole grid's answer (its check line: the
# product's mean), for each product it drives.
for f in .libs/ss-scale ss-scale; do [ -x "$build/$f" ] && scale=$build/$f; done
for product in "" --horizon "--insolation 2026-12-01T00:00Z/P1D/PT2H"; do
    [ -n "${scale:-}" ] || break
    # shellcheck disable=SC2086
    whole=$("$scale" --size 96 --directions 8 $product --whole 2>&1 | grep '^check')
    # shellcheck disable=SC2086
    banded=$("$scale" --size 96 --directions 8 $product --band-rows 10 2>&1 | grep '^check')
    [ -n "$whole" ] && [ "$whole" = "$banded" ]
    tap_ok $? "ss-scale ${product:-svf} in bands of 10 rows == whole grid: ${banded:-failed} (whole: ${whole:-failed})"
done
if command -v clinfo >/dev/null 2>&1 && clinfo -l 2>/dev/null | grep -q Device; then
    "$bench" --synthetic 128 --directions 4 --reps 1 >"$build/tests/core_bench_cl.out" 2>&1
    tap_ok $? "ss-bench sweeps on the default OpenCL device: $(tail -n 1 "$build/tests/core_bench_cl.out" | head -c 200)"
else
    tap_skip "ss-bench on an OpenCL device" "no OpenCL device here"
fi
tap_done
