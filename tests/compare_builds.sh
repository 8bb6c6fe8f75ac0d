#!/bin/sh
# Runs every product with two builds of skysweep on the same DEMs and
# compares the outputs: the check that a redesign kept behaviour.
# Usage: tests/compare_builds.sh OLD_SKYSWEEP NEW_SKYSWEEP [DEVICE [NEW_DEVICE]]
# DEVICE is passed to --device (default: reference, the C twin; "default" runs
# each build's default device), NEW_DEVICE to the new build's (default: the
# same). On the same device the outputs must be bit-identical (each raster
# turned into raw float32 or bytes by gdal_translate, then cmp); on another
# (an OpenCL device against the C twin's outputs) within 1e-6 of the output's
# scale (its largest magnitude: a sky view of 0.9999 and an albedo leave 1e-4
# of the reflected light's smallest values to float rounding), bytes within
# 1; so are products marked loose below, whose method changed. Prints one line per product and "N same, N differ".
set -u
old=$(realpath "$1") new=$(realpath "$2") device=${3:-reference} new_device=${4:-${3:-reference}}
top=$(cd "$(dirname "$0")/.." && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-compare.XXXXXX")
trap 'rm -rf "$work"' EXIT
dem=$top/samples/kilauea_summit_30m.tif
# Twice as many cells each way: the bands need a DEM whose whole grid takes
# more than one band does (its hulls included).
dem2=$work/kilauea_15m.tif
gdal_translate -q -outsize 200% 200% -r bilinear "$dem" "$dem2"
same=0 differ=0 loose=
# Options only the new build is given (a product whose default method
# changed, run the old way): none but where set below.
new_extra=
option_for() { [ "$1" = default ] || echo "--device $1"; }
old_option=$(option_for "$device") new_option=$(option_for "$new_device")

# within OLD.raw NEW.raw TYPE: whether two raw float32 rasters agree within
# 1e-6 of the old one's largest magnitude (nodata -9999 apart; rasters that
# were bytes: within 1); prints the worst relative difference.
within() {
    python3 - "$1" "$2" "$3" <<'PY'
import array, sys
a, b = array.array("f"), array.array("f")
a.frombytes(open(sys.argv[1], "rb").read())
b.frombytes(open(sys.argv[2], "rb").read())
byte = sys.argv[3] == "Byte"
scale = 1.0 if byte else max([abs(u) for u in a if u != -9999.0] + [1e-30])
worst = 0.0 if len(a) == len(b) else float("inf")
for u, v in zip(a, b):
    if (u == -9999.0) != (v == -9999.0):
        worst = float("inf")
    e = abs(u - v) / scale
    worst = max(worst, e if e == e else float("inf"))
print(worst)
sys.exit(0 if worst <= (1.0 if byte else 1e-6) else 1)
PY
}

# --memory bounds the whole process since issue 41 (the program, its
# libraries and the device counted), where it bounded the run's buffers
# before: a banded case gives the new build the budget with which it sweeps
# the old build's band rows at the old budget (same rows, same sums), which
# same_rows finds for the product that follows. The old budgets give whole
# 256-row strips (512 for shadow), which a range of budgets gives.
new_memory=
# swap_memory M ARGS...: ARGS, one a line, --memory's value replaced by M
# (M empty: unchanged). Arguments here hold no blanks.
swap_memory() {
    m=$1
    shift
    for a in "$@"; do echo "$a"; done |
        awk -v m="$m" 'prev == "--memory" && m != "" { print m; prev = ""; next } { print; prev = $0 }'
}
# rows_of BIN OPTION ARGS...: the band rows the run prints ("bands N rows"),
# nothing when it sweeps the grid whole, "refused" when the budget is too
# small (the process's measured size varies a little from run to run).
rows_of() {
    bin=$1 option=$2
    shift 2
    # shellcheck disable=SC2086
    out=$(cd "$work" && "$bin" "$@" $option 2>/dev/null)
    [ $? -eq 6 ] && { echo refused; return; }
    echo "$out" | sed -n 's/^bands *\([0-9]*\) rows.*/\1/p'
}
# same_rows ARGS... (with --memory): sets new_memory to a budget, in
# 1 MiB steps up from the least the new build names, that gives the old rows.
same_rows() {
    want=$(rows_of "$old" "$old_option" "$@")
    # shellcheck disable=SC2046,SC2086
    start=$(cd "$work" && "$new" $(swap_memory 1M "$@") $new_option 2>&1 >/dev/null |
        sed -n 's/.*at least --memory \([0-9]*\)M.*/\1/p')
    new_memory=
    for m in $(seq "${start:-1}" $((${start:-1} + 400))); do
        # shellcheck disable=SC2046
        got=$(rows_of "$new" "$new_option" $(swap_memory "${m}M" "$@"))
        [ "$got" = refused ] && continue
        if [ "$got" = "$want" ]; then
            # 3 MiB into the budgets that give these rows, if they still do,
            # away from the edge where the process's size could tip them.
            # shellcheck disable=SC2046
            [ "$(rows_of "$new" "$new_option" $(swap_memory "$((m + 3))M" "$@"))" = "$want" ] &&
                m=$((m + 3))
            new_memory=${m}M
            return
        fi
        # Past the rows: the process's measured size jitters by a MiB or so
        # on a busy machine, so the edge is measured once more before no
        # budget is taken to give them.
        if [ -n "$got" ] && [ "$got" -gt "$want" ] && [ -z "${edge_retried:-}" ]; then
            edge_retried=1
            for r in $((m - 1)) "$m"; do
                # shellcheck disable=SC2046
                if [ "$(rows_of "$new" "$new_option" $(swap_memory "${r}M" "$@"))" = "$want" ]; then
                    new_memory=${r}M
                    edge_retried=
                    return
                fi
            done
        fi
        # swept whole, or past the rows: no budget gives them
        { [ -z "$got" ] || [ "$got" -gt "$want" ]; } && edge_retried= && return
    done
}

# product NAME ARGS... (the last two are DEM and OUTPUT, OUTPUT relative to
# the build's folder; extra outputs are named with --distance/--cast-height).
product() {
    name=$1
    shift
    for b in old new; do
        mkdir -p "$work/$b"
        eval "bin=\$$b option=\$${b}_option"
        # shellcheck disable=SC2046
        [ "$b" = new ] && set -- $(swap_memory "$new_memory" "$@")
        extra=
        [ "$b" = new ] && extra=$new_extra
        # shellcheck disable=SC2086
        (cd "$work/$b" && "$bin" "$@" -q $option $extra >/dev/null 2>"$work/$b.err") ||
            { echo "$name: $b build failed: $(head -c 200 "$work/$b.err")"; differ=$((differ + 1)); return; }
    done
    verdict=same
    for f in "$work/old/"*.tif; do
        base=$(basename "$f")
        if [ "$device" = "$new_device" ] && [ -z "$loose" ]; then
            gdal_translate -q -of ENVI "$f" "$work/old.raw" &&
                gdal_translate -q -of ENVI "$work/new/$base" "$work/new.raw" &&
                cmp -s "$work/old.raw" "$work/new.raw" || verdict="differ ($base)"
            continue
        fi
        type=$(gdalinfo "$f" | sed -n 's/.*Type=\([A-Za-z0-9]*\).*/\1/p' | head -n1)
        gdal_translate -q -ot Float32 -of ENVI "$f" "$work/old.raw" &&
            gdal_translate -q -ot Float32 -of ENVI "$work/new/$base" "$work/new.raw" &&
            worst=$(within "$work/old.raw" "$work/new.raw" "$type") ||
            verdict="differ ($base, worst ${worst:-?})"
        [ "$verdict" = same ] && verdict="same within 1e-6 (worst $worst)"
    done
    echo "$name: $verdict"
    case $verdict in same*) same=$((same + 1)) ;; *) differ=$((differ + 1)) ;; esac
    rm -rf "$work/old" "$work/new"
}

t=2026-06-21T19:00Z
for def in geometric radiative horizontal; do
    product "svf $def" svf --directions 16 --definition "$def" "$dem" out.tif
    same_rows svf --directions 16 --definition "$def" --memory 58M "$dem2" out.tif
    product "svf $def, bands" svf --directions 16 --definition "$def" --memory 58M "$dem2" out.tif
done
# Radius-limited horizons are found by chunked hulls since before-engine, not
# by a scan: a sample that sees two equally steep horizons may take the
# other, a float rounding apart, so these are compared within 1e-6.
loose=1
product "svf --radius" svf --directions 16 --radius 1000 "$dem" out.tif
product "openness --radius" openness --directions 16 --radius 600 "$dem" out.tif
loose=
product "openness +" openness --directions 16 "$dem" out.tif
product "openness -" openness --directions 16 --kind negative "$dem" out.tif
product "horizon" horizon --directions 8 --distance d.tif --cast-height c.tif "$dem" out.tif
same_rows horizon --directions 8 --distance d.tif --cast-height c.tif --memory 60M "$dem2" out.tif
product "horizon, bands" horizon --directions 8 --distance d.tif --cast-height c.tif \
    --memory 60M "$dem2" out.tif
# Refraction is interpolated between the sun lattice's nodes since 97b95e5
# (src/adapt/sun_field.c): a cell's sun may move by a float's rounding.
loose=1
product "shadow" shadow --time "$t" "$dem" out.tif
same_rows shadow --time "$t" --memory 58M "$dem2" out.tif
product "shadow, bands" shadow --time "$t" --memory 58M "$dem2" out.tif
loose=
product "hillshade" hillshade "$dem" out.tif
product "hillshade --cast-shadows" hillshade --cast-shadows --directions 16 "$dem" out.tif
product "hillshade --blend vat" hillshade --blend vat --directions 16 "$dem" out.tif
# Insolation's sun terms are tabulated over each step's cells since 97b95e5
# (src/core/sun_table.h), and its suns' refraction interpolated as the
# shadows': within 1e-6, not bit for bit.
loose=1
product "insolation" insolation --time 2026-06-21T16:00Z/PT6H --step PT1H --directions 16 \
    "$dem" out.tif
product "insolation --shadow interpolated" insolation --time 2026-06-21T16:00Z/PT6H --step PT1H \
    --directions 16 --shadow interpolated "$dem" out.tif
same_rows insolation --time 2026-06-21T16:00Z/PT6H --step PT1H --directions 16 --memory 110M \
    "$dem2" out.tif
product "insolation, bands" insolation --time 2026-06-21T16:00Z/PT6H --step PT1H \
    --directions 16 --memory 110M "$dem2" out.tif
# Walked steps enough for the shadow walks to stop past the cells the sun
# clears by their horizon bounds (src/core/lit_levels.c, since 54a655d).
product "insolation, 5 days of exact shadows" insolation --time 2026-06-19T00:00Z/P5D \
    --step PT1H --directions 16 --shadow exact "$dem" out.tif
# The same on box lines, whose walks stop early too (since issue 42).
# Box lines' shadows and sky view are each cell's own ray since issue 42
# (doc/model.md); --box-shadows lines --box-sky lines runs the families'
# walks the old build ran.
new_extra="--box-shadows lines --box-sky lines"
product "svf, box lines" svf --directions 16 --lines box --box-lines 4 "$dem" out.tif
product "openness, box lines" openness --directions 16 --lines box --box-lines 4 "$dem" out.tif
product "insolation, 5 days of exact shadows, box lines" insolation \
    --time 2026-06-19T00:00Z/P5D --step PT1H --directions 16 --shadow exact --lines box \
    --box-lines 4 "$dem" out.tif
product "shadow, box lines" shadow --time "$t" --lines box --box-lines 4 "$dem" out.tif
product "hillshade --cast-shadows, box lines" hillshade --cast-shadows --lines box \
    --box-lines 4 "$dem" out.tif
# Box lines' horizon rasters follow --box-sky since 2026-12-07.
product "horizon, box lines" horizon --directions 8 --lines box --box-lines 4 --distance d.tif \
    --cast-height c.tif "$dem" out.tif
new_extra=
# In bands, whose walks stop early too (since issue 42 item 1).
same_rows insolation --time 2026-06-19T00:00Z/P5D --step PT1H --directions 16 --shadow exact \
    --memory 110M "$dem2" out.tif
product "insolation, 5 days of exact shadows, bands" insolation --time 2026-06-19T00:00Z/P5D \
    --step PT1H --directions 16 --shadow exact --memory 110M "$dem2" out.tif
loose=
echo "$same same, $differ differ"
[ "$differ" -eq 0 ]
