#!/bin/bash
# The picture gallery of doc/pictures.md, made in one go into doc/img/ from
# the sample DEMs: Kilauea's sky-view factor draped in 3D and lit by the
# sun skysweep shadow uses, its clear-sky insolation on 21 June (3D and a
# 2D quicklook), a hillshade with exact cast shadows, and the Gothenburg
# DSM's shadows at 09:00 CET on 20 March 2026 (skipped with a message when
# ../shared/data is absent).
#
#   doc/gallery.sh            (or make gallery; SKYSWEEP=... picks the binary)
#
# Renders need an X display: without one the script runs itself under
# xvfb-run -a, so one Xvfb serves every render.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
if [ -z "${DISPLAY:-}" ]; then
    command -v xvfb-run >/dev/null || {
        echo "gallery: no X display and no xvfb-run (apt-get install xvfb)" >&2
        exit 5
    }
    exec xvfb-run -a "$here/gallery.sh" "$@"
fi
cd "$here/.."
SKYSWEEP=${SKYSWEEP:-$PWD/skysweep}
KILAUEA=samples/kilauea_summit_30m.tif
GOTEBORG=${GOTEBORG:-../shared/data/goteborg_kronenhuset_dsm_1m.tif}
img=doc/img
mkdir -p "$img"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/ss-gallery.XXXXXX")
trap 'rm -rf "$tmp"' EXIT

ss() { nice "$SKYSWEEP" "$@"; }
# Renders, and prints the summary's render line (size, z factor, seconds).
render() { ss render "$@" | grep '^render'; }

# Stop early, with skysweep's own message, when a picture library is missing.
ss quicklook -q "$KILAUEA" "$tmp/probe.png"
ss render -q --size 32x32 "$KILAUEA" "$tmp/probe_3d.png"

# Kilauea's southern rows reach the sea, where the DEM is speckled with
# nodata: the pictures show the summit and the fault scarps above it.
gdal_translate -q -srcwin 0 0 512 540 "$KILAUEA" "$tmp/kilauea.tif"
dem=$tmp/kilauea.tif

# 1. Sky-view factor, lit by the sun skysweep shadow sees at 09:00 HST.
when=2026-06-21T19:00Z
ss svf -q --directions 32 "$dem" "$tmp/svf.tif"
render --drape "$tmp/svf.tif" --colormap svf --legend "sky-view factor" --unit "0..1" \
    --time "$when" --camera-azimuth 330 --camera-elevation 40 --distance 1.1 --size 720x540 \
    --max-points 100000 --title "Kīlauea summit: sky-view factor, sun of 21 June 2026 09:00 HST" \
    "$dem" "$img/kilauea_svf_3d.png"

# 2. Clear-sky insolation over the local day of 21 June, in kWh/m2 (a band
# scale, so nodata stays nodata).
ss insolation -q --time 2026-06-21T00:00-10:00/P1D --step PT30M "$dem" "$tmp/insolation.tif"
gdal_translate -q -b 1 -a_scale 0.001 "$tmp/insolation.tif" "$tmp/insolation_kwh.tif"
render --drape "$tmp/insolation_kwh.tif" --colormap magma --min 7 --max 9.1 \
    --legend "global irradiation" --unit "kWh/m²" --camera-elevation 45 --distance 1.1 \
    --size 720x540 --max-points 100000 \
    --title "Kīlauea summit: clear-sky insolation on 21 June 2026" \
    "$dem" "$img/kilauea_insolation_3d.png"
# The 2D quicklook at half resolution keeps the PNG small (map noise
# compresses badly).
gdal_translate -q -r average -outsize 50% 50% "$tmp/insolation_kwh.tif" "$tmp/insolation_half.tif"
ss quicklook -q --colormap magma --min 7 --max 9.1 "$tmp/insolation_half.tif" \
    "$img/kilauea_insolation.png"

# 3. Hillshade with exact cast shadows of a low evening light.
# Flat ground comes out at 1 + 254 sin 15 deg = 67: stretched to show it.
ss hillshade -q --az 290 --alt 15 --cast-shadows "$dem" "$tmp/hillshade.tif"
ss quicklook -q --colormap grey --min 1 --max 150 "$tmp/hillshade.tif" \
    "$img/kilauea_hillshade_shadows.png"

# 4. RVT's VAT relief blend of the caldera (doc/relief.md), horizons within
# 10 cells as RVT's default, and positive openness at unlimited range.
ss hillshade -q --blend vat "$dem" "$tmp/vat.tif"
gdal_translate -q -of PNG "$tmp/vat.tif" "$img/kilauea_vat.png"
ss openness -q "$dem" "$tmp/openness.tif"
ss quicklook -q --colormap grey --min 60 --max 100 "$tmp/openness.tif" \
    "$img/kilauea_openness.png"

# 5. Gothenburg: buildings and their shadows at 09:00 CET on 20 March.
if [ -e "$GOTEBORG" ]; then
    when=2026-03-20T08:00Z
    ss shadow -q --time "$when" "$GOTEBORG" "$tmp/goteborg_shadow.tif"
    render --drape "$tmp/goteborg_shadow.tif" --drape-band 3 --colormap viridis --min 0 --max 1 \
        --legend "direct sun cos i" --unit "0 in shadow" --time "$when" --z-factor 1 \
        --camera-azimuth 300 --camera-elevation 50 --distance 1.15 --size 720x540 \
        --title "Gothenburg DSM: shadows on 20 March 2026, 09:00 CET" \
        "$GOTEBORG" "$img/goteborg_shadows_3d.png"
else
    echo "gallery: $GOTEBORG is absent: the Gothenburg picture is skipped"
fi

for f in "$img"/*.png; do
    bytes=$(stat -c %s "$f")
    echo "$f: $((bytes / 1024)) KiB"
    [ "$bytes" -le 307200 ] || echo "gallery: warning: $f is over 300 KiB"
done
