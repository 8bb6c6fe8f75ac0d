#!/bin/sh
# Builds the libFuzzer harnesses with clang from the sources of a configured
# tree (config.h and src/core/kernel_source.c must exist: ./configure &&
# make first). Every core, adapter and CLI source (not main.c, not the
# OpenImageIO/VTK adapters) is compiled with the fuzzer's instrumentation
# into one archive, so a harness pulls in only what it calls. Usage:
#   tests/fuzz/build.sh [OUTDIR]              fuzzers + replayers, ASan + UBSan
#   MODE=opencl tests/fuzz/build.sh OUTDIR    fuzz_sweep with the OpenCL
#                                             device too, no ASan (PoCL's JIT)
#   MODE=coverage tests/fuzz/build.sh OUTDIR  replayers with source coverage (cov_NAME)
# Running them: doc/reliability.md.
set -eu
top=$(cd "$(dirname "$0")/../.." && pwd)
out=${1:-/tmp/ss-fuzz}
mode=${MODE:-fuzz}
CC=${CC:-clang}
CXX=${CXX:-clang++}
cd "$top"
[ -f config.h ] && [ -f src/core/kernel_source.c ] || {
    echo "build.sh: configure and build the tree first (config.h, kernel_source.c)" >&2
    exit 1
}
case $mode in
fuzz)
    lib_flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fsanitize=fuzzer-no-link"
    fuzz_flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined -fsanitize=fuzzer"
    replay_flags="-fsanitize=address,undefined -fno-sanitize-recover=undefined" ;;
opencl)
    lib_flags="-fsanitize=fuzzer-no-link"
    fuzz_flags="-fsanitize=fuzzer -DFUZZ_SWEEP_OPENCL"
    replay_flags="" ;;
coverage)
    lib_flags="-fprofile-instr-generate -fcoverage-mapping"
    fuzz_flags=""
    replay_flags="$lib_flags" ;;
*) echo "build.sh: unknown MODE $mode" >&2; exit 2 ;;
esac
obj=$out/obj-$mode
mkdir -p "$obj"
incs="-I. -Isrc -Isrc/core -Isrc/adapt -Isrc/cli -Ikernels -Itests"
# What libsscli_la_CFLAGS defines (Makefile.am): where the modules are found.
incs="$incs -DSS_BUILD_DIR=\"$top\" -DSS_MODULE_DIR=\"$top/.libs\""
pkgs="gdal OpenCL geographiclib json-c"
# Optional dependencies as configure found them (scene files, MPI, images, 3D).
mk() { sed -n "s/^$1 = //p" Makefile; }
opt_cflags="$(mk INIH_CFLAGS) $(mk MPI_CFLAGS)"
opt_libs="$(mk INIH_LIBS) $(mk MPI_LIBS) $(mk OIIO_LIBS) $(mk VTK_LIBS)"
cflags="-std=c11 -D_GNU_SOURCE -fno-math-errno -g -O1 -fno-omit-frame-pointer $incs -DTOP_SRCDIR=\"$top\"
 $(pkg-config --cflags $pkgs) $opt_cflags"
cxxflags="-std=c++17 -g -O1 -fno-omit-frame-pointer $incs $(pkg-config --cflags $pkgs)"
libs="$(pkg-config --libs $pkgs) $opt_libs -lm"

rm -f "$obj"/*.o "$obj/libss.a"
for f in src/core/*.c src/adapt/*.c src/adapt/*.cpp src/cli/*.c tests/testlib.c; do
    extra=
    case $f in
    src/cli/main.c) continue ;;
    src/adapt/images.cpp) [ -n "$(mk OIIO_LIBS)" ] || continue; extra=$(mk OIIO_CFLAGS) ;;
    src/adapt/render.cpp) [ -n "$(mk VTK_LIBS)" ] || continue; extra=$(mk VTK_CFLAGS) ;;
    esac
    o=$obj/$(echo "$f" | tr / _).o
    case $f in
    *.cpp) $CXX $cxxflags $extra $lib_flags -c "$f" -o "$o" ;;
    *) $CC $cflags $lib_flags -c "$f" -o "$o" ;;
    esac
done
ar rcs "$obj/libss.a" "$obj"/*.o

harnesses="fuzz_time fuzz_options fuzz_sweep fuzz_dem_read fuzz_scene fuzz_weather fuzz_points"
[ "$mode" = opencl ] && harnesses=fuzz_sweep
for h in $harnesses; do
    name=$h
    [ "$mode" = opencl ] && name=${h}_opencl
    if [ "$mode" != coverage ]; then
        $CC $cflags $fuzz_flags -c tests/fuzz/$h.c -o "$obj/$h.o"
        $CXX $fuzz_flags -o "$out/$name" "$obj/$h.o" "$obj/libss.a" $libs
    fi
    [ "$mode" = opencl ] && continue # its library objects need libFuzzer's runtime
    $CC $cflags $replay_flags -DFUZZ_NAME=\"$h\"  \
        -c tests/fuzz/replay.c -o "$obj/replay_$h.o"
    $CC $cflags $replay_flags -c tests/fuzz/$h.c -o "$obj/$h.r.o"
    prefix=replay_
    [ "$mode" = coverage ] && prefix=cov_
    $CXX $replay_flags -o "$out/$prefix$name" "$obj/replay_$h.o" "$obj/$h.r.o" \
        "$obj/libss.a" $libs
done
echo "built in $out ($mode)"
