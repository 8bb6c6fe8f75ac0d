#!/bin/bash
# Pictures from the command line: skysweep render draws a PNG of the size
# asked for, lit by the sun skysweep shadow uses, and exports a .vts that
# names the drape; skysweep quicklook writes a PNG of the raster's size with
# nodata transparent; a 16-bit PNG heightmap read with --heightmap gives the
# very SVF its GeoTIFF gives; and without VTK, OpenImageIO or an X display
# the commands fail with one line and exit 5. Parts whose library is absent
# are skipped with the reason; renders need an X display (xvfb-run -a).
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
SKYSWEEP=${SKYSWEEP:-./skysweep}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-pictures.XXXXXX")
trap 'rm -rf "$work"' EXIT

# A 60 x 50 DEM in UTM 5N with a hill and one nodata cell at (0, 0), as in
# test_cli.sh.
dem=$work/dem.tif
awk 'BEGIN {
    print "ncols 60"; print "nrows 50"; print "xllcorner 254325"; print "yllcorner 2152155"
    print "cellsize 30"; print "NODATA_value -9999"
    for (r = 0; r < 50; r++) {
        line = ""
        for (c = 0; c < 60; c++) {
            v = (r == 0 && c == 0) ? -9999 : 100 + 300 * exp(-((c - 30) ^ 2 + (r - 25) ^ 2) / 80)
            line = line sprintf("%.3f ", v)
        }
        print line
    }
}' >"$work/dem.asc"
gdal_translate -q -ot Float32 -a_srs EPSG:32605 "$work/dem.asc" "$dem"

run() { # runs skysweep, capturing stdout/stderr and the exit code in $rc
    "$SKYSWEEP" "$@" >"$work/stdout" 2>"$work/stderr"
    rc=$?
}
one_line() { [ "$(wc -l <"$work/stderr")" -eq 1 ]; }
# PNG header fields: width, height, bit depth, colour type (IHDR at byte 16).
png_header() {
    od -A n -t u1 -j 16 -N 10 "$1" |
        awk '{ print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4, \
                     $5 * 16777216 + $6 * 65536 + $7 * 256 + $8, $9, $10 }'
}

run svf -q --directions 16 "$dem" "$work/svf.tif"
tap_ok $rc "svf product to draw ($(head -c 200 "$work/stderr"))"

# ---- quicklook (OpenImageIO) ---------------------------------------------------
run quicklook --colormap magma "$work/svf.tif" "$work/q.png"
if [ $rc -eq 5 ] && grep -q 'built without OpenImageIO' "$work/stderr"; then
    one_line && [ ! -e "$work/q.png" ]
    tap_ok $? "quicklook without OpenImageIO: one line, exit 5, no file"
    have_oiio=0
else
    have_oiio=1
    tap_ok $rc "quicklook exits 0 ($(head -c 200 "$work/stderr"))"
    read -r w h depth type <<<"$(png_header "$work/q.png")"
    [ "$w" = 60 ] && [ "$h" = 50 ]
    tap_ok $? "quicklook PNG is the raster's size (${w} x ${h})"
    [ "$depth" = 8 ] && [ "$type" = 6 ]
    tap_ok $? "quicklook of a product with nodata is 8-bit RGBA (depth $depth, colour type $type)"
    if command -v oiiotool >/dev/null; then
        # "Pixel (x, y): R G B A (...)": alpha is field 7.
        oiiotool --dumpdata "$work/q.png" >"$work/dump.txt"
        transparent=$(awk '$7 == 0' "$work/dump.txt")
        opaque=$(awk '$7 == 255' "$work/dump.txt" | wc -l)
        [ "$(echo "$transparent" | wc -l)" -eq 1 ] && echo "$transparent" | grep -q '^ *Pixel (0, 0):' &&
            [ "$opaque" -eq 2999 ]
        tap_ok $? "quicklook alpha is 0 at the one nodata cell and opaque elsewhere ($opaque opaque)"
    else
        tap_skip "quicklook alpha at nodata" "oiiotool not installed"
    fi
    run quicklook --bits 16 "$work/svf.tif" "$work/q16.png"
    read -r w h depth type <<<"$(png_header "$work/q16.png")"
    [ $rc -eq 0 ] && [ "$depth" = 16 ] && [ "$type" = 4 ] && [ "$w" = 60 ]
    tap_ok $? "quicklook --bits 16 is 16-bit grey + alpha (depth $depth, colour type $type)"
    run shadow -q --sun-azimuth 90 --sun-elevation 20 "$dem" "$work/shadow.tif"
    run quicklook --band 3 --colormap grey "$work/shadow.tif" "$work/q3.png"
    [ $rc -eq 0 ] && grep -q '^band .*3 of 3: illumination' "$work/stdout"
    tap_ok $? "quicklook --band 3 draws the third band"
    run quicklook --band 4 "$work/shadow.tif" "$work/q4.png"
    [ $rc -eq 2 ] && one_line && [ ! -e "$work/q4.png" ]
    tap_ok $? "quicklook of a band that does not exist: exit 2, one line, no file"
    run quicklook --colormap rainbow "$work/svf.tif" "$work/q5.png"
    [ $rc -eq 2 ] && one_line && grep -q 'known: grey' "$work/stderr"
    tap_ok $? "quicklook with an unknown colour map: exit 2, names the known ones"
    run quicklook "$work/svf.tif" "$work/svf.tif"
    [ $rc -eq 2 ] && one_line
    tap_ok $? "quicklook refuses to overwrite its input"
    run quicklook "$work/svf.tif" "$work/q.tif"
    [ $rc -eq 2 ] && one_line && [ ! -e "$work/q.tif" ] && grep -q "PNG" "$work/stderr"
    tap_ok $? "quicklook to a name that is not .png: exit $rc, one line, no file (it once wrote PNG bytes there)"
    gdal_translate -q -scale 0 1 -9999 -9999 "$work/svf.tif" "$work/blank.tif"
    run quicklook "$work/blank.tif" "$work/blank.png"
    [ $rc -eq 3 ] && one_line && [ ! -e "$work/blank.png" ] && grep -q "nothing to show" "$work/stderr"
    tap_ok $? "quicklook of a band that is all nodata: exit $rc, one line, no file: $(head -c 160 "$work/stderr")"
fi

# ---- heightmaps (OpenImageIO) --------------------------------------------------
# Whole-metre heights in a CRS whose central meridian runs through the
# grid's centre, so the ground cell there is exactly 30 m (scale factor 1)
# and the GeoTIFF and the PNG read with --cell-size 30 are the same DEM.
if [ $have_oiio = 0 ]; then
    run svf --heightmap --cell-size 30 "$work/any.png" "$work/out.tif"
    [ $rc -eq 5 ] && one_line && grep -q 'built without OpenImageIO' "$work/stderr"
    tap_ok $? "--heightmap without OpenImageIO: one line, exit 5"
    tap_skip "16-bit PNG heightmap SVF equals GeoTIFF SVF" "built without OpenImageIO"
elif ! command -v oiiotool >/dev/null; then
    tap_skip "16-bit PNG heightmap SVF equals GeoTIFF SVF" "oiiotool not installed"
else
    gdal_translate -q -ot UInt16 -a_nodata none -srcwin 1 1 58 48 \
        -a_srs '+proj=tmerc +lat_0=0 +lon_0=0 +k=1 +x_0=0 +y_0=0 +datum=WGS84 +units=m' \
        -a_ullr -870 2201440 870 2200000 "$dem" "$work/crop.tif"
    oiiotool "$work/crop.tif" -d uint16 -o "$work/crop.png"
    read -r w h depth type <<<"$(png_header "$work/crop.png")"
    run svf -q --north grid --directions 16 "$work/crop.tif" "$work/svf_tif.tif"
    rc_tif=$rc
    run svf --heightmap --cell-size 30 --directions 16 "$work/crop.png" "$work/svf_png.tif"
    [ $rc_tif -eq 0 ] && [ $rc -eq 0 ] && [ "$depth" = 16 ] && [ "$w" = 58 ]
    tap_ok $? "svf runs on the GeoTIFF crop and on its 16-bit PNG (depth $depth) with --heightmap"
    grep -q 'heightmap: 30 m cells' "$work/stdout"
    tap_ok $? "the summary says the input was read as a heightmap"
    gdal_translate -q -of ENVI "$work/svf_tif.tif" "$work/a.bin"
    gdal_translate -q -of ENVI "$work/svf_png.tif" "$work/b.bin"
    cmp -s "$work/a.bin" "$work/b.bin"
    tap_ok $? "SVF from the PNG heightmap equals SVF from the GeoTIFF, bit for bit"
    stats=$(gdalinfo -stats "$work/svf_png.tif" 2>&1 | grep -c 'STATISTICS_MEAN=0\.9')
    [ "$stats" -eq 1 ]
    tap_ok $? "that SVF is plausible (mean 0.9..1 on a gentle hill)"
    run svf --heightmap --directions 16 "$work/crop.png" "$work/out.tif"
    [ $rc -eq 2 ] && one_line && grep -q -- '--cell-size' "$work/stderr"
    tap_ok $? "--heightmap without --cell-size: exit 2, asks for it"
    # Cut short: an uncompressed TIFF's missing strips once read as zeros
    # (flat ground) with exit 0, and libpng printed a line of its own.
    gdal_translate -q -co COMPRESS=NONE "$work/crop.tif" "$work/whole.tif"
    head -c 3000 "$work/whole.tif" >"$work/cut.tif"
    head -c $(($(wc -c <"$work/crop.png") / 2)) "$work/crop.png" >"$work/cut.png"
    # OpenImageIO 2.4's PNG reader leaks 31 bytes here: libpng's error
    # handler longjmps over a std::string its read callback holds, and the
    # leak's stack stops in libstdc++, which no suppression can name without
    # slowing every run: that one run goes without leak checks.
    saved_asan=${ASAN_OPTIONS-}
    for cut in cut.tif cut.png; do
        rm -f "$work/out.tif"
        [ $cut = cut.png ] && export ASAN_OPTIONS="${saved_asan:+$saved_asan:}detect_leaks=0"
        run svf --heightmap --cell-size 30 "$work/$cut" "$work/out.tif"
        export ASAN_OPTIONS="$saved_asan"
        [ $rc -eq 3 ] && one_line && [ ! -e "$work/out.tif" ] &&
            grep -q 'cannot read the pixels' "$work/stderr"
        tap_ok $? "a heightmap cut short ($cut): exit $rc (want 3), one line: $(head -c 200 "$work/stderr")"
    done
fi

# ---- render (VTK) ---------------------------------------------------------------
env -u DISPLAY "$SKYSWEEP" render "$dem" "$work/nodisplay.png" >"$work/stdout" 2>"$work/stderr"
rc=$?
if grep -q 'built without VTK' "$work/stderr"; then
    have_vtk=0
    [ $rc -eq 5 ] && one_line
    tap_ok $? "render without VTK: one line, exit 5"
else
    have_vtk=1
    [ $rc -eq 5 ] && one_line && grep -q 'needs an X display: run under xvfb-run -a' "$work/stderr" &&
        [ ! -e "$work/nodisplay.png" ]
    tap_ok $? "render without a display: one line naming xvfb-run, exit 5, no file"
fi
if [ $have_vtk = 0 ]; then
    tap_skip "render and .vts export" "built without VTK"
elif [ -z "${DISPLAY:-}" ]; then
    tap_skip "render and .vts export" "no X display: run the tests under xvfb-run -a"
else
    # Mesa's llvmpipe (the renderer under Xvfb) leaves allocations behind in
    # driver modules it has unloaded by exit; LeakSanitizer cannot name them
    # to suppress, so sanitizer builds skip leak checks from here on.
    export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
    run render --drape "$work/svf.tif" --colormap svf --size 320x240 --title "test hill" \
        --export "$work/hill.vts" "$dem" "$work/r.png"
    tap_ok $rc "render with a drape and --export exits 0 ($(head -c 200 "$work/stderr"))"
    read -r w h depth type <<<"$(png_header "$work/r.png")"
    [ "$w" = 320 ] && [ "$h" = 240 ] && [ "$type" = 2 ]
    tap_ok $? "render PNG is RGB of the size asked for (${w} x ${h}, colour type $type)"
    [ -s "$work/hill.vts" ] && grep -aq 'Name="sky-view factor \[1\]"' "$work/hill.vts" &&
        grep -aq 'Name="height \[m\]"' "$work/hill.vts"
    tap_ok $? ".vts export holds the drape field and the heights"
    grep -q "cell (0,0) centred at 254340.000, 2153640.000" "$work/stdout"
    tap_ok $? ".vts points are in the DEM's CRS (cell (0,0) centre reported)"

    # The light is the sun skysweep shadow uses at that time.
    run shadow --time 2026-03-20T19:00Z "$dem" "$work/sh.tif"
    sun_shadow=$(sed -n 's/^sun  *azimuth \([0-9.-]*\), apparent elevation \([0-9.-]*\) deg.*/\1 \2/p' \
        "$work/stdout")
    run render --view top --drape "$work/sh.tif" --drape-band 3 --colormap grey \
        --time 2026-03-20T19:00Z --size 200x160 "$dem" "$work/top.png"
    sun_render=$(sed -n 's/^light .*azimuth \([0-9.-]*\) deg, apparent elevation \([0-9.-]*\) deg.*/\1 \2/p' \
        "$work/stdout")
    [ $rc -eq 0 ] && [ -n "$sun_shadow" ] && [ "$sun_shadow" = "$sun_render" ]
    tap_ok $? "render's light is shadow's sun ($sun_render vs $sun_shadow)"

    gdal_translate -q -srcwin 0 0 30 30 "$work/svf.tif" "$work/svf_part.tif"
    run render --drape "$work/svf_part.tif" "$dem" "$work/out.png"
    [ $rc -eq 3 ] && one_line && grep -q "not on the DEM's grid" "$work/stderr" &&
        [ ! -e "$work/out.png" ]
    tap_ok $? "a drape on another grid: exit 3, one line, no file"
    run render --drape "$work/svf.tif" --drape-band 2 "$dem" "$work/out.png"
    [ $rc -eq 2 ] && one_line
    tap_ok $? "a drape band that does not exist: exit 2"
    for bad in "--size 800" "--size 8x8" "--background 1,2" "--export x.vtk" \
        "--view top --camera-elevation 40" "--colormap rainbow"; do
        # shellcheck disable=SC2086
        run render $bad "$dem" "$work/out.png"
        [ $rc -eq 2 ] && one_line && [ ! -e "$work/out.png" ]
        tap_ok $? "render $bad: exit 2, one line, no file"
    done
    if [ $have_oiio = 1 ] && [ -e "$work/crop.png" ]; then
        run render --heightmap --cell-size 30 --sun-azimuth 135 --sun-elevation 30 \
            --size 160x120 "$work/crop.png" "$work/hm.png"
        read -r w h depth type <<<"$(png_header "$work/hm.png")"
        [ $rc -eq 0 ] && [ "$w" = 160 ]
        tap_ok $? "render draws a PNG heightmap read with --heightmap"
    fi
fi

# The program itself links neither VTK nor OpenImageIO: each is a module
# that only its commands load (src/cli/modules.c), so no other command pays
# their start-up. The build tree's binary sits in .libs behind libtool's
# wrapper.
binary=$(dirname "$SKYSWEEP")/.libs/$(basename "$SKYSWEEP")
[ -x "$binary" ] || binary=$SKYSWEEP
if ldd "$binary" >"$work/ldd" 2>/dev/null; then
    ! grep -q -E 'libvtk|libOpenImageIO' "$work/ldd"
    tap_ok $? "skysweep links no VTK or OpenImageIO library ($(wc -l <"$work/ldd") shared libraries): $(grep -E -o 'libvtk[^ ]*|libOpenImageIO[^ ]*' "$work/ldd" | head -n 3 | tr '\n' ' ')"
else
    tap_skip "skysweep links no VTK or OpenImageIO library" "ldd cannot read $binary"
fi
tap_done
