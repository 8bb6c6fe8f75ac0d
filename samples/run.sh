#!/bin/sh
# Set-up command 1 (README): installs what is needed, builds skysweep and runs
# the main job on the bundled Kilauea sample DEM: sky-view factor and 16
# horizon bands, written as GeoTIFFs into out/.
set -eu
cd "$(dirname "$0")/.."
build-aux/deps.sh
build-aux/build.sh
mkdir -p out
dem=samples/kilauea_summit_30m.tif
./skysweep svf --directions 32 "$dem" out/kilauea_svf.tif
./skysweep horizon --directions 16 --distance out/kilauea_horizon_distance.tif \
    "$dem" out/kilauea_horizon.tif
echo "outputs: out/kilauea_svf.tif out/kilauea_horizon.tif out/kilauea_horizon_distance.tif"
