#!/bin/bash
# skysweep against its own speed and memory targets (DESIGN.md "Speed to aim
# for", issue 6), printed as Markdown for doc/performance.md:
#   1. svf --directions 16 on the Kilauea DEM: the sweep's compute time
#      (kernels cached) and the whole process, median of 5;
#   2. the sweep against the bare pass that only reads every cell along the
#      same lines (the practical memory-bandwidth limit), both line models;
#   3. scaling in cells x directions from 512^2 to 4096^2 (16 and 64
#      directions): the least-squares exponent, and a plot;
#   4. peak memory of `skysweep svf` against the DEM's float grid;
#   5. where the time goes: skysweep's own split of a run, and a perf
#      profile of the C twin of the kernels.
# Needs a build tree (BUILD, default the source tree): ss-bench, skysweep.
#
#   doc/bench/targets.sh [--quick] [--plot FILE.png] [--reps R]
#
# --quick: 512^2 and 1024^2 only, 3 repetitions (about a minute).
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
top=$(cd "$here/../.." && pwd)
build=${BUILD:-$top}
bench=$build/ss-bench
skysweep=$build/skysweep
sizes="512 1024 2048 4096"
reps=5
plot=""
while [ $# -gt 0 ]; do
    case $1 in
    --quick) sizes="512 1024" reps=3 ;;
    --plot) plot=${2:?--plot needs a file} && shift ;;
    --reps) reps=${2:?--reps needs a number} && shift ;;
    *) echo "usage: doc/bench/targets.sh [--quick] [--plot FILE.png] [--reps R]" >&2 && exit 2 ;;
    esac
    shift
done
[ -x "$bench" ] && [ -x "$skysweep" ] || { echo "targets.sh: build first (make): $bench" >&2; exit 2; }
py=/usr/bin/python3
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-targets.XXXXXX")
trap 'rm -rf "$work"' EXIT
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$work/pocl-cache}

field() { sed -n "s/^$1 *//p" "${2:--}"; }       # a line of ss-bench's report (file or stdin)
first_number() { grep -o '[0-9.]*' | head -n 1; }

dem=$top/../shared/data/hawaii_kilauea_utm5n_30m.tif
[ -r "$dem" ] || dem=$top/samples/kilauea_summit_30m.tif
read -r dem_w dem_h <<<"$(gdalinfo "$dem" | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1 \2/p')"
gdal_translate -q -of ENVI -ot Float32 -a_nodata -3.4e38 "$dem" "$work/dem.raw"
cell=$(gdalinfo "$dem" | sed -n 's/^Pixel Size = (\([0-9.]*\),.*/\1/p')

echo "Measured by \`doc/bench/targets.sh\` on $(date -u '+%Y-%m-%d %H:%M UTC'): $(nproc) cores of"
echo "$(lscpu | sed -n 's/^Model name: *//p' | head -n 1), through $("$bench" --synthetic 64 --directions 1 --reps 1 | field device), kernels"
echo "built once and cached; load average before: $(cut -d' ' -f1-3 /proc/loadavg). Medians of $reps runs."
echo

# ---- 1 and 2: Kilauea, the sweep against the bare pass ---------------------------
echo "### The Kīlauea target and the bare pass"
echo
echo "\`ss-bench\` on $(basename "$dem") ($dem_w × $dem_h cells): the SVF sweep (geometric) against"
echo "the bare pass over the same lines, which reads each cell's height and adds it into the"
echo "cell, with no hull: the cost of visiting every cell once per direction."
echo
echo "| directions | lines | sweep s | M cell-dir/s | bare pass s | M cell-dir/s | sweep / bare |"
echo "|---|---|---|---|---|---|---|"
"$bench" --raw "$work/dem.raw" "$dem_w" "$dem_h" --cell "$cell" --directions 1 --reps 1 >/dev/null
for lines in interpolated digital; do
    for d in 16 64; do
        "$bench" --raw "$work/dem.raw" "$dem_w" "$dem_h" --cell "$cell" --directions "$d" \
            --lines "$lines" --reps "$reps" >"$work/k"
        sweep=$(field sweep "$work/k")
        bare=$(field bare "$work/k")
        echo "| $d | $lines | $(echo "$sweep" | awk '{print $1}') | $(echo "$sweep" | awk '{print $3}') |" \
            "$(echo "$bare" | awk '{print $1}') | $(echo "$bare" | awk '{print $3}') |" \
            "$(field ratio "$work/k" | first_number) |"
        [ "$lines/$d" = interpolated/16 ] && kilauea_sweep=$(echo "$sweep" | awk '{print $1}')
    done
done
"$skysweep" svf -q --directions 16 "$dem" "$work/warm.tif"
for ((i = 1; i <= reps; i++)); do
    /usr/bin/time -f '%e %M' -o "$work/t.$i" "$skysweep" svf --directions 16 "$dem" "$work/svf.tif" \
        >"$work/svf.log.$i"
    sed -n 's/^time *sweep \([0-9.]*\) s.*/\1/p' "$work/svf.log.$i" >"$work/sw.$i"
done
whole=$(cat "$work"/t.* | awk '{print $1}' | sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}')
cli_sweep=$(cat "$work"/sw.* | sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}')
echo
echo "\`skysweep svf --directions 16\` on it: the sweep **$kilauea_sweep s** in \`ss-bench\` (target"
echo "≤ 0.1 s of compute), $cli_sweep s as the command's own summary reports it (the sweep with its"
echo "queueing and read-back), **$whole s** for the whole process (start-up, OpenCL set-up with the"
echo "kernel cache warm, reading, writing a DEFLATE GeoTIFF)."
echo

# ---- 3: scaling -----------------------------------------------------------------------
echo "### Scaling in cells × directions"
echo
echo "\`ss-bench --synthetic N\` (smooth random terrain, 30 m cells), interpolated lines, SVF sweep"
echo "and bare pass, median of $reps:"
echo
: >"$work/scaling.tsv"
for n in $sizes; do
    for d in 16 64; do
        "$bench" --synthetic "$n" --directions "$d" --reps "$reps" >"$work/s"
        printf '%s\t%s\t%s\t%s\n' "$n" "$d" "$(field sweep "$work/s" | awk '{print $1}')" \
            "$(field bare "$work/s" | awk '{print $1}')" >>"$work/scaling.tsv"
    done
done
"$py" - "$work/scaling.tsv" "$plot" <<'EOF'
import sys
import numpy as np

rows = [l.split("\t") for l in open(sys.argv[1]).read().split("\n") if l]
n = np.array([int(r[0]) for r in rows], float)
d = np.array([int(r[1]) for r in rows], float)
sweep = np.array([float(r[2]) for r in rows])
bare = np.array([float(r[3]) for r in rows])
work = n * n * d

print("| grid | directions | sweep s | M cell-dir/s | bare s | sweep / bare |")
print("|---|---|---|---|---|---|")
for i in range(len(rows)):
    print(f"| {int(n[i])}² | {int(d[i])} | {sweep[i]:.3f} | {work[i] / sweep[i] / 1e6:.1f} | "
          f"{bare[i]:.3f} | {sweep[i] / bare[i]:.2f} |")


def exponent(t):
    # log t = e log(cells x directions) + one intercept per direction count
    cols = [np.log(work)] + [(d == v).astype(float) for v in sorted(set(d))]
    coef, *_ = np.linalg.lstsq(np.column_stack(cols), np.log(t), rcond=None)
    return coef[0]


print()
print(f"Least-squares exponent of time against cells × directions, {int(n.min())}² to "
      f"{int(n.max())}² (one intercept per direction count; 1 is linear): sweep "
      f"**{exponent(sweep):.3f}**, bare pass {exponent(bare):.3f}.")
if sys.argv[2]:
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("\n(no plot: matplotlib is not installed)")
        sys.exit(0)
    fig, ax = plt.subplots(figsize=(6.4, 4.2), dpi=120)
    for v, mark in zip(sorted(set(d)), "os^"):
        k = d == v
        ax.loglog(work[k], sweep[k], mark + "-", label=f"sweep, {int(v)} directions")
        ax.loglog(work[k], bare[k], mark + ":", color="grey", label=f"bare pass, {int(v)} directions")
    ref = np.array([work.min(), work.max()])
    ax.loglog(ref, sweep[work.argmin()] * ref / work.min(), "k--", lw=0.8, label="linear")
    ax.set_xlabel("cells × directions")
    ax.set_ylabel("seconds")
    ax.set_title("skysweep SVF sweep, PoCL on the CPU")
    ax.grid(True, which="both", lw=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(sys.argv[2])
    print(f"\n![skysweep's sweep time against cells × directions](img/{sys.argv[2].split('/')[-1]})")
EOF
echo

# ---- 4: memory --------------------------------------------------------------------------
echo "### Memory of svf against the DEM"
echo
big=$(echo "$sizes" | awk '{print $NF}')
"$py" "$here/make_dem.py" "$big" "$work/big.tif"
"$py" "$here/make_dem.py" 64 "$work/small.tif"
for f in small big; do
    "$skysweep" svf -q --directions 16 "$work/$f.tif" "$work/$f-svf.tif"
    /usr/bin/time -f '%M' -o "$work/$f.rss" "$skysweep" svf -q --directions 16 "$work/$f.tif" \
        "$work/$f-svf.tif"
done
"$py" - "$work/small.rss" "$work/big.rss" "$big" <<'EOF'
import sys
small, big = (int(open(p).read().split()[-1]) / 1024 for p in sys.argv[1:3])
n = int(sys.argv[3])
grid = n * n * 4 / 2**20
print(f"`skysweep svf --directions 16` on a {n}² DEM (its float grid {grid:.0f} MiB): peak resident "
      f"{big:.0f} MiB, against {small:.0f} MiB on a 64² DEM (the program, GDAL, PoCL and LLVM). "
      f"The DEM's share, {big - small:.0f} MiB, is **{(big - small) / grid:.2f}×** its float grid "
      "(target ≤ 3×): the heights, the hull stack, the sums, and OpenCL's mapped copies.")
EOF
echo

# ---- 5: where the time goes ------------------------------------------------------------
echo "### Where the time goes"
echo
echo "skysweep's own split of \`svf --directions 16\` on $(basename "$dem") (the last run above):"
echo
echo '```'
grep -E '^(time|memory) ' "$work/svf.log.$reps"
echo '```'
echo
if command -v perf >/dev/null && perf record -q -o "$work/probe.data" true 2>/dev/null; then
    echo "\`perf record\` (software clock: this VM exposes no hardware counters) of"
    echo "\`ss-bench --synthetic 1024 --directions 16\` on PoCL, the share of samples per kernel"
    echo "(the walk, the hull and the SVF term are inlined into \`sweep_svf\`):"
    echo
    echo '```'
    perf record -q -F 2000 -o "$work/perf.data" \
        "$bench" --synthetic 1024 --directions 16 --reps 3 >/dev/null 2>&1
    perf report -q -i "$work/perf.data" --sort dso,symbol --percent-limit 1.5 2>/dev/null |
        grep -v '^$' | sed 's/  *$//' | head -n 8
    echo '```'
    echo
    echo "The instructions of \`sweep_svf\` that collect the most samples (a sample lands on the"
    echo "instruction after a slow one: after a division, after a store that misses):"
    echo
    echo '```'
    perf annotate -i "$work/perf.data" --stdio -s _pocl_kernel_sweep_svf_workgroup 2>/dev/null |
        grep -E '^ +[0-9]+\.[0-9]+ :' | sort -rn | head -n 10 | sed 's/  *$//'
    echo '```'
else
    echo "(perf is not available or not permitted here: no profile.)"
fi
