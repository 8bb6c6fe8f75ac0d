# Comparing two rasters in the shell tests (sourced): through
# tests/raster_worst, which make check names in RASTER_WORST.
RASTER_WORST=${RASTER_WORST:-${TOP_SRCDIR:-.}/tests/raster_worst}

# worst_of A B [BAND...]: the largest |a - b| over the bands (all of them
# without BAND) where both hold data; or, where there is no such number,
# why: "nodata differs at N cells", or "no comparison (...)" when the
# files cannot be compared (raster_worst's reason goes to stderr).
worst_of() {
    local out worst mismatched
    if ! out=$("$RASTER_WORST" "$@"); then
        echo "no comparison (raster_worst failed, its message is in the log)"
        return
    fi
    read -r worst mismatched <<<"$out"
    if [ "$mismatched" -ne 0 ]; then echo "nodata differs at $mismatched cells"; else echo "$worst"; fi
}

# worst_within WORST TOLERANCE [WORST TOLERANCE...]: whether every WORST is
# a number (as worst_of prints one) no larger than its TOLERANCE.
worst_within() {
    [ $# -ge 2 ] && [ $(($# % 2)) -eq 0 ] || return 1
    while [ $# -ge 2 ]; do
        case $1 in [0-9]*) ;; *) return 1 ;; esac
        case $1 in *[!0-9.e+-]*) return 1 ;; esac
        awk -v w="$1" -v t="$2" 'BEGIN { exit !(w + 0 <= t + 0) }' || return 1
        shift 2
    done
}
