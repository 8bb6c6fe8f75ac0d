#!/bin/bash
# shadow --canopy (doc/vegetation.md) from the command line: a canopy of
# zeros leaves bands 1-3 byte for byte as without one and adds classes 0/1;
# a tree adds vegetation shadow (class 2) whose fraction is the
# transmissivity (0 and 1 checked); absolute heights give the classes of
# the same trees above ground; a canopy on a finer grid is warped onto the
# DSM's; the metadata name canopy, trunk rule and transmissivity; bad
# canopies, trunks, transmissivities, grids and a canopy that is also the
# output are refused in one line with the documented exit code. svf
# --canopy: a canopy of zeros leaves band 1 byte for byte, svfveg 1 and
# svfbuveg = svf; a tree gives svfbuveg = svf - (1 - svfveg)(1 - T) at T
# 0, 0.03 and 1; the metadata; the DSM in bands; its refusals. hillshade
# --canopy --cast-shadows: a canopy of zeros or of transmissivity 1 leaves
# the shade byte for byte; cells in vegetation shadow (shadow's class 2 for
# the same light) take 1 + T (shade - 1), every other cell its shade; a
# canopy without cast shadows is refused. shadow --crown-light
# beer-lambert: band 6 holds a path exactly where class 2 is, band 5 is
# exp(-G LAD path) there; its options alone are refused. horizon --canopy
# --canopy-horizon: a canopy of zeros gives the solid horizon byte for
# byte; trees only raise it; south of the tree, looking north, the crown's
# top at its closed form; its refusals.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-$PWD/skysweep}
case $SKYSWEEP in /*) ;; *) SKYSWEEP=$PWD/$SKYSWEEP ;; esac
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-trees.XXXXXX")
trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1

# asc NAME CELL N EXPR: an N x N AAIGrid of CELL m cells over the same
# 60 m square (EPSG:3006), EXPR of x, y (metres east and south of the
# north-west corner) in awk, then a GeoTIFF.
asc() {
    awk -v n="$3" -v cell="$2" "BEGIN {
        print \"ncols \" n; print \"nrows \" n
        print \"xllcorner 400000\"; print \"yllcorner 6400000\"; print \"cellsize \" cell
        for (r = 0; r < n; ++r) { line = \"\"
            for (c = 0; c < n; ++c) { x = (c + 0.5) * cell; y = (r + 0.5) * cell
                line = line \" \" ($4) }
            print line } }" >"$1.asc"
    gdal_translate -q -ot Float32 -a_srs EPSG:3006 "$1.asc" "$1.tif"
}
ground='(x > 40 && x < 50 && y > 10 && y < 30) ? 12 : 0.02 * x'
tree='((x - 22) ^ 2 + (y - 20) ^ 2 <= 16) ? 10 : 0'
asc dsm 1 60 "$ground"
asc zeros 1 60 0
asc canopy 1 60 "$tree"
asc absolute 1 60 "($tree) > 0 ? ($tree) + ($ground) : 0"
asc fine 0.5 120 "$tree"
asc negative 1 60 "($tree) > 0 ? -1 : 0"
asc tall_trunk 1 60 "($tree) > 0 ? 11 : 0"
asc small 1 30 "$tree" # covers only the north-west quarter
# 50 x 50 cells without georeferencing (a VRT without its geotransform and CRS).
gdal_translate -q -srcwin 0 0 50 50 -of VRT canopy.tif nogeo.vrt
sed -i '/<GeoTransform>/d; /<SRS.*<\/SRS>/d' nogeo.vrt
gdal_translate -q nogeo.vrt nogeo.tif

sun=(--device reference --sun-azimuth 250 --sun-elevation 30)
shadow() { "$SKYSWEEP" shadow -q "${sun[@]}" "$@"; }
# band FILE N: the band's values, one a line.
band() {
    gdal_translate -q -b "$2" -of ENVI "$1" "$1.b$2.raw" && od -An -v -f -w4 "$1.b$2.raw" | tr -d ' '
}

shadow dsm.tif plain.tif
shadow --canopy zeros.tif dsm.tif z.tif
same=0
for b in 1 2 3; do cmp -s <(band plain.tif $b) <(band z.tif $b) || same=1; done
tap_ok $same "a canopy of zeros: bands 1-3 byte for byte as without --canopy"
[ "$(gdalinfo plain.tif | grep -c '^Band ')" -eq 3 ] && [ "$(gdalinfo z.tif | grep -c '^Band ')" -eq 5 ]
tap_ok $? "without --canopy 3 bands, with it 5"
paste <(band z.tif 1) <(band z.tif 4) <(band z.tif 5) |
    awk '($1 == 1 && ($2 != 0 || $3 != 1)) || ($1 == 0 && ($2 != 1 || $3 != 0)) {bad++}
         END {exit bad > 0}'
tap_ok $? "a canopy of zeros: class 0 where sunlit, 1 where not; fraction = sunlit"

for t in 0 1 0.03; do
    shadow --canopy canopy.tif --transmissivity $t dsm.tif t$t.tif
    cmp -s <(band plain.tif 1) <(band t$t.tif 1)
    tap_ok $? "--transmissivity $t: band 1 unchanged by the trees"
    paste <(band t$t.tif 4) <(band t$t.tif 5) |
        awk -v t=$t '$1 == 2 {veg++; if ($2 != t + 0 && sprintf("%.6g", $2) != t) bad++}
                     $1 == 1 && $2 != 0 {bad++} $1 == 0 && $2 != 1 {bad++}
                     END {exit !(veg > 20 && bad == 0)}'
    tap_ok $? "--transmissivity $t: vegetation shadow (class 2) gets fraction $t, solid 0, lit 1"
done
md=$(gdalinfo t0.03.tif)
grep -q "CANOPY=canopy.tif (heights above the ground)" <<<"$md" &&
    grep -q "TRUNK=crown bottoms at 0.25 x the canopy height" <<<"$md" &&
    grep -q "TRANSMISSIVITY=0.03" <<<"$md" &&
    grep -q "Description = shadow class: 0 lit, 1 solid shadow, 2 vegetation shadow" <<<"$md"
tap_ok $? "the metadata name the canopy, its convention, the trunk rule and the transmissivity"

shadow --canopy absolute.tif --canopy-heights absolute dsm.tif abs.tif
cmp -s <(band t0.03.tif 4) <(band abs.tif 4)
tap_ok $? "--canopy-heights absolute: the same classes as the heights above ground"
gdalinfo abs.tif | grep -q "CANOPY=absolute.tif (heights absolute, the DSM subtracted)"
tap_ok $? "--canopy-heights absolute is recorded"

out=$("$SKYSWEEP" shadow "${sun[@]}" --canopy fine.tif dsm.tif fine_out.tif 2>&1)
rc=$?
veg=$(band fine_out.tif 4 | grep -c '^2$')
[ $rc -eq 0 ] && grep -q "warped onto the DEM's grid" <<<"$out" && [ "$veg" -gt 20 ]
tap_ok $? "a canopy on a 0.5 m grid is warped onto the DSM's ($veg cells in vegetation shadow)"

# A DSM swept in bands (--memory): the crowns read it whole, the same classes.
# Gothenburg's DSM and canopy at 4 times the resolution (cells split in 16),
# swept within the least budget the planner names: one band's, below the
# whole grid's, so the sweep runs in bands.
data=${TOP_SRCDIR:-$OLDPWD}/../shared/data
if [ -r "$data/goteborg_kronenhuset_dsm_1m.tif" ] && [ -r "$data/goteborg_kronenhuset_cdsm_1m.tif" ]; then
    gdal_translate -q -r near -outsize 400% 400% "$data/goteborg_kronenhuset_dsm_1m.tif" dsm4.tif
    gdal_translate -q -r near -outsize 400% 400% "$data/goteborg_kronenhuset_cdsm_1m.tif" cdsm4.tif
fi
# least_budget COMMAND OPTIONS...: the least --memory the run's refusal names.
least_budget() {
    "$SKYSWEEP" "$@" --memory 1M dsm4.tif least.tif 2>&1 >/dev/null |
        sed -n 's/.*at least --memory \([0-9]*M\).*/\1/p'
}
# at_least SUMMARY LEAST COMMAND ARGS...: runs skysweep COMMAND ARGS at the
# budget the refusal named (the least and a MiB of headroom for what the
# process holds from run to run); its summary into the file SUMMARY (not a
# pipe, which could end the run before its output is written).
at_least() {
    local summary=$1 least=$2
    shift 2
    "$SKYSWEEP" "$@" --memory "$least" >"$summary" 2>/dev/null
}
if [ -r dsm4.tif ]; then
    g=(--lines interpolated --canopy cdsm4.tif dsm4.tif)
    least=$(least_budget shadow "${sun[@]}" --lines interpolated --canopy cdsm4.tif)
    shadow "${g[@]}" gw.tif && at_least gb.out "$least" shadow "${sun[@]}" "${g[@]}" gb.tif &&
        grep -q "in bands$" gb.out &&
        cmp -s <(band gw.tif 4) <(band gb.tif 4) && cmp -s <(band gw.tif 5) <(band gb.tif 5)
    tap_ok $? "Gothenburg swept in bands: bands 4 and 5 as on the DSM held whole"
else
    tap_skip "Gothenburg swept in bands" "../shared/data is not here"
fi

# refuse EXIT DESCRIPTION ARGS...: exit EXIT, one line on stderr, no output.
refuse() {
    local want=$1 what=$2
    shift 2
    rm -f bad.tif
    shadow "$@" 2>err.txt >/dev/null
    local rc=$?
    [ $rc -eq "$want" ] && [ "$(wc -l <err.txt)" -eq 1 ] && [ ! -e bad.tif ]
    tap_ok $? "$what: exit $rc ($(head -c 160 err.txt))"
}
refuse 3 "a canopy below 0" --canopy negative.tif dsm.tif bad.tif
refuse 3 "a trunk above its canopy" --canopy canopy.tif --trunk tall_trunk.tif dsm.tif bad.tif
refuse 2 "--transmissivity 1.5" --canopy canopy.tif --transmissivity 1.5 dsm.tif bad.tif
refuse 2 "--trunk-ratio 2" --canopy canopy.tif --trunk-ratio 2 dsm.tif bad.tif
refuse 3 "a canopy on another grid without georeferencing" --canopy nogeo.tif dsm.tif bad.tif
refuse 3 "a canopy that does not cover the DSM" --canopy small.tif dsm.tif bad.tif
refuse 2 "--trunk without --canopy" --trunk canopy.tif dsm.tif bad.tif
refuse 2 "--trunk with --trunk-ratio" --canopy canopy.tif --trunk zeros.tif --trunk-ratio 0.5 dsm.tif bad.tif
refuse 2 "--transmissivity without --canopy" --transmissivity 0.5 dsm.tif bad.tif
cp canopy.tif same.tif
shadow --canopy same.tif dsm.tif same.tif 2>err.txt >/dev/null
rc=$?
[ $rc -eq 2 ] && [ "$(wc -l <err.txt)" -eq 1 ] && cmp -s canopy.tif same.tif
tap_ok $? "a canopy that is also the output is refused and left alone: exit $rc ($(cat err.txt))"
# svf --canopy (doc/vegetation.md, "svf"): bands 2 svfveg and 3 svfbuveg.
svf() { "$SKYSWEEP" svf -q --device reference --directions 16 "$@"; }
svf dsm.tif svf_plain.tif && svf --canopy zeros.tif dsm.tif svf_zeros.tif
cmp -s <(band svf_plain.tif 1) <(band svf_zeros.tif 1) &&
    cmp -s <(band svf_plain.tif 1) <(band svf_zeros.tif 3) &&
    [ "$(band svf_zeros.tif 2 | sort -u)" = 1 ] &&
    [ "$(gdalinfo svf_plain.tif | grep -c '^Band ')" -eq 1 ] &&
    [ "$(gdalinfo svf_zeros.tif | grep -c '^Band ')" -eq 3 ]
tap_ok $? "svf, a canopy of zeros: band 1 byte for byte as without --canopy (1 band, with it 3), svfveg 1, svfbuveg = svf"
for t in 0 0.03 1; do
    svf --canopy canopy.tif --transmissivity $t dsm.tif svf_t$t.tif
    paste <(band svf_t$t.tif 1) <(band svf_t$t.tif 2) <(band svf_t$t.tif 3) |
        awk -v t=$t '{ want = $1 - (1 - $2) * (1 - t); d = $3 - want; if (d < 0) d = -d
                       if (d > 1e-6 || $2 > 1 || $2 < 0) bad++; if ($2 < 0.999) veg++ }
                     END {exit !(veg > 100 && bad == 0)}'
    tap_ok $? "svf --transmissivity $t: svfbuveg = svf - (1 - svfveg)(1 - $t) on every cell, svfveg below 1 on more than 100"
done
cmp -s <(band svf_plain.tif 1) <(band svf_t0.03.tif 1)
tap_ok $? "svf --canopy: band 1 byte for byte as without it"
md=$(gdalinfo svf_t0.03.tif)
grep -q "CANOPY=canopy.tif (heights above the ground)" <<<"$md" &&
    grep -q "TRUNK=crown bottoms at 0.25 x the canopy height" <<<"$md" &&
    grep -q "TRANSMISSIVITY=0.03" <<<"$md" && grep -q "TRUNK_GAPS=open" <<<"$md" &&
    grep -q "Description = svfveg" <<<"$md" && grep -q "Description = svfbuveg" <<<"$md"
tap_ok $? "svf --canopy: the metadata name the canopy, the trunk rule, the transmissivity and the trunk gaps"
svf --canopy canopy.tif --trunk-gaps ignore dsm.tif svf_ignore.tif
paste <(band svf_t0.03.tif 2) <(band svf_ignore.tif 2) |
    awk '$2 > $1 + 1e-6 {bad++} $2 < $1 - 1e-4 {lower++} END {exit !(bad == 0 && lower > 10)}'
tap_ok $? "svf --trunk-gaps ignore: crowns down to the ground hide more, never less"
if [ -r dsm4.tif ]; then
    g=(--canopy cdsm4.tif dsm4.tif)
    least=$(least_budget svf --device reference --directions 16 --lines digital --canopy cdsm4.tif)
    svf --lines digital "${g[@]}" sw.tif &&
        at_least sb.out "$least" svf --device reference --directions 16 --lines digital "${g[@]}" sb.tif &&
        grep -q "in bands$" sb.out &&
        cmp -s <(band sw.tif 2) <(band sb.tif 2) &&
        paste <(band sw.tif 3) <(band sb.tif 3) | awk '{d = $1 - $2} d > 1e-6 || d < -1e-6 {bad++} END {exit bad > 0}'
    # band 1 (so 3) of a banded sweep may differ from the whole one's in the last float bit
    tap_ok $? "svf, Gothenburg swept in bands: band 2 as on the DSM held whole, band 3 within 1e-6"
else
    tap_skip "svf, Gothenburg swept in bands" "../shared/data is not here"
fi
refuse_svf() {
    local want=$1 what=$2 command=$3
    shift 3
    rm -f bad.tif
    "$SKYSWEEP" "$command" -q "$@" 2>err.txt >/dev/null
    local rc=$?
    [ $rc -eq "$want" ] && [ "$(wc -l <err.txt)" -eq 1 ] && [ ! -e bad.tif ]
    tap_ok $? "$command, $what: exit $rc ($(head -c 160 err.txt))"
}
refuse_svf 2 "--trunk-gaps without --canopy" svf --trunk-gaps ignore dsm.tif bad.tif
refuse_svf 2 "--canopy with the radiative definition" svf --canopy canopy.tif --definition radiative dsm.tif bad.tif
refuse_svf 2 "--canopy with --radius" svf --canopy canopy.tif --radius 20 dsm.tif bad.tif
refuse_svf 3 "a canopy below 0" svf --canopy negative.tif dsm.tif bad.tif
refuse_svf 2 "--canopy (openness takes no trees)" openness --canopy canopy.tif dsm.tif bad.tif
refuse_svf 2 "--trunk-gaps (shadow has no sky view)" shadow "${sun[@]}" --canopy canopy.tif --trunk-gaps open dsm.tif bad.tif
# hillshade --canopy: the light's crowns darken its cast shadows.
hs() { "$SKYSWEEP" hillshade -q --device reference --cast-shadows --az 250 --alt 30 --north grid "$@"; }
# byte_band FILE: band 1 of a byte raster as floats, one a line.
byte_band() {
    gdal_translate -q -ot Float32 -of ENVI "$1" "$1.f.raw" && od -An -v -f -w4 "$1.f.raw" | tr -d ' '
}
hs dsm.tif hs_plain.tif && hs --canopy zeros.tif dsm.tif hs_zeros.tif &&
    hs --canopy canopy.tif --transmissivity 1 dsm.tif hs_t1.tif &&
    cmp -s <(byte_band hs_plain.tif) <(byte_band hs_zeros.tif) &&
    cmp -s <(byte_band hs_plain.tif) <(byte_band hs_t1.tif)
tap_ok $? "hillshade, a canopy of zeros or of transmissivity 1: the shade byte for byte as without --canopy"
"$SKYSWEEP" shadow -q --device reference --north grid --sun-azimuth 250 --sun-elevation 30 \
    --canopy canopy.tif dsm.tif hs_classes.tif
for t in 0 0.5; do
    hs --canopy canopy.tif --transmissivity $t dsm.tif hs_t$t.tif
    # The shade is written as bytes: 1 + T (shade - 1) of the unrounded
    # shade, within 0.5 T + 0.5 of the rounded one's.
    paste <(byte_band hs_plain.tif) <(byte_band hs_t$t.tif) <(band hs_classes.tif 4) |
        awk -v t=$t '$3 == 2 {veg++; d = $2 - (1 + t * ($1 - 1)); if (d < 0) d = -d
                              if (d > 0.5 * t + 0.5 + 1e-6 || (t == 0 && $2 != 1)) bad++}
                     $3 != 2 && $2 != $1 {bad++}
                     END {exit !(veg > 50 && bad == 0)}'
    tap_ok $? "hillshade --transmissivity $t: cells in the crowns' shadow take 1 + $t (shade - 1), the others their shade"
done
grep -q "TRANSMISSIVITY=0.5" <(gdalinfo hs_t0.5.tif)
tap_ok $? "hillshade --canopy: the metadata name the transmissivity"
if [ -r dsm4.tif ]; then
    g=(--lines interpolated --canopy cdsm4.tif --transmissivity 0.5 dsm4.tif)
    least=$(least_budget hillshade --device reference --cast-shadows --north grid --lines interpolated --canopy cdsm4.tif)
    hs "${g[@]}" hw.tif &&
        at_least hb.out "$least" hillshade --device reference --cast-shadows --az 250 --alt 30 \
            --north grid "${g[@]}" hb.tif && grep -q "^bands " hb.out &&
        cmp -s <(byte_band hw.tif) <(byte_band hb.tif)
    tap_ok $? "hillshade --canopy, Gothenburg swept in bands: the shade as on the DSM held whole"
    # insolation --canopy: 10 MiB above the least budget (bands of about a
    # hundred rows). The beam and sun hours, which the crowns cut, byte for
    # byte; the sky's terms within 1e-6 of the band's largest value (a
    # banded sweep's last bits).
    g=(--device reference --time 2026-06-21T06:00Z/PT3H --step PT1H --lines interpolated
        --directions 8 --canopy cdsm4.tif)
    least=$(least_budget insolation "${g[@]}")
    "$SKYSWEEP" insolation -q "${g[@]}" dsm4.tif iw.tif &&
        "$SKYSWEEP" insolation "${g[@]}" --memory "$((${least%M} + 10))M" dsm4.tif ib.tif >ib.out &&
        grep -q "^bands " ib.out && cmp -s <(band iw.tif 2) <(band ib.tif 2) &&
        cmp -s <(band iw.tif 5) <(band ib.tif 5) &&
        (for b in 1 3 4; do
            paste <(band iw.tif $b) <(band ib.tif $b) |
                awk '{d = $1 - $2; m = $1 < 0 ? -$1 : $1; if (d < 0) d = -d
                      if (d > worst) worst = d; if (m > largest) largest = m}
                     END {exit worst > 1e-6 * largest}' || exit 1
        done)
    tap_ok $? "insolation --canopy, Gothenburg swept in bands: beam and sun hours as on the DSM held whole, the sky's terms within 1e-6"
else
    tap_skip "hillshade --canopy, Gothenburg swept in bands" "../shared/data is not here"
    tap_skip "insolation --canopy, Gothenburg swept in bands" "../shared/data is not here"
fi
refuse_svf 2 "--canopy without --cast-shadows" hillshade --canopy canopy.tif dsm.tif bad.tif
refuse_svf 2 "--transmissivity without --canopy" hillshade --cast-shadows --transmissivity 0.5 dsm.tif bad.tif
# shadow --crown-light beer-lambert: the path inside crowns (band 6).
shadow --canopy canopy.tif --crown-light beer-lambert --leaf-area-density 0.8 dsm.tif bl.tif
paste <(band bl.tif 4) <(band bl.tif 5) <(band bl.tif 6) |
    awk '$1 == 2 {veg++; want = exp(-0.5 * 0.8 * $3); d = $2 - want; if (d < 0) d = -d
                  if (!($3 > 0) || d > 1e-6 * want) bad++}
         $1 != 2 && $3 != 0 {bad++} $1 == 1 && $2 != 0 {bad++} $1 == 0 && $2 != 1 {bad++}
         END {exit !(veg > 20 && bad == 0)}'
tap_ok $? "--crown-light beer-lambert: a path exactly where class 2 is, its fraction exp(-0.5 x 0.8 x path)"
grep -q "CROWN_LIGHT=Beer-Lambert: exp(-0.5 x 0.8 m2/m3" <(gdalinfo bl.tif) &&
    grep -q "TRANSMISSIVITY=none leaf on: Beer-Lambert" <(gdalinfo bl.tif) &&
    grep -q "CROWN_LIGHT=constant: transmissivity 0.03" <(gdalinfo t0.03.tif) &&
    grep -q "TRANSMISSIVITY=0.03$" <(gdalinfo t0.03.tif)
tap_ok $? "the metadata name the crowns' light: constant or Beer-Lambert with its coefficients (TRANSMISSIVITY not the constant Beer-Lambert replaces)"
refuse 2 "--leaf-area-density without --crown-light beer-lambert" --canopy canopy.tif --leaf-area-density 2 dsm.tif bad.tif
refuse 2 "--crown-light beer-lambert without --canopy" --crown-light beer-lambert dsm.tif bad.tif
refuse 2 "--transmissivity with --crown-light beer-lambert" --canopy canopy.tif --crown-light beer-lambert --transmissivity 0.1 dsm.tif bad.tif
# horizon --canopy: the canopy horizon beside the solid one.
hz() { "$SKYSWEEP" horizon -q --device reference --north grid --directions 4 "$@"; }
hz --canopy zeros.tif --canopy-horizon hz_zeros.tif dsm.tif hz_solid.tif &&
    hz --canopy canopy.tif --canopy-horizon hz_trees.tif dsm.tif hz_solid2.tif
same=0 raised=0
for b in 1 2 3 4; do
    cmp -s <(band hz_solid.tif $b) <(band hz_zeros.tif $b) || same=1
    cmp -s <(band hz_solid.tif $b) <(band hz_solid2.tif $b) || same=1
    paste <(band hz_solid.tif $b) <(band hz_trees.tif $b) |
        awk '$2 < $1 {bad++} END {exit bad > 0}' || raised=1
done
tap_ok $same "horizon, a canopy of zeros: the canopy horizon is the solid one byte for byte, and --canopy leaves the solid output alone"
# Cell (22, 40) looks north along its column at the crown (radius 4 m,
# 10 m tall, centre row 20): the nearest crown cell's top, 17 cells away,
# over level ground along the column (cells of 1.00028 m on the ground).
north=$(band hz_trees.tif 1 | sed -n "$((40 * 60 + 22 + 1))p")
awk -v h="$north" -v raised=$raised 'BEGIN {want = atan2(10, 17 * 1.00028) * 45 / atan2(1, 1)
                          d = h - want; exit !(raised == 0 && d < 1e-3 && d > -1e-3)}'
tap_ok $? "horizon --canopy: trees only raise the horizon; looking north at the crown 17 m away, $north deg (atan(10 / 17.005 m))"
rm -f bad.tif
"$SKYSWEEP" horizon -q --canopy canopy.tif dsm.tif bad.tif 2>err.txt >/dev/null
rc=$?
[ $rc -eq 2 ] && [ "$(wc -l <err.txt)" -eq 1 ] && [ ! -e bad.tif ]
tap_ok $? "horizon --canopy without --canopy-horizon: exit $rc ($(head -c 160 err.txt))"
"$SKYSWEEP" horizon -q --canopy canopy.tif --canopy-horizon c.tif --transmissivity 0.2 dsm.tif bad.tif 2>err.txt >/dev/null
rc=$?
[ $rc -eq 2 ] && [ "$(wc -l <err.txt)" -eq 1 ] && [ ! -e bad.tif ] && [ ! -e c.tif ]
tap_ok $? "horizon --canopy with --transmissivity (which cannot change it): exit $rc ($(head -c 160 err.txt))"
tap_done
