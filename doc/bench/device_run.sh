#!/bin/bash
# Runs on a lent GPU machine, over a bundle made by device_bundle.sh: the
# core-only tests with SKYSWEEP_DEVICE naming the GPU (so each test's default
# device is the GPU and its twin the C reference), then ss-bench on the GPU
# and on PoCL over the machine's CPU cores, one line per measurement, then
# ss-scale's whole-grid SVF and horizon products on both, then a week of
# hourly clear-sky insolation (a year is 52 of them) with exact shadows, and
# the GPU's per-cell work against the host's, exact and interpolated.
#
#   doc/bench/device_run.sh [DIR] [OUTDIR]    (defaults .gpu and $OUT or .)
#
# GPU is the part of "platform: device" names to match (default NVIDIA);
# PARTS the parts to run (default "tests bench scale solar").
set -u
dir=${1:-.gpu}
out=${2:-${OUT:-.}}
gpu=${GPU:-NVIDIA}
parts=${PARTS:-tests bench scale solar}
want() { case " $parts " in *" $1 "*) return 0 ;; esac; return 1; }
export LD_LIBRARY_PATH=$PWD/$dir/lib POCL_CACHE_DIR=${TMPDIR:-/tmp}/ss-pocl-cache
# CUDA's OpenCL loader reads only /etc/OpenCL/vendors, which lists PoCL alone.
if [ -d /etc/OpenCL/vendors ] && [ -w /etc/OpenCL/vendors ] && ! ls /etc/OpenCL/vendors | grep -qi nvidia; then
    echo libnvidia-opencl.so.1 >/etc/OpenCL/vendors/nvidia.icd
fi
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader 2>/dev/null
echo "cpu: $(nproc) x $(sed -n 's/^model name\t: //p' /proc/cpuinfo | head -n 1)"

want tests && echo "== core tests, default device $gpu, twin: C reference"
want tests && for t in $(cat "$dir/core_tests"); do
    SKYSWEEP_DEVICE=$gpu timeout 150 "$dir/bin/test_$t" >"$out/test_$t.log" 2>&1
    rc=$?
    echo "test_$t rc=$rc ok=$(grep -c '^ok' "$out/test_$t.log") not_ok=$(grep -c '^not ok' "$out/test_$t.log")"
    grep '^not ok' "$out/test_$t.log" | head -n 5
done
want tests && cat "$out"/test_*.log >"$out/tests.log" && rm -f "$out"/test_*.log

bench() { timeout 120 "$dir/bin/ss-bench" "$@" 2>&1 | grep -v '^peak' | sed 's/^/  /'; echo; }
read -r w h <"$dir/data/dem.size"
want bench && for dev in "$gpu" "Portable"; do
    echo "== ss-bench on $dev"
    bench --device "$dev" --raw "$dir/data/dem.raw" "$w" "$h" --directions 16 --reps 7
    bench --device "$dev" --raw "$dir/data/dem.raw" "$w" "$h" --directions 64 --reps 5
    bench --device "$dev" --synthetic 1024 --directions 64 --reps 5
    bench --device "$dev" --synthetic 4096 --directions 64 --reps 3
    bench --device "$dev" --synthetic 4096 --directions 64 --reps 3 --lines digital
    [ "$dev" = "$gpu" ] || continue
    bench --device "$dev" --synthetic 1024 --directions 256 --reps 5
    # The batch against one direction per launch, and bands against the whole grid.
    bench --device "$dev" --synthetic 1024 --directions 256 --reps 5 --batch 1
    bench --device "$dev" --synthetic 4096 --directions 64 --reps 3 --band-rows 512
    bench --device "$dev" --synthetic 8192 --directions 64 --reps 3
done

want scale && for product in "" --horizon; do
    for dev in "$gpu" "Portable"; do
        echo "== ss-scale whole grid ${product:-svf} on $dev"
        timeout 150 "$dir/bin/ss-scale" --size 8192 --directions 16 --whole $product \
            --device "$dev" 2>&1 | grep -E '^(grid|device|time|check)' | sed 's/^/  /'
    done
done

week=2026-06-01T00:00Z/P7D/PT1H
want solar && for dev in "$gpu" "Portable"; do
    echo "== ss-scale insolation, a week of hourly steps, on $dev"
    for size in 1024 4096; do
        [ "$dev" = "$gpu" ] || [ "$size" -eq 1024 ] || continue
        for mode in --whole "--memory 512"; do
            timeout 300 "$dir/bin/ss-scale" --size $size --directions 16 --insolation $week \
                $mode --device "$dev" 2>&1 | grep -E '^(grid|steps|bands|time|check)' |
                sed 's/^/  /'
        done
    done
done
# The GPU's per-cell work (its default) against the same on the host, with
# exact and with interpolated shadows (the stored horizons uploaded per band).
for shadows in "" --interpolated; do
    for cells in device host; do
        want solar || continue
        echo "== ss-scale insolation on $gpu, 4096 whole, ${shadows:-exact}, cells on the $cells"
        SKYSWEEP_CELLS=$cells timeout 300 "$dir/bin/ss-scale" --size 4096 --directions 16 \
            --insolation $week --whole $shadows --device "$gpu" 2>&1 |
            grep -E '^(grid|steps|time|check)' | sed 's/^/  /'
    done
done
