#!/usr/bin/env bash
# Side-by-side benchmark of skysweep against the peer tools that install on
# Debian 12: GRASS r.horizon and r.sun, SAGA "Sky View Factor", WhiteboxTools,
# RVT, topocalc and gdaldem. On the Kilauea sample and on synthetic DEMs it
# times skysweep and each peer (median wall time and peak RSS of --reps runs,
# /usr/bin/time -v) and compares every peer's output with skysweep's.
# What each peer computes, and why the numbers differ: doc/bench/README.md.
set -euo pipefail

usage() {
    cat <<'EOF'
usage: doc/performance.sh [--tiny] [--sizes "512 1024 ..."] [--reps N] [--out FILE]
                          [--dems "FILE ..."] [--timeout S] [--slow S]
                          [--rvt-radius CELLS] [--workdir DIR] [--remark TEXT]
                          [--report-only]
  --tiny        CI mode: one 128 x 128 synthetic DEM, 16 directions only, one
                run each, nothing installed, absent peers skipped, no report
                file (< 60 s)
  --sizes       synthetic DEM sizes (default "512 1024 2048 4096", and 8192
                where the machine has 64 GiB of memory or more)
  --reps        runs per measurement; the median is reported (default 3)
  --out         Markdown report (default doc/performance.md)
  --dems        real DEMs to run as well (default the Kilauea sample)
  --timeout     seconds before a run is abandoned (default 1800); a tool that
                times out is not run again on larger DEMs, nor on a larger DEM
                or more directions where its last time, scaled up, already
                exceeds the timeout (skysweep is always run)
  --slow        a run longer than this many seconds is not repeated (default 600)
  --rvt-radius  RVT's search radius in cells (default 100; RVT is pure Python
                and its time grows with the radius)
  --workdir     scratch directory, kept (default: a temporary one, removed)
  --report-only with --workdir DIR of an earlier run: write the report from
                its tables again, measuring nothing
  --remark      a sentence for the report's machine section (e.g. that other
                work shared the machine during the run)
As root and not --tiny, missing peers are installed (apt-get, and pip into
$PEERS_VENV). Environment: SKYSWEEP (the binary; default ./skysweep),
PEERS_VENV (default /opt/peers-venv), SKYSWEEP_HILLSHADE_ARGS (default
"--az 315 --alt 45", gdaldem's settings here) and SKYSWEEP_INSOLATION_ARGS
(default: 21 June 2026 = r.sun's day 172, the DEM's local day in whole hours
from its centre longitude, --step PT15M --linke 3 --albedo 0.2 --curvature on
--refraction 0, r.sun's settings here).
EOF
}

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
top=$(dirname "$here")
bench=$here/bench
# shellcheck source=doc/bench/lib.sh
. "$bench/lib.sh"
command_line="$(printf '%q ' "$0" "$@")"

# ---- options -------------------------------------------------------------------
tiny=0 reps=3 sizes=default out=$top/doc/performance.md timeout_s=1800 slow_s=600
dems=$top/samples/kilauea_summit_30m.tif rvt_radius=100 workdir="" remark="" report_only=0
while [ $# -gt 0 ]; do
    case $1 in
    --tiny) tiny=1 ;;
    --sizes) sizes=${2-} && shift ;;
    --reps) reps=${2:?--reps needs a value} && shift ;;
    --out) out=${2:?--out needs a value} && shift ;;
    --dems) dems=${2-} && shift ;;
    --timeout) timeout_s=${2:?--timeout needs a value} && shift ;;
    --slow) slow_s=${2:?--slow needs a value} && shift ;;
    --rvt-radius) rvt_radius=${2:?--rvt-radius needs a value} && shift ;;
    --workdir) workdir=${2:?--workdir needs a value} && shift ;;
    --remark) remark=${2-} && shift ;;
    --report-only) report_only=1 ;;
    -h | --help) usage && exit 0 ;;
    *) usage >&2 && exit 2 ;;
    esac
    shift
done
horizon_dirs="16 64"
svf_dirs="16 32"
if [ "$tiny" = 1 ]; then
    sizes=128 reps=1 dems="" horizon_dirs=16 svf_dirs=16
elif [ "$sizes" = default ]; then
    sizes="512 1024 2048 4096"
    mem_gib=$(awk '/^MemTotal:/ {print int($2 / 1048576)}' /proc/meminfo)
    [ "$mem_gib" -ge 63 ] && sizes="$sizes 8192"
fi
export REPS=$reps TIMEOUT=$timeout_s SLOW=$slow_s

py=/usr/bin/python3 # Debian's, for python3-gdal and numpy
peers_venv=${PEERS_VENV:-/opt/peers-venv}
vpy=$peers_venv/bin/python
skysweep=${SKYSWEEP:-$PWD/skysweep}
[ -x "$skysweep" ] || skysweep=$top/skysweep
skysweep=$(realpath "$skysweep")

if [ -n "$workdir" ]; then
    mkdir -p "$workdir"
    work=$(realpath "$workdir")
else
    work=$(mktemp -d "${TMPDIR:-/tmp}/skysweep-bench.XXXXXX")
    trap 'rm -rf "$work"' EXIT
fi
# A kernel cache of our own, empty at the start: the first run of each
# setting builds the kernels (reported as the cold run), later ones reuse it.
export POCL_CACHE_DIR=$work/pocl-cache
mkdir -p "$POCL_CACHE_DIR" "$work/dems"
if [ "$report_only" = 1 ]; then
    [ -s "$work/times.tsv" ] || { log "performance.sh: no $work/times.tsv to report" && exit 2; }
else
    : >"$work/times.tsv"
    : >"$work/agreement.tsv"
    : >"$work/notes.md"
    : >"$work/loads.txt"
fi

log() { printf '%s\n' "$*" >&2; }
note() {
    log "note: $*"
    printf -- '- %s\n' "$*" >>"$work/notes.md"
}

# ---- peers: what is there, and installing the rest ----------------------------
have() { # have PEER: is PEER installed?
    case $1 in
    grass) command -v grass ;;
    saga) command -v saga_cmd ;;
    gdaldem) command -v gdaldem ;;
    wbw) "$vpy" -c 'import whitebox_workflows' ;;
    rvt) "$vpy" -c 'import rvt.vis' ;;
    topocalc) "$vpy" -c 'import topocalc.viewf' ;;
    esac >/dev/null 2>&1
}

ours_has() { # ours_has COMMAND: does this skysweep have COMMAND?
    "$skysweep" "$1" --help >/dev/null 2>&1
}

install_topocalc() {
    local src=$work/topocalc-src
    mkdir -p "$src"
    "$vpy" -m pip download -q --no-deps --no-binary :all: -d "$src" topocalc &&
        tar -xzf "$src"/topocalc-*.tar.gz -C "$src" &&
        # The pre-generated topo_core.c does not build on Python 3.11;
        # without it, Cython regenerates it from topo_core.pyx.
        rm -f "$src"/topocalc-*/topocalc/core_c/topo_core.c &&
        "$vpy" -m pip install -q --no-build-isolation "$src"/topocalc-*/
}

install_peers() {
    local pkg missing=()
    for pkg in grass-core saga gdal-bin python3-gdal python3-numpy python3-venv \
        python3-scipy cython3 time; do
        dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' ||
            missing+=("$pkg")
    done
    if [ ${#missing[@]} -gt 0 ]; then
        log "installing ${missing[*]} with apt-get"
        { apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}"; } \
            >"$work/apt.log" 2>&1 ||
            note "apt-get install ${missing[*]} failed: $(tail -n 1 "$work/apt.log")"
    fi
    # One venv for the Python peers, on top of Debian's numpy, scipy and GDAL.
    [ -x "$vpy" ] || /usr/bin/python3 -m venv --system-site-packages "$peers_venv" ||
        note "could not create the venv $peers_venv"
    [ -x "$vpy" ] || return 0
    have wbw || "$vpy" -m pip install -q whitebox-workflows >"$work/pip-wbw.log" 2>&1 ||
        note "pip install whitebox-workflows failed: $(tail -n 1 "$work/pip-wbw.log")"
    # --no-deps: rvt-py asks for GDAL from PyPI, which would build from source.
    have rvt || "$vpy" -m pip install -q --no-deps rvt-py >"$work/pip-rvt.log" 2>&1 ||
        note "pip install rvt-py failed: $(tail -n 1 "$work/pip-rvt.log")"
    have topocalc || install_topocalc >"$work/pip-topocalc.log" 2>&1 ||
        note "installing topocalc failed: $(tail -n 1 "$work/pip-topocalc.log")"
}

if [ "$tiny" = 0 ] && [ "$report_only" = 0 ] && [ "$(id -u)" = 0 ]; then
    install_peers
fi

# Without these there is nothing to run: CI skips, a full run stops.
prerequisites_missing=""
[ -x /usr/bin/time ] || prerequisites_missing+=" /usr/bin/time (Debian: time)"
command -v gdal_translate >/dev/null || prerequisites_missing+=" gdal_translate (gdal-bin)"
"$py" -c 'import numpy; from osgeo import gdal' 2>/dev/null ||
    prerequisites_missing+=" python3-gdal/python3-numpy"
[ -x "$skysweep" ] || prerequisites_missing+=" $skysweep (build it first)"
if [ -n "$prerequisites_missing" ]; then
    log "performance.sh: missing:$prerequisites_missing"
    if [ "$tiny" = 1 ]; then
        log "performance.sh --tiny: skipped"
        exit 0
    fi
    exit 1
fi

[ "$report_only" = 1 ] || for peer in grass saga gdaldem wbw rvt topocalc; do
    have "$peer" || note "peer absent, skipped: $peer (doc/bench/README.md says how to install it)"
done

# ---- measuring -------------------------------------------------------------------
# The DEM, task and direction count being measured; a measurement fills
# STATUS, WALL (median s), RSS (median MB) and RUNS from a timed_reps folder.
dem="" dem_label="" dem_cells="" dem_cell_m="" task="" dirs="" case_dir="" last_dir=""
ours_wall=""
declare -A timed_out=() last_run=() warmed=()

collect() {
    local f files
    last_dir=$1
    STATUS=$(cat "$last_dir/status" 2>/dev/null || echo failed)
    files=$(find "$last_dir" -name 'time.*' 2>/dev/null | sort)
    RUNS=$(printf '%s' "$files" | grep -c . || true)
    WALL=$(for f in $files; do wall_seconds "$f"; done | median)
    RSS=$(for f in $files; do rss_mb "$f"; done | median)
    # skysweep's own summary: the sweep alone, and the kernel build (which a
    # warm cache makes a few hundredths of a second).
    SWEEP=$(sed -n 's/^time  *sweep \([0-9.]*\) s.*/\1/p' "$last_dir/log" 2>/dev/null | median)
    BUILD=$(sed -n 's/.*kernel build \([0-9.]*\) s.*/\1/p' "$last_dir/log" 2>/dev/null | sort -g | tail -n 1)
}

# The load average (1 min) before each measurement: the machine may be shared.
sample_load() { cut -d' ' -f1 /proc/loadavg >>"$work/loads.txt"; }

# row TOOL SETTINGS [TAG]: adds the last measurement to the timing table.
# Columns after the nine shown: cells, directions (number), skysweep's
# setting tag, its sweep time, its largest kernel build time.
row() {
    local tool=$1 settings=$2 tag=${3-} speedup="" wall=$WALL
    if [ "$STATUS" != ok ]; then
        wall=$STATUS
        if [ "$STATUS" = timeout ]; then
            timed_out["$tool|$task"]="$dem_label ($dirs directions)"
            wall="timeout (> $TIMEOUT s)"
        else
            note "$tool, $task, $dirs directions, $dem_label: $STATUS: $(tail -n 2 "$last_dir/log" 2>/dev/null | tr '\n' ' ')"
        fi
    elif [ "$tool" = skysweep ]; then
        speedup="(reference)"
    elif [ -n "$ours_wall" ]; then
        speedup=$(awk -v p="$WALL" -v o="$ours_wall" 'BEGIN {
            if (o > 0) printf "%.1f", p / o; else print "n/a (skysweep < 0.01 s)" }')
    fi
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$dem_label" "$task" "$dirs" \
        "$tool" "$settings" "$wall" "$RUNS" "$RSS" "$speedup" "$dem_cells" \
        "$([ "$dirs" = - ] && echo 1 || echo "$dirs")" "$tag" "${SWEEP-}" "${BUILD-}" >>"$work/times.tsv"
    log "  $tool ($settings): $wall s, ${RSS:-?} MB${speedup:+, speed-up $speedup}"
}

# not_run TOOL SETTINGS WHY: a row saying that TOOL was not run, and why.
not_run() {
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$dem_label" "$task" "$dirs" \
        "$1" "$2" "not run: $3" 0 "" "" "$dem_cells" "" "" "" "" >>"$work/times.tsv"
    note "$1, $task, $dirs directions, $dem_label: not run: $3"
}

# skipped TOOL SETTINGS EXPONENT: true (with a row saying why) when TOOL is not
# to be run here: it timed out before on a smaller DEM, or its last run of
# this task, scaled by cells^EXPONENT and by the number of directions,
# predicts more than the timeout. EXPONENT is what the tool's algorithm
# gives (1.5: every cell searches to the DEM's edge; 1: a fixed radius or a
# local operator), a rough guess used for this decision only.
skipped() {
    local tool=$1 settings=$2 exponent=$3 key="$1|$task" prediction
    if [ -n "${timed_out[$key]-}" ]; then
        not_run "$tool" "$settings" "timed out on ${timed_out[$key]}"
        return 0
    fi
    [ -n "${last_run[$key]-}" ] || return 1
    prediction=$(awk -v last="${last_run[$key]}" -v cells="$dem_cells" -v dirs="$dirs" \
        -v e="$exponent" 'BEGIN {
            split(last, l, " "); d = (dirs == "-") ? 1 : dirs
            printf "%.0f", l[3] * (cells / l[1]) ^ e * d / l[2] }')
    if [ "$prediction" -gt "$TIMEOUT" ]; then
        not_run "$tool" "$settings" "predicted ~$prediction s > timeout $TIMEOUT s (from ${last_run[$key]##* } s at $(awk -v c="${last_run[$key]%% *}" 'BEGIN {printf "%.2f", c / 1e6}') Mcells, cells^$exponent x directions)"
        return 0
    fi
    return 1
}

# remember TOOL: keeps the last measurement for skipped's prediction.
remember() {
    [ "$STATUS" = ok ] || return 0
    last_run["$1|$task"]="$dem_cells $([ "$dirs" = - ] && echo 1 || echo "$dirs") $WALL"
}

# ours TAG SETTINGS ARG...: times `skysweep ARG...`; sets ours_wall for the
# speed-ups of the peers after it. The first run of each setting (TAG and
# directions) is an untimed one that builds its kernels into the empty
# cache (its time is reported as "cold"); later DEMs find them built.
ours() {
    local tag=$1 settings=$2 cold=""
    shift 2
    ours_wall=""
    sample_load
    if [ -z "${warmed[$tag|$dirs]-}" ]; then
        REPS=1 timed_reps "$case_dir/$tag.cold" "$skysweep" "$@"
        collect "$case_dir/$tag.cold"
        if [ "$STATUS" != ok ]; then
            row skysweep "$settings" "$tag"
            return 0
        fi
        warmed[$tag|$dirs]=1
        cold="; cold run (kernels built) $WALL s"
    fi
    timed_reps "$case_dir/$tag" "$skysweep" "$@"
    collect "$case_dir/$tag"
    row skysweep "$settings${SWEEP:+; sweep alone ${SWEEP} s}$cold" "$tag"
    [ "$STATUS" = ok ] && ours_wall=$WALL
    return 0
}

# peer TOOL TAG SETTINGS EXPONENT CMD...: times a peer run as one command.
peer() {
    local tool=$1 tag=$2 settings=$3 exponent=$4
    shift 4
    skipped "$tool" "$settings" "$exponent" && return 1
    sample_load
    timed_reps "$case_dir/$tag" "$@"
    collect "$case_dir/$tag"
    SWEEP="" BUILD=""
    row "$tool" "$settings"
    remember "$tool"
    [ "$STATUS" = ok ]
}

# grass_peer TOOL TAG SETTINGS EXPONENT horizon|sun MODULE_OPTION...: times a
# GRASS module inside a throw-away location made from the DEM; its maps land
# in $case_dir/TAG.out.
grass_peer() {
    local tool=$1 tag=$2 settings=$3 exponent=$4
    shift 4
    skipped "$tool" "$settings" "$exponent" && return 1
    sample_load
    mkdir -p "$case_dir/$tag"
    grass --tmp-location "$dem" --exec bash "$bench/grass_peer.sh" "$1" "$dem" \
        "$case_dir/$tag" "$case_dir/$tag.out" "${@:2}" >>"$case_dir/$tag/log" 2>&1 || true
    collect "$case_dir/$tag"
    SWEEP="" BUILD=""
    row "$tool" "$settings"
    remember "$tool"
    [ "$STATUS" = ok ]
}

# agree PEER VERSUS compare.py-ARG...: adds a line to the agreement table
# (only when skysweep's own run succeeded).
agree() {
    local peer_name=$1 versus=$2 result
    shift 2
    [ -n "$ours_wall" ] || return 0
    result=$("$py" "$bench/compare.py" "$@" 2>"$case_dir/compare.err") ||
        result="comparison failed: $(tail -n 1 "$case_dir/compare.err")"
    printf '%s\t%s\t%s\t%s\t%s\t%s\n' "$dem_label" "$task" "$dirs" "$peer_name" "$versus" \
        "$result" >>"$work/agreement.tsv"
}

# ---- the tasks -------------------------------------------------------------------
# Every peer works on the grid's own axes without the earth's curvature, except
# r.horizon and r.sun (curvature, no refraction). GRASS 8.2.1's r.horizon was
# found to use grid north too (doc/bench/README.md), so skysweep runs with
# --north grid for all of them; its insolation keeps its automatic true north.
bench_horizon() {
    task=horizon dirs=$1
    local step
    step=$(awk -v n="$dirs" 'BEGIN {print 360 / n}')
    ours curv "--curvature on --refraction 0 --north grid (as r.horizon)" horizon \
        --directions "$dirs" --curvature on --refraction 0 --north grid \
        "$dem" "$case_dir/ours_curv.tif"
    if have grass && grass_peer "GRASS r.horizon" grass \
        "step=$step, maxdistance unset (unlimited), single-threaded" 1.5 \
        horizon step="$step"; then
        agree "GRASS r.horizon" "skysweep, curvature on" horizon "$case_dir/ours_curv.tif" \
            "$case_dir/grass.out" --tol 1
    fi
    rm -rf "$case_dir/grass.out"
    ours flat "--curvature off --north grid" horizon --directions "$dirs" --curvature off \
        --north grid "$dem" "$case_dir/ours.tif"
    if have wbw && peer "WhiteboxTools horizon_angle" wbw \
        "one call per azimuth, max_dist = DEM diagonal" 1.5 \
        "$vpy" "$bench/peers.py" wbw-horizon "$dem" "$dirs" "$case_dir/wbw.tif"; then
        agree "WhiteboxTools horizon_angle" "skysweep, curvature off" horizon \
            "$case_dir/ours.tif" "$case_dir/wbw.tif" --tol 1
    fi
}

bench_svf() {
    task=svf dirs=$1
    local radius_m rvt_ok=0 rvt_settings
    # SAGA and topocalc compute Dozier & Frew's slope-aware SVF: our radiative.
    ours rad "--definition radiative --curvature off --north grid" svf --directions "$dirs" \
        --definition radiative --curvature off --north grid "$dem" "$case_dir/ours_rad.tif"
    if have saga && peer "SAGA Sky View Factor" saga \
        "METHOD=0 (cell size), RADIUS=0 (whole DEM), NDIRS=$dirs" 1.5 \
        saga_cmd ta_lighting 3 -DEM "$dem" -SVF "$case_dir/saga.tif" \
        -VISIBLE "$case_dir/saga_visible.tif" -RADIUS 0 -NDIRS "$dirs" -METHOD 0; then
        agree "SAGA Sky View Factor" "skysweep radiative" field "$case_dir/ours_rad.tif" \
            "$case_dir/saga.tif" --tol 0.01
    fi
    if have topocalc && peer "topocalc viewf" topocalc "nangles=$dirs, whole DEM, single-threaded" 1 \
        "$vpy" "$bench/peers.py" topocalc-svf "$dem" "$dirs" "$case_dir/topocalc.tif"; then
        agree "topocalc viewf" "skysweep radiative" field "$case_dir/ours_rad.tif" \
            "$case_dir/topocalc.tif" --tol 0.01
    fi
    # WhiteboxTools and RVT compute Zaksek's geometric SVF: our default.
    ours geo "--definition geometric --curvature off --north grid" svf --directions "$dirs" \
        --curvature off --north grid "$dem" "$case_dir/ours_geo.tif"
    if have wbw && peer "WhiteboxTools sky_view_factor" wbw \
        "max_dist = DEM diagonal, observer_hgt_offset=0" 1.5 \
        "$vpy" "$bench/peers.py" wbw-svf "$dem" "$dirs" "$case_dir/wbw.tif"; then
        agree "WhiteboxTools sky_view_factor" "skysweep geometric" field \
            "$case_dir/ours_geo.tif" "$case_dir/wbw.tif" --tol 0.01
    fi
    rvt_settings="svf_r_max=$rvt_radius cells, single-threaded"
    if have rvt && peer "RVT sky_view_factor" rvt "$rvt_settings" 1 \
        "$vpy" "$bench/peers.py" rvt-svf "$dem" "$dirs" "$case_dir/rvt.tif" "$rvt_radius"; then
        rvt_ok=1
        agree "RVT sky_view_factor" "skysweep geometric (unlimited)" field \
            "$case_dir/ours_geo.tif" "$case_dir/rvt.tif" --tol 0.01
    fi
    # Like for like with RVT: skysweep's horizon searched only as far as
    # RVT's (svf --radius: scanned up to 20 steps, chunked hulls beyond), on
    # the DEMs RVT ran on. RVT's row is repeated (the same runs) with its
    # speed-up over this one.
    if [ "$rvt_ok" = 1 ]; then
        local rvt_status=$STATUS rvt_wall=$WALL rvt_rss=$RSS rvt_runs=$RUNS
        radius_m=$(awk -v r="$rvt_radius" -v c="$dem_cell_m" 'BEGIN {printf "%g", r * c}')
        ours georad "--definition geometric --radius $radius_m (RVT's $rvt_radius cells) --curvature off --north grid" \
            svf --directions "$dirs" --radius "$radius_m" --curvature off --north grid \
            "$dem" "$case_dir/ours_georad.tif"
        STATUS=$rvt_status WALL=$rvt_wall RSS=$rvt_rss RUNS=$rvt_runs SWEEP="" BUILD=""
        row "RVT sky_view_factor" "$rvt_settings (the runs above, against skysweep --radius)"
        # RVT pads the DEM by mirroring it, so that cells within its radius
        # of an edge see mirrored terrain; skysweep sees nothing beyond the
        # edge. Like for like: the cells at least the radius inside.
        local w=0 h=0
        [[ $dem_label =~ \(([0-9]+)\ x\ ([0-9]+)\)$ ]] && w=${BASH_REMATCH[1]} h=${BASH_REMATCH[2]}
        if [ "$w" -gt $((4 * rvt_radius)) ] && [ "$h" -gt $((4 * rvt_radius)) ]; then
            agree "RVT sky_view_factor" "skysweep geometric --radius $radius_m, cells >= $rvt_radius from the edge" \
                field "$case_dir/ours_georad.tif" "$case_dir/rvt.tif" --tol 0.01 --border "$rvt_radius"
        else
            agree "RVT sky_view_factor" "skysweep geometric --radius $radius_m (DEM too small to leave out $rvt_radius cells)" \
                field "$case_dir/ours_georad.tif" "$case_dir/rvt.tif" --tol 0.01
        fi
    fi
}

hillshade_args() { echo "${SKYSWEEP_HILLSHADE_ARGS-"--az 315 --alt 45"}"; }

# r.sun's day 172 is 21 June (2026 is not a leap year); the DEM's local day,
# in whole hours from its centre longitude, so that the day is one day.
insolation_args() {
    if [ -n "${SKYSWEEP_INSOLATION_ARGS+set}" ]; then
        echo "$SKYSWEEP_INSOLATION_ARGS"
        return
    fi
    local zone
    zone=$("$py" - "$dem" <<'EOF'
import sys
from osgeo import gdal, osr
gdal.UseExceptions()
ds = gdal.Open(sys.argv[1])
gt = ds.GetGeoTransform()
srs = osr.SpatialReference(wkt=ds.GetProjection())
geo = srs.CloneGeogCS()
for s in (srs, geo):
    s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
lon = osr.CoordinateTransformation(srs, geo).TransformPoint(
    gt[0] + gt[1] * ds.RasterXSize / 2, gt[3] + gt[5] * ds.RasterYSize / 2)[0]
h = round(lon / 15)
print(f"{'-' if h < 0 else '+'}{abs(h):02d}:00")
EOF
    ) || zone=Z
    echo "--time 2026-06-21T00:00$zone/P1D --step PT15M --linke 3 --albedo 0.2 --curvature on --refraction 0"
}

bench_hillshade() {
    task=hillshade dirs=-
    local args settings
    settings=$(hillshade_args)
    read -ra args <<<"$settings"
    ours hs "$settings" hillshade "${args[@]}" "$dem" "$case_dir/ours_hs.tif"
    # Both write gdaldem's bytes: 1 + 254 cos(incidence), 1 where the sun is
    # behind the slope, 0 = nodata; compared as they are, within 1.
    if have gdaldem && peer "gdaldem hillshade" gdaldem "-az 315 -alt 45 -compute_edges" 1 \
        gdaldem hillshade -q -compute_edges -az 315 -alt 45 "$dem" "$case_dir/gdaldem.tif"; then
        agree "gdaldem hillshade" "skysweep hillshade" field "$case_dir/ours_hs.tif" \
            "$case_dir/gdaldem.tif" --tol 1
    fi
}

bench_insolation() {
    task=insolation dirs=-
    local args settings
    settings=$(insolation_args)
    read -ra args <<<"$settings"
    ours ins "$settings" insolation "${args[@]}" "$dem" "$case_dir/ours_ins.tif"
    if have grass && grass_peer "GRASS r.sun" grass \
        "day=172, step=0.25 h, linke_value=3, albedo_value=0.2, nprocs=$(nproc), its own shadows" 1.5 \
        sun day=172 step=0.25 linke_value=3.0 albedo_value=0.2 nprocs="$(nproc)"; then
        agree "GRASS r.sun" "skysweep insolation (global)" field "$case_dir/ours_ins.tif" \
            "$case_dir/grass.out/glob_rad.tif" --tol 0.02 --relative
    fi
}

# ---- the DEMs, smallest first (a timeout then spares the larger ones) -----------
measure_all() {
    dem_list=$work/dems.tsv
    : >"$dem_list"
    add_dem() { # add_dem NAME FILE
        local width height cell
        read -r width height < <(gdalinfo "$2" | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)$/\1 \2/p')
        cell=$(gdalinfo "$2" | sed -n 's/^Pixel Size = (\([0-9.e+-]*\),.*/\1/p')
        printf '%s\t%s\t%s\t%s\n' "$((width * height))" "$1 ($width x $height)" "$2" "$cell" >>"$dem_list"
    }
    for real in $dems; do
        name=$(basename "$real" .tif)
        # Float32, uncompressed: the one form every peer reads correctly.
        gdal_translate -q -ot Float32 -co COMPRESS=NONE "$real" "$work/dems/$name.tif"
        add_dem "$name" "$work/dems/$name.tif"
    done
    for n in $sizes; do
        "$py" "$bench/make_dem.py" "$n" "$work/dems/synthetic_$n.tif"
        add_dem synthetic "$work/dems/synthetic_$n.tif"
    done
    sort -n -o "$dem_list" "$dem_list"

    ours_has hillshade || note "skysweep has no hillshade command: gdaldem hillshade not run"
    ours_has insolation || note "skysweep has no insolation command: r.sun not run"

    started=$(date +%s)
    printf '%s\n' "$command_line" >"$work/command_line"
    sample_load
    # (fd 3: the tools must not read the list from stdin)
    while IFS=$'\t' read -r dem_cells dem_label dem dem_cell_m <&3; do
        log "== $dem_label ($(date -u '+%H:%M:%S UTC'))"
        for d in $horizon_dirs; do
            case_dir=$work/case && rm -rf "$case_dir" && mkdir -p "$case_dir"
            bench_horizon "$d"
        done
        for d in $svf_dirs; do
            case_dir=$work/case && rm -rf "$case_dir" && mkdir -p "$case_dir"
            bench_svf "$d"
        done
        case_dir=$work/case && rm -rf "$case_dir" && mkdir -p "$case_dir"
        if ours_has hillshade; then bench_hillshade; fi
        if ours_has insolation; then bench_insolation; fi
    done 3<"$dem_list"
    rm -rf "$work/case"
    sample_load
    echo $(( ($(date +%s) - started + 30) / 60 )) >"$work/elapsed_min"
}
[ "$report_only" = 1 ] || measure_all
# skysweep against its own targets, the scaling plot and the profile
# (doc/bench/targets.sh; needs the build tree's ss-bench beside skysweep).
if [ "$tiny" = 0 ] && [ "$report_only" = 0 ]; then
    log "skysweep's own targets (doc/bench/targets.sh)"
    BUILD=$(dirname "$skysweep") bash "$bench/targets.sh" --plot "$top/doc/img/scaling.png" \
        >"$work/targets.md" || note "doc/bench/targets.sh failed: no target figures in this report"
fi
elapsed_min=$(cat "$work/elapsed_min" 2>/dev/null || echo "?")
[ "$report_only" = 0 ] || command_line=$(cat "$work/command_line" 2>/dev/null || echo "$command_line")

# ---- the report ------------------------------------------------------------------
version_of() { # version_of PEER: one line, or "absent"
    have "$1" || {
        echo absent
        return
    }
    case $1 in
    grass) grass --version 2>&1 | grep -m 1 -o 'GRASS GIS [0-9.]*' ;;
    saga) saga_cmd --version 2>/dev/null | grep -m 1 -o 'SAGA Version: [0-9.]*' ;;
    gdaldem) gdalinfo --version ;;
    wbw) "$vpy" -c 'import importlib.metadata as m; print("whitebox-workflows", m.version("whitebox-workflows"))' ;;
    rvt) "$vpy" -c 'import importlib.metadata as m; print("rvt-py", m.version("rvt-py"))' ;;
    topocalc) "$vpy" -c 'import importlib.metadata as m; print("topocalc", m.version("topocalc"))' ;;
    esac
}

skysweep_source() { # the skysweep build: its git commit, where it has one
    local d
    d=$(dirname "$skysweep")
    git -C "$d" rev-parse --is-inside-work-tree >/dev/null 2>&1 || return 0
    echo ", built from commit $(git -C "$d" describe --always --dirty 2>/dev/null) ($(git -C "$d" log -1 --format=%s 2>/dev/null | cut -c1-60))"
}

loads() { # min, median and max of the load samples
    sort -g "$work/loads.txt" | awk '{v[NR] = $1} END {
        if (NR) printf "%s, %s and %s", v[1], v[int((NR + 1) / 2)], v[NR] }'
}

report() {
    local gpu="" regen
    command -v nvidia-smi >/dev/null &&
        gpu=$(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | head -n 1)
    regen=$command_line
    [ -n "${SKYSWEEP-}" ] && regen="SKYSWEEP=$(printf '%q' "$SKYSWEEP") $regen"
    [ -n "${SKYSWEEP_HILLSHADE_ARGS+set}" ] && regen="SKYSWEEP_HILLSHADE_ARGS=$(printf '%q' "$SKYSWEEP_HILLSHADE_ARGS") $regen"
    [ -n "${SKYSWEEP_INSOLATION_ARGS+set}" ] && regen="SKYSWEEP_INSOLATION_ARGS=$(printf '%q' "$SKYSWEEP_INSOLATION_ARGS") $regen"
    cat <<EOF
# skysweep and peer tools, side by side

Written by \`doc/performance.sh\` on $(date -u '+%Y-%m-%d %H:%M UTC') after a run of $elapsed_min min; what the
peers compute and why their numbers differ from ours: [doc/bench/README.md](bench/README.md).

Regenerate with (from the source tree's top, as root to install missing peers):

\`\`\`
$regen
\`\`\`

Runs per measurement: $reps, the median reported; runs over $slow_s s not repeated; a run is
abandoned after $timeout_s s, and a peer is not run where its last time, scaled up to the
DEM and directions, predicts more than that (rows "not run").

## Machine

- CPU: $(lscpu | sed -n 's/^Model name: *//p' | head -n 1), $(nproc) cores available ($(lscpu | sed -n 's/^Thread(s) per core: *//p') thread(s) per core)
- memory: $(free -g | awk '/^Mem:/ {print $2}') GiB; OS: $(. /etc/os-release && echo "$PRETTY_NAME"), Linux $(uname -r)
- GPU: ${gpu:-none visible to nvidia-smi}
- load average (1 min) sampled before each measurement: min, median and max $(loads) on $(nproc) cores
${remark:+
$remark
}
skysweep's view of its devices (\`skysweep info\`):

\`\`\`
$("$skysweep" info 2>&1)
\`\`\`

## Versions

- skysweep: $("$skysweep" info 2>&1 | head -n 1)$(skysweep_source); PoCL $(dpkg-query -W -f='${Version}' pocl-opencl-icd 2>/dev/null || echo "not from Debian")
- GRASS: $(version_of grass); SAGA: $(version_of saga); gdaldem: $(version_of gdaldem)
- WhiteboxTools: $(version_of wbw); RVT: $(version_of rvt); topocalc: $(version_of topocalc)
  (venv $peers_venv: $("$vpy" --version 2>/dev/null || echo absent); numpy $("$py" -c 'import numpy; print(numpy.__version__)'))

$("$py" "$bench/summary.py" "$work/times.tsv")

## skysweep against its own targets

$(cat "$work/targets.md" 2>/dev/null || echo "(not measured in this run: doc/bench/targets.sh)")

## Wall time and memory

Speed-up: the peer's median wall time over skysweep's for the same DEM, task and
directions (the skysweep run just above it). skysweep's kernels were built by an
untimed first run of each setting (its time in "cold run", on the first DEM that
setting ran on); "sweep alone" is the sweep's time from skysweep's own summary.
GRASS times cover the module alone (not the session, import or export); the
Python peers' times include starting Python and reading/writing the GeoTIFFs, as
skysweep's include GDAL I/O (DEFLATE-compressed output: 64 horizon bands of a
4096² DEM are most of that time).

| DEM | task | directions | tool | settings | wall s (median) | runs | max RSS MB | speed-up |
|---|---|---|---|---|---|---|---|---|
$(awk -F'\t' '{printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", $1, $2, $3, $4, $5, $6, $7, $8, $9}' "$work/times.tsv")

## Agreement with skysweep

Cells within 2 of the edge left out. Δ = peer − skysweep: degrees for horizons
(both clipped at 0), SVF units for SVF, gdaldem's byte values for hillshade,
Wh/m² for the day's global insolation. Tolerance: 1° for horizons, 0.01 for
SVF, 1 for hillshade, 2 % of skysweep's value for insolation. Why they differ: [doc/bench/README.md](bench/README.md).

| DEM | task | directions | peer | compared with | mean abs Δ | max abs Δ | mean Δ | within tolerance | cells | correlation | note |
|---|---|---|---|---|---|---|---|---|---|---|---|
$(awk -F'\t' '{printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", $1, $2, $3, $4, $5, $6, $7, $8, $9, $10, $11, $12}' "$work/agreement.tsv")

## Notes

$(cat "$work/notes.md")
EOF
}

report >"$work/report.md"
cat "$work/report.md"
if [ "$tiny" = 0 ]; then
    cp "$work/report.md" "$out"
    log "written: $out"
fi
