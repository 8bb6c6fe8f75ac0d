#!/bin/bash
# UMEP's SVF (the `solweig` package from PyPI, its Rust skyview.calculate_svf
# on the CPU) and skysweep's `svf --lines box` side by side on Gothenburg's
# 1 m DSM, without and with the canopy (CDSM): issue 42's speed table.
# Whole processes (wall time from start to exit), N alternated runs a job (runner
# after runner, round after round), medians; UMEP's compute_svf() call is
# also timed alone. Each runner has one untimed warm-up run first (the PoCL
# kernel cache, Python's bytecode). The load average is printed before and
# after: on a shared machine the times are only comparable within one run.
# Then |skysweep - UMEP| over the cells: svf (band 1) without trees, svfbuveg
# (band 3, transmissivity 0.03 on both sides) with them.
# usage: doc/bench/umep_svf.sh [--reps N] [--venv DIR]
#   --reps N    alternated runs per runner and job (default 5)
#   --venv DIR  the venv for solweig, made and filled by `pip install solweig`
#               when absent (default ${XDG_CACHE_HOME:-$HOME/.cache}/skysweep-bench/solweig-venv)
# Environment: SKYSWEEP (default ./skysweep at the top of the tree), DATA (the
# folder of the Gothenburg rasters, default ../shared/data beside the tree).
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
# shellcheck source=doc/bench/lib.sh
. "$here/lib.sh" # median
usage() { sed -n 's/^# \{0,1\}//; /^usage:/,/^#\{0,1\} *when absent/p' "$0"; }
reps=5 venv=${XDG_CACHE_HOME:-$HOME/.cache}/skysweep-bench/solweig-venv
while [ $# -gt 0 ]; do
    case $1 in
    --reps) reps=${2:?--reps needs a number} && shift ;;
    --venv) venv=${2:?--venv needs a folder} && shift ;;
    -h | --help) usage && exit 0 ;;
    *) usage >&2 && exit 2 ;;
    esac
    shift
done
case $reps in '' | *[!0-9]* | 0) echo "umep_svf.sh: --reps takes a positive whole number" >&2 && exit 2 ;; esac
SKYSWEEP=${SKYSWEEP:-$top/skysweep}
DATA=${DATA:-$top/../shared/data}
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$top/tests/pocl-cache}
dsm=$DATA/goteborg_kronenhuset_dsm_1m.tif cdsm=$DATA/goteborg_kronenhuset_cdsm_1m.tif
for f in "$SKYSWEEP" "$dsm" "$cdsm"; do
    [ -r "$f" ] || { echo "umep_svf.sh: $f is missing" >&2 && exit 3; }
done
py=$venv/bin/python
if ! "$py" -c 'import solweig' 2>/dev/null; then
    echo "making $venv with solweig (pip install solweig)" >&2
    python3 -m venv "$venv" && "$venv/bin/pip" install -q solweig >&2
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-umep.XXXXXX")
trap 'rm -rf "$work"' EXIT

# solweig finds a GPU adapter where there is none (a software one): force its CPU paths.
export SOLWEIG_NO_GPU=1

# run_one JOB RUNNER OUT: one run of RUNNER on JOB's inputs, output to OUT.
run_one() {
    local job=$1 runner=$2 out=$3 trees=()
    [ "$job" = plain ] || trees=(--canopy "$cdsm")
    case $runner in
    ss-default) "$SKYSWEEP" svf -q --lines box "${trees[@]}" "$dsm" "$out" ;;
    ss-reference) "$SKYSWEEP" svf -q --lines box --device reference "${trees[@]}" "$dsm" "$out" ;;
    ss-opencl) "$SKYSWEEP" svf -q --lines box --device 0:0 "${trees[@]}" "$dsm" "$out" ;;
    ss-horizontal) "$SKYSWEEP" svf -q --lines box --definition horizontal "${trees[@]}" "$dsm" "$out" ;;
    umep) "$py" "$here/umep_svf.py" svf "$dsm" "$out" "${trees[@]}" ;;
    esac
}

jobs="plain trees" runners="ss-default ss-reference umep"
# The first OpenCL device too, named: the planner may pick the C twin by default.
if "$SKYSWEEP" info 2>/dev/null | grep -q '^0:0 '; then runners="ss-default ss-reference ss-opencl umep"; fi
echo "load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
for job in $jobs; do
    for runner in $runners ss-horizontal; do
        run_one "$job" "$runner" "$work/$job.$runner.tif" >"$work/$job.$runner.warm" 2>&1 ||
            { echo "umep_svf.sh: $runner on $job failed:" >&2 && cat "$work/$job.$runner.warm" >&2 && exit 5; }
    done
done
for ((i = 1; i <= reps; i++)); do
    for job in $jobs; do
        for runner in $runners; do
            start=$(date +%s%N)
            run_one "$job" "$runner" "$work/$job.$runner.tif" >"$work/log" 2>&1 ||
                { echo "umep_svf.sh: $runner on $job failed:" >&2 && cat "$work/log" >&2 && exit 5; }
            echo "$start $(date +%s%N)" | awk '{print ($2 - $1) / 1e9}' >>"$work/$job.$runner.wall"
            awk '/^svf_seconds/ {print $2}' "$work/log" >>"$work/$job.$runner.call"
        done
    done
done
echo "load average after:  $(cut -d' ' -f1-3 /proc/loadavg)"
echo "$(nproc) cores; $reps alternated runs; skysweep: $("$SKYSWEEP" --version 2>/dev/null | head -1); solweig $("$py" -c 'import importlib.metadata as m; print(m.version("solweig"))')"
echo
# The ratio: UMEP's whole process over the fastest skysweep's; agreement: the
# default (geometric) SVF, then --definition horizontal, UMEP's weighting.
ocl=0
case $runners in *ss-opencl*) ocl=1 ;; esac
echo "| job | skysweep default s | skysweep reference s | skysweep OpenCL s | UMEP s (whole; compute_svf alone) | UMEP / fastest skysweep (whole; compute_svf alone) | mean, p95 \|skysweep − UMEP\|: default (geometric); --definition horizontal |"
echo "|---|---|---|---|---|---|---|"
for job in $jobs; do
    d=$(median <"$work/$job.ss-default.wall")
    r=$(median <"$work/$job.ss-reference.wall")
    o=-
    [ "$ocl" = 0 ] || o=$(median <"$work/$job.ss-opencl.wall")
    u=$(median <"$work/$job.umep.wall")
    c=$(median <"$work/$job.umep.call")
    band=1 name="svf, no trees"
    [ "$job" = plain ] || band=3 name="svfbuveg, with the canopy"
    g=$("$py" "$here/umep_svf.py" compare "$work/$job.ss-default.tif" $band "$work/$job.umep.tif" $band | cut -d' ' -f1-2)
    h=$("$py" "$here/umep_svf.py" compare "$work/$job.ss-horizontal.tif" $band "$work/$job.umep.tif" $band | cut -d' ' -f1-2)
    awk -v n="$name" -v d="$d" -v r="$r" -v o="$o" -v u="$u" -v c="$c" -v g="$g" -v h="$h" 'BEGIN {
        f = d < r ? d : r; if (o != "-" && o < f) f = o
        split(g, G, " "); split(h, H, " ")
        printf "| %s | %.2f | %.2f | %s | %.2f; %.2f | %.2f×; %.2f× | %s, %s; %s, %s |\n",
            n, d, r, o == "-" ? "-" : sprintf("%.2f", o), u, c, u / f, c / f, G[1], G[2], H[1], H[2] }'
done
echo
echo "Every run's wall time (s), in order:"
for job in $jobs; do
    for runner in $runners; do echo "  $job $runner: $(tr '\n' ' ' <"$work/$job.$runner.wall")"; done
    echo "  $job umep compute_svf alone: $(tr '\n' ' ' <"$work/$job.umep.call")"
done
echo
echo "With the canopy, the other bands (mean, p95 |skysweep − UMEP|, geometric; horizontal):"
for band in 1 2; do
    echo "  band $band ($([ $band = 1 ] && echo svf || echo "svfveg against svf_veg")): $("$py" "$here/umep_svf.py" compare "$work/trees.ss-default.tif" $band "$work/trees.umep.tif" $band | cut -d' ' -f1-2); $("$py" "$here/umep_svf.py" compare "$work/trees.ss-horizontal.tif" $band "$work/trees.umep.tif" $band | cut -d' ' -f1-2)"
done
[ "$ocl" = 0 ] || echo "skysweep's OpenCL against its C twin, band 1 (mean, p95, max |Δ|): $("$py" "$here/umep_svf.py" compare "$work/plain.ss-opencl.tif" 1 "$work/plain.ss-reference.tif" 1 | cut -d' ' -f1-3)"
if [ -n "${KEEP:-}" ]; then mkdir -p "$KEEP" && cp "$work"/*.tif "$KEEP"/; fi
