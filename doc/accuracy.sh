#!/usr/bin/env bash
# What accuracy costs in time: runs doc/accuracy_driver (built by `make
# accuracy`) on the analytic shapes and the real DEMs of ../shared/data,
# collects its CSV rows, and has doc/accuracy_plot.py write doc/accuracy.md,
# the plots in doc/img/ and the table behind the default number of
# directions (src/core/accuracy_table.c). Every number in those files comes
# from this run.
set -euo pipefail

usage() {
    cat <<'EOF'
usage: doc/accuracy.sh [--quick] [--out DIR] [--data DIR]
  --quick   CI mode (< 1 minute): small crops, few cells and directions; the
            report goes to a temporary folder (or --out), doc/ and src/ are
            left alone
  --out     folder for accuracy.md, accuracy.csv and img/ (default doc/)
  --data    the shared DEMs (default ../shared/data, or $SS_SHARED_DATA)
Environment: DRIVER (default ./doc/accuracy_driver), PYTHON (default
/usr/bin/python3, with matplotlib: apt-get install python3-matplotlib).
EOF
}

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
top=$(dirname "$here")
quick=0 out="" data=${SS_SHARED_DATA:-$top/../shared/data}
while [ $# -gt 0 ]; do
    case $1 in
    --quick) quick=1 ;;
    --out) out=${2:?--out needs a folder} && shift ;;
    --data) data=${2:?--data needs a folder} && shift ;;
    -h | --help) usage && exit 0 ;;
    *) usage >&2 && exit 2 ;;
    esac
    shift
done
command_line="doc/accuracy.sh$([ $quick = 1 ] && echo ' --quick' || true)"
driver=${DRIVER:-$PWD/doc/accuracy_driver}
[ -x "$driver" ] || driver=$top/doc/accuracy_driver
[ -x "$driver" ] || { echo "accuracy.sh: no driver: run 'make accuracy'" >&2 && exit 2; }
python=${PYTHON:-/usr/bin/python3}
if [ -z "$out" ]; then
    if [ $quick = 1 ]; then
        out=$(mktemp -d "${TMPDIR:-/tmp}/ss-accuracy.XXXXXX")
        trap 'rm -rf "$out"' EXIT
    else
        out=$top/doc
    fi
fi
mkdir -p "$out/img"
csv=$out/accuracy.csv
log=$out/accuracy.log
# A kernel cache of its own, so that builds are not timed (the driver also
# warms up before timing).
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$top/tests/pocl-cache}
started=$(date +%s)

# ---- settings ---------------------------------------------------------------------
if [ $quick = 1 ]; then
    shape_size=96 shape_cells=30 crop=128x128 full_crop=128x128 cells=30 ref_az=720
    dirs=8,32 digital_dirs=32 cost_dirs=8 reps=1 cost_reps=1
    insol_crop=60x60 steps=60,30 ref_step=15 interp_dirs=16 insol_dirs=8
    effects_crop=100x100 effects_dirs=8
else
    # The direction study sweeps the 256 x 256 centre of each DEM and
    # 128 x 128 shapes (errors and times per cell need no more, and 2 cores
    # then finish in minutes); the cost study times the whole DEMs.
    shape_size=128 shape_cells=100 crop=256x256 full_crop=0x0 cells=300 ref_az=3600
    dirs=4,8,16,32,64,128,256,360 digital_dirs=8,32,128 cost_dirs=32 reps=2 cost_reps=3
    insol_crop=400x300 steps=60,30,15,5 ref_step=1 interp_dirs=16,32,64,128,360 insol_dirs=32
    effects_crop=0x0 effects_dirs=32
fi

# scene:class:file:utc offset (h) of local time
dems="kilauea:gentle volcano:hawaii_kilauea_utm5n_30m.tif:-10
bigtujunga:steep canyons:bigtujunga_srtm30m_utm11n.tif:-8
oetztal:alpine:alps_oetztal_srtm3_geo.tif:1
goteborg:urban DSM:goteborg_kronenhuset_dsm_1m.tif:1"
shapes="plane30 vvalley bowl"

echo "study,scene,class,setting,value,quantity,mean,p95,max,seconds,cells" >"$csv"
: >"$log"
drive() { # runs the driver, appending its rows to the CSV and its notes to the log
    echo "+ accuracy_driver $*" >>"$log"
    nice "$driver" "$@" >>"$csv" 2>>"$log"
}

device=$("$driver" machine 2>>"$log")
cpu=$(awk -F': ' '/^model name/ {print $2; exit}' /proc/cpuinfo 2>/dev/null || echo unknown)
cores=$(nproc 2>/dev/null || echo "?")
load_before=$(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo "?")

for s in $shapes; do
    drive directions --scene "$s" --class analytic --shape "$s" --crop "${shape_size}x$shape_size" \
        --cells "$shape_cells" --ref-az "$ref_az" --dirs "$dirs" --digital-dirs "$digital_dirs" \
        --reps "$reps"
done
while IFS=: read -r scene class file utc; do
    dem=$data/$file
    if [ ! -r "$dem" ]; then
        echo "skipped $scene: $dem is absent" >>"$log"
        continue
    fi
    drive directions --scene "$scene" --class "$class" --dem "$dem" --crop "$crop" \
        --cells "$cells" --ref-az "$ref_az" --dirs "$dirs" --digital-dirs "$digital_dirs" \
        --reps "$reps"
    drive cost --scene "$scene" --class "$class" --dem "$dem" --crop "$full_crop" \
        --dirs "$cost_dirs" --reps "$cost_reps"
    case $scene in
    bigtujunga)
        drive insolation --scene "$scene" --class "$class" --dem "$dem" --crop "$insol_crop" \
            --utc-offset "$utc" --date 2026-12-21 --steps "$steps" --ref-step "$ref_step" \
            --interp-dirs "$interp_dirs" --insol-dirs "$insol_dirs"
        ;;
    esac
    case $scene in
    bigtujunga | oetztal | goteborg)
        drive effects --scene "$scene" --class "$class" --dem "$dem" --crop "$effects_crop" \
            --utc-offset "$utc" --date 2026-12-21 --dirs "$effects_dirs"
        ;;
    esac
done <<<"$dems"

elapsed=$(($(date +%s) - started))
load_after=$(cut -d' ' -f1-3 /proc/loadavg 2>/dev/null || echo "?")
table_args=()
[ $quick = 1 ] || table_args=(--table "$top/src/core/accuracy_table.c")
"$python" "$here/accuracy_plot.py" --csv "$csv" --md "$out/accuracy.md" --img "$out/img" \
    --command "$command_line" --device "$device" --cpu "$cpu ($cores cores)" \
    --load "$load_before -> $load_after" --elapsed "$elapsed" \
    --timing "the fastest of $reps run(s) ($cost_reps for the whole DEMs)" "${table_args[@]}"
echo "accuracy: $(($(wc -l <"$csv") - 1)) rows in ${elapsed} s -> $out/accuracy.md"
