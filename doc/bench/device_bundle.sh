#!/bin/bash
# Packs what a lent GPU machine needs to time and test the OpenCL kernels:
# that machine has no GDAL (reference/toolchain.md), so the bundle holds only
# programs that link the core (statically: libsscore) and OpenCL: ss-bench,
# ss-scale, the core-only test programs, libgomp, and the Kilauea DEM as raw
# float32.
#
#   doc/bench/device_bundle.sh [DIR]     (default .gpu; build first: make check TESTS=)
#
# Then run doc/bench/device_run.sh DIR there (see that script).
set -euo pipefail
top=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${BUILD:-$top}
dir=${1:-$top/.gpu}
core_tests="lines analytic shadow horizon_edges cast_height insolation openness banded
    banded_horizon banded_insolation engine params reference hardcases"
rm -rf "$dir" && mkdir -p "$dir/bin" "$dir/lib" "$dir/data"
cp "$build/ss-bench" "$build/ss-scale" "$dir/bin/"
for t in $core_tests; do cp "$build/tests/test_$t" "$dir/bin/"; done
cp -L "$(ldd "$build/ss-bench" | awk '/libgomp/ {print $3}')" "$dir/lib/"
echo $core_tests >"$dir/core_tests"
dem=$top/../shared/data/hawaii_kilauea_utm5n_30m.tif
[ -r "$dem" ] || dem=$top/samples/kilauea_summit_30m.tif
gdal_translate -q -of ENVI -ot Float32 -a_nodata -3.4e38 "$dem" "$dir/data/dem.raw"
gdalinfo "$dem" | sed -n 's/^Size is \([0-9]*\), \([0-9]*\)/\1 \2/p' >"$dir/data/dem.size"
rm -f "$dir/data/dem.hdr" "$dir/data/dem.raw.aux.xml"
du -sh "$dir"
