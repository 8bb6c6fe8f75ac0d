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
# product's mean), for each product it drives: the same line, but for
# insolation, whose steps' sun tables follow each band's range of suns and
# air pressures (doc/insolation.md): its mean within 1e-6 relative and a
# unit of the last printed digit.
same_check() { # same_check WHOLE BANDED TOLERANT
    [ -n "$1" ] || return 1
    [ "$3" = 1 ] || { [ "$1" = "$2" ]; return; }
    printf '%s\n%s\n' "$1" "$2" | awk '{ for (i = 1; i <= NF; ++i) if ($i == "mean") { v[NR] = $(i + 2); w[NR] = $(i + 1) } }
        END { d = v[1] - v[2]; if (d < 0) d = -d; a = v[1] < 0 ? -v[1] : v[1]
              exit !(NR == 2 && w[1] == w[2] && v[1] != "" && d <= 1e-6 * a + 0.001) }'
}
for f in .libs/ss-scale ss-scale; do [ -x "$build/$f" ] && scale=$build/$f; done
for product in "" --horizon "--insolation 2026-12-01T00:00Z/P1D/PT2H"; do
    [ -n "${scale:-}" ] || break
    # shellcheck disable=SC2086
    whole=$("$scale" --size 96 --directions 8 $product --whole 2>&1 | grep '^check')
    # shellcheck disable=SC2086
    banded=$("$scale" --size 96 --directions 8 $product --band-rows 10 2>&1 | grep '^check')
    case $product in --insolation*) tolerant=1 ;; *) tolerant=0 ;; esac
    same_check "$whole" "$banded" "$tolerant"
    tap_ok $? "ss-scale ${product:-svf} in bands of 10 rows == whole grid: ${banded:-failed} (whole: ${whole:-failed})"
done
if command -v clinfo >/dev/null 2>&1 && clinfo -l 2>/dev/null | grep -q Device; then
    "$bench" --synthetic 128 --directions 4 --reps 1 >"$build/tests/core_bench_cl.out" 2>&1
    tap_ok $? "ss-bench sweeps on the default OpenCL device: $(tail -n 1 "$build/tests/core_bench_cl.out" | head -c 200)"
else
    tap_skip "ss-bench on an OpenCL device" "no OpenCL device here"
fi
tap_done
