#!/bin/bash
# Issue 17's table: skysweep against one peer per job, in the same run, with
# the issue's targets. Whole processes (/usr/bin/time, lib.sh's timed_reps),
# medians of --reps runs, a run over 20 s not repeated; skysweep with its
# default device and -q after one untimed warm-up run per job. The GRASS
# modules are timed alone inside a session (grass_peer.sh), not the session's
# start or the import. Peers: doc/bench/README.md.
# usage: doc/bench/issue17_table.sh [--reps N] [--quick] [--install]
#   --reps N   runs per measurement (default 5)
#   --quick    one run each, no year rows (a smoke test)
#   --install  as root: install the missing peers (apt-get, pip into PEERS_VENV)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
# shellcheck source=doc/bench/lib.sh
. "$here/lib.sh"
usage() { sed -n 's/^# \{0,1\}//; /^usage:/,/^  --install/p' "$0"; }
reps=5 quick=0 install=0
while [ $# -gt 0 ]; do
    case $1 in
    --reps) reps=${2:?--reps needs a number} && shift ;;
    --quick) quick=1 ;;
    --install) install=1 ;;
    -h | --help) usage && exit 0 ;;
    *) usage >&2 && exit 2 ;;
    esac
    shift
done
[ "$quick" = 0 ] || reps=1
export REPS=$reps TIMEOUT=${TIMEOUT:-3600} SLOW=20
SKYSWEEP=${SKYSWEEP:-$top/skysweep}
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$top/tests/pocl-cache}
peers_venv=${PEERS_VENV:-/opt/peers-venv}
vpy=$peers_venv/bin/python
sample=$top/samples/kilauea_summit_30m.tif
K=$top/../shared/data/hawaii_kilauea_utm5n_30m.tif
kname="Kīlauea 857 × 793" knote="\"Kīlauea\" is $(realpath "$K" 2>/dev/null || echo "$K")."
if [ ! -r "$K" ]; then
    knote="$K is absent: its rows use the sample instead." K=$sample kname="Kīlauea sample 512 × 643"
fi
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-issue17.XXXXXX")
trap 'rm -rf "$work"' EXIT
log() { printf '%s\n' "$*" >&2; }

have() { # have PEER: is PEER installed?
    case $1 in
    grass) command -v grass ;;
    gdal) command -v gdaldem && command -v gdalinfo ;;
    rvt) "$vpy" -c 'import rvt.vis' ;;
    topocalc) "$vpy" -c 'import topocalc.viewf' ;;
    esac >/dev/null 2>&1
}

install_peers() { # as doc/performance.sh does; a failure leaves the peer absent
    local pkg missing=() src=$work/topocalc-src
    for pkg in grass-core gdal-bin python3-gdal python3-numpy python3-venv python3-scipy cython3 time; do
        dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed' || missing+=("$pkg")
    done
    if [ ${#missing[@]} -gt 0 ]; then
        log "installing ${missing[*]} with apt-get"
        { apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q "${missing[@]}"; } ||
            log "apt-get install failed"
    fi
    [ -x "$vpy" ] || /usr/bin/python3 -m venv --system-site-packages "$peers_venv" || return 0
    # --no-deps: rvt-py asks for GDAL from PyPI, which would build from source.
    have rvt || "$vpy" -m pip install -q --no-deps rvt-py || log "pip install rvt-py failed"
    # topocalc: an sdist whose pre-generated C does not build on Python 3.11;
    # without it, Cython regenerates it from the .pyx.
    have topocalc || { mkdir -p "$src" &&
        "$vpy" -m pip download -q --no-deps --no-binary :all: -d "$src" topocalc &&
        tar -xzf "$src"/topocalc-*.tar.gz -C "$src" &&
        rm -f "$src"/topocalc-*/topocalc/core_c/topo_core.c &&
        "$vpy" -m pip install -q --no-build-isolation "$src"/topocalc-*/; } || log "installing topocalc failed"
}
if [ "$install" = 1 ]; then
    if [ "$(id -u)" = 0 ]; then install_peers >&2; else log "--install needs root: nothing installed"; fi
fi
[ -x /usr/bin/time ] || { log "issue17_table.sh: needs /usr/bin/time (Debian: time)" && exit 1; }
[ -x "$SKYSWEEP" ] || { log "issue17_table.sh: no $SKYSWEEP (build first)" && exit 1; }

# timed DIR CMD...: the median wall time of CMD in s, or why there is none.
timed() { timed_reps "$work/$1" "${@:2}" && measured "$work/$1"; }
measured() { # measured DIR: a timed_reps folder's median, or its status
    local f status
    status=$(cat "$1/status" 2>/dev/null || echo failed)
    [ "$status" = ok ] || { echo "$status" && return; }
    for f in "$1"/time.*; do wall_seconds "$f"; done | median
}
# A build tree's ./skysweep is libtool's wrapper script, a shell that runs
# sed before it starts the program: time the program itself, as installed.
ours_cmd=("$SKYSWEEP")
built=$(dirname "$SKYSWEEP")/.libs
if head -c 2048 "$SKYSWEEP" | grep -q 'temporary wrapper script' && [ -x "$built/skysweep" ]; then
    ours_cmd=(env "LD_LIBRARY_PATH=$built${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$built/skysweep")
fi
ours() { # ours DIR ARG...: skysweep ARG... -q after a warm-up run
    local dir=$1
    shift
    "${ours_cmd[@]}" "$@" -q >/dev/null 2>&1 || true
    timed "$dir" "${ours_cmd[@]}" "$@" -q
}
grass_time() { # grass_time DIR DEM horizon|sun OPTION...: the module alone
    local dir=$work/$1 dem=$2
    shift 2
    mkdir -p "$dir"
    grass --tmp-location "$dem" --exec bash "$here/grass_peer.sh" "$1" "$dem" "$dir" "$dir.out" \
        "${@:2}" >>"$dir/log" 2>&1 || true
    rm -rf "$dir.out"
    measured "$dir"
}

# row JOB OURS PEER PEER_TIME MIN_RATIO MAX_OURS: a table row; an empty
# target is not asked for. The target column says whether it was met.
row() {
    awk -v job="$1" -v s="$2" -v peer="$3" -v p="$4" -v rmin="$5" -v smax="$6" 'BEGIN {
        num = "^[0-9]+([.][0-9]*)?$"; r = "n/a"; goal = ""; ok = 1; known = 1
        if (s ~ num && p ~ num && s > 0) r = sprintf("%.1f", p / s)
        if (rmin != "") { goal = "ratio >= " rmin; if (r == "n/a") known = 0; else ok = ok && p / s >= rmin }
        if (smax != "") { goal = goal (goal == "" ? "" : " and ") "skysweep <= " smax " s"
            if (s !~ num) known = 0; else ok = ok && s + 0 <= smax }
        printf "| %s | %s | %s | %s | %s | %s: %s |\n", job, s (s ~ num ? " s" : ""), peer,
            p (p ~ num ? " s" : ""), r, goal, known ? (ok ? "met" : "**not met**") : "unknown"
    }'
}
absent="peer not installed"

echo "Measured by \`doc/bench/issue17_table.sh\` on $(date -u '+%Y-%m-%d %H:%M UTC'): $(nproc) cores of" \
    "$(lscpu | sed -n 's/^Model name: *//p' | head -n 1); load average $(cut -d' ' -f1-3 /proc/loadavg);" \
    "skysweep commit $(git -C "$top" rev-parse --short HEAD 2>/dev/null || echo unknown); median of $reps run(s)" \
    "per measurement (runs over $SLOW s once). $knote"
echo
echo "| job | skysweep | peer | peer time | ratio (peer / skysweep) | target |"
echo "|---|---|---|---|---|---|"

s=$(ours svf svf --directions 16 "$K" "$work/o.tif")
p=$absent
if have topocalc; then p=$(timed topocalc "$vpy" "$here/peers.py" topocalc-svf "$K" 16 "$work/p.tif"); fi
row "\`svf --directions 16\`, $kname" "$s" "topocalc \`viewf\`, 16 angles" "$p" 40 0.15

s=$(ours horizon horizon --directions 16 "$K" "$work/o.tif")
p=$absent
if have grass; then p=$(grass_time rhorizon "$K" horizon step=22.5); fi
row "\`horizon --directions 16\`, $kname" "$s" "GRASS \`r.horizon\`, step=22.5" "$p" 100 ""

gdal_translate -q -srcwin 0 0 64 64 "$sample" "$work/d64.tif"
s=$(ours svf64 svf --directions 16 "$work/d64.tif" "$work/o.tif")
p=$absent
if have gdal; then p=$(timed gdalinfo gdalinfo "$work/d64.tif"); fi
row "\`svf --directions 16\`, 64 × 64 crop of the sample" "$s" "\`gdalinfo\` of the same file" "$p" "" 0.07

s=$(ours hillshade hillshade "$K" "$work/o.tif")
p=$absent
if have gdal; then p=$(timed gdaldem gdaldem hillshade -q -compute_edges "$K" "$work/p.tif"); fi
row "\`hillshade\`, $kname" "$s" "\`gdaldem hillshade -compute_edges\`" "$p" 1 ""

s=$(ours svfr svf --radius 3000 --directions 16 "$sample" "$work/o.tif")
p=$absent
if have rvt; then p=$(timed rvt "$vpy" "$here/peers.py" rvt-svf "$sample" 16 "$work/p.tif" 100); fi
row "\`svf --radius 3000 --directions 16\`, sample 512 × 643" "$s" \
    "RVT \`sky_view_factor\`, svf_r_max=100 cells, 16 directions" "$p" 2 ""

sun="linke_value=3.0 albedo_value=0.2 nprocs=$(nproc)"
s=$(ours day insolation --time 2026-06-21T00:00-10:00/P1D --step PT30M "$K" "$work/o.tif")
p=$absent
# shellcheck disable=SC2086 # $sun: several options
if have grass; then p=$(grass_time rsun "$K" sun day=172 step=0.5 $sun); fi
row "\`insolation\`, one day, 30-min steps, $kname" "$s" "GRASS \`r.sun\`, day=172, step=0.5 h, $sun" "$p" 30 ""

if [ "$quick" = 0 ]; then
    p=$absent year=""
    # shellcheck disable=SC2086
    if have grass; then p=$(grass_time rsunday "$sample" sun day=172 step=1.0 $sun); fi
    if [[ $p =~ ^[0-9.]+$ ]]; then
        year=$(awk -v d="$p" 'BEGIN {printf "%.0f", 365 * d}')
        desc="GRASS \`r.sun\`, not run: estimated 365 × its one day (day=172, step=1 h: $p s)"
    else
        desc="GRASS \`r.sun\` (one day: $p)" year=$p
    fi
    for shadow in exact interpolated; do
        s=$(ours "year-$shadow" insolation --time 2026-01-01T00:00-10:00/P1Y --step PT1H \
            --shadow "$shadow" "$sample" "$work/o.tif")
        max=10
        [ "$shadow" = interpolated ] || max=30
        row "\`insolation --shadow $shadow\`, a year hourly, sample 512 × 643" "$s" "$desc" "$year" "" "$max"
    done
fi
