#!/bin/bash
# A product added by one file reaches every front end without an edit of
# theirs (issue 41): tests/toy_product.c declares "toy" (the highest
# horizon of each cell over the sweep's directions) and its consumer, and
# registers it when preloaded (ss_product_register). With it loaded, the
# CLI lists and runs it (--help, --help-json with its outputs, a man page
# from --help-man), the Python package has its array and file calls, and
# the QGIS provider's loader offers its algorithm. Its values equal a
# brute-force horizon over every cell of the DEM. The test prints the count
# of files a new product touched.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
top=$(realpath "${TOP_SRCDIR:-.}")
SKYSWEEP=$(realpath "${SKYSWEEP:-./skysweep}")
build=$(dirname "$SKYSWEEP")
toy=${TOY_PRODUCT:-$build/tests/.libs/toy_product.so}
py=${SKYSWEEP_PVLIB_PYTHON:-$top/tests/pyvenv/bin/python}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-toy.XXXXXX")
trap 'rm -rf "$work"' EXIT

if [ ! -f "$toy" ]; then
    tap_skip "the toy product" "tests/toy_product.la was not built ($toy)"
    tap_done
    exit
fi
# A library built with the sanitizers needs their runtime loaded first.
preload=""
if ldd "$build/.libs/libskysweep.so.0" | grep -q libasan; then
    preload="$(gcc -print-file-name=libasan.so) $(gcc -print-file-name=libubsan.so) "
fi
# No alternate signal stack per thread, as tests/test_python.sh: on CI's
# Firecracker kernel AddressSanitizer could not unmap one when a thread
# ended in a preloaded Python process, and aborted it; pip's build of the
# package failed that way under CI's sanitizer build (stop 49).
export ASAN_OPTIONS=detect_leaks=0:use_sigaltstack=0:${ASAN_OPTIONS:-}
# The toy's library is the build's: the CLI's, and Python's (SKYSWEEP_LIBRARY).
with_toy() {
    LD_LIBRARY_PATH=$build/.libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH} \
        LD_PRELOAD="$preload$toy" SKYSWEEP_LIBRARY=$build/.libs/libskysweep.so.0 "$@"
}

# The source files that name the toy, besides this test, its lines in
# Makefile.am that build it for the test, and the docs: the one that adds it.
if git -C "$top" rev-parse --git-dir >/dev/null 2>&1; then
    named=$(cd "$top" && git ls-files -co --exclude-standard | grep -v -e '^tests/test_toy_product.sh$' \
        -e '^Makefile.am$' -e '^doc/' | xargs grep -lw -e toy -e toy_product 2>/dev/null | sort)
    count=$(printf '%s\n' "$named" | grep -c .)
    [ "$named" = "tests/toy_product.c" ]
    tap_ok $? "files touched to add the toy product: $count ($(echo $named)): its registry entry and its consumer, no front end's file (before issue 41: about 18)"
else
    tap_skip "the files that name the toy" "not a git checkout"
fi

"$SKYSWEEP" --help-commands >"$work/before"
with_toy "$SKYSWEEP" --help-commands >"$work/after"
! grep -qw toy "$work/before" && grep -qw toy "$work/after"
tap_ok $? "the CLI lists the toy only with it loaded: $(cat "$work/after")"
with_toy "$SKYSWEEP" --help >"$work/help"
grep -q "^  toy .*highest horizon elevation of each cell" "$work/help"
tap_ok $? "skysweep --help lists it with its summary: $(grep '^  toy' "$work/help")"
with_toy "$SKYSWEEP" toy --help >"$work/toy-help"
rc=$?
[ "$rc" -eq 0 ] && grep -q "^Usage: skysweep toy \[options\] DEM... OUTPUT" "$work/toy-help" &&
    grep -q "highest horizon elevation (degrees)" "$work/toy-help" && grep -q -- "--directions" "$work/toy-help"
tap_ok $? "skysweep toy --help (exit $rc): its usage, description and the sweep's options"

with_toy "$SKYSWEEP" toy --help-json >"$work/toy.json"
got=$(python3 -c '
import json, sys
t = json.load(open(sys.argv[1]))
print(" ".join(":".join(str(o[k]) for k in ("name", "unit", "bands", "output"))
               for o in t["outputs"]),
      any(o["name"] == "directions" for o in t["options"]))
' "$work/toy.json" 2>&1)
[ "$got" = "toy:deg:1:True True" ]
tap_ok $? "skysweep toy --help-json: its outputs as declared, the sweep's options ($got)"

with_toy "$SKYSWEEP" toy --help-man >"$work/toy.1" && head -n 1 "$work/toy.1" | grep -q '^\.TH' &&
    grep -q -- '\\-\\-directions' "$work/toy.1" && with_toy "$SKYSWEEP" --help-man | grep -q '^\.B toy$'
tap_ok $? "its man page: skysweep toy --help-man, and skysweep(1) lists it"

# A DEM of heights that vary along the rows only, piecewise linear between
# cell centres: the highest horizon lies east or west along the row
# (exact on the sweep's lines), so a brute force over every pair of cells
# gives it exactly.
python3 - "$work" <<'PY'
import math, random, sys
random.seed(7)
w, h, f, z = 36, 30, [], 0.0
for c in range(w):
    z += random.uniform(-8, 8)
    f.append(round(z, 2))
with open(f"{sys.argv[1]}/dem.asc", "w") as out:
    out.write(f"ncols {w}\nnrows {h}\nxllcorner 0\nyllcorner 0\ncellsize 10\n")
    out.write("".join(" ".join(str(v) for v in f) + "\n" for _ in range(h)))
best = []
for r in range(h):
    for c in range(w):
        best.append(max(math.degrees(math.atan2(f[c2] - f[c], 10 * math.hypot(c2 - c, r2 - r)))
                        for r2 in range(h) for c2 in range(w) if (r2, c2) != (r, c)))
with open(f"{sys.argv[1]}/brute.txt", "w") as out:
    out.write("\n".join(f"{v:.9g}" for v in best) + "\n")
PY
with_toy "$SKYSWEEP" toy -q --directions 8 --curvature off --cell-size 10 "$work/dem.asc" \
    "$work/toy.tif" 2>"$work/err"
rc=$?
gdal_translate -q -of AAIGrid "$work/toy.tif" "$work/toy.asc" 2>/dev/null
worst=$(python3 -c '
import sys
got = [float(v) for line in open(sys.argv[1]).read().splitlines()[6:] for v in line.split()]
want = [float(v) for v in open(sys.argv[2])]
print(max(abs(a - b) for a, b in zip(got, want)) if len(got) == len(want) else "sizes differ")
' "$work/toy.asc" "$work/brute.txt" 2>&1)
[ "$rc" -eq 0 ] && python3 -c "import sys; sys.exit(not float('$worst') < 1e-4)" 2>/dev/null
tap_ok $? "skysweep toy (exit $rc) equals the brute-force highest horizon: worst $worst deg (within 1e-4) $(head -c 200 "$work/err")"
gdalinfo "$work/toy.tif" 2>/dev/null | grep -q "Description = highest horizon" &&
    gdalinfo "$work/toy.tif" | grep -q "Unit Type: deg"
tap_ok $? "its band is named and has its unit as declared"

# The QGIS provider's loader (qgis/skysweep/cli.py, run without QGIS).
with_toy env PYTHONPATH="$top/qgis/skysweep" python3 -c '
import sys, cli
tables, problem = cli.option_tables(sys.argv[1])
t = tables["toy"]
print(t["title"], "|", t["group"], "|", [o["name"] for o in t["outputs"]], "|", problem)
' "$SKYSWEEP" >"$work/qgis" 2>&1
grep -q "^Highest horizon | Terrain | \['toy'\] | None$" "$work/qgis"
tap_ok $? "a QGIS algorithm, skysweep:toy: $(head -c 200 "$work/qgis")"

if ! "$py" -c "import cffi, numpy, wheel" 2>/dev/null; then
    tap_skip "its Python calls" "no venv with cffi, numpy and wheel ($py; tests/run.sh makes it)"
    tap_done
    exit
fi
# The package's option tables come from the CLI it is built with: the toy's too.
# From a copy of python/: pip builds in the folder it is given (build/,
# *.egg-info), and the Python tests, run in parallel, would race there.
# (tar leaves out what other builds write, which cp could find half gone).
tar -C "$top" --exclude=python/build --exclude='python/*.egg-info' -cf - python | tar -C "$work" -xf - &&
    mv "$work/python" "$work/package"
SKYSWEEP_BUILD_DIR=$top with_toy "$py" -m pip install -q --disable-pip-version-check \
    --no-build-isolation --no-deps --target "$work/site" "$work/package" >"$work/pip.log" 2>&1
tap_ok $? "pip installs the package with the toy loaded $(grep -m 3 -i -e 'error' -e 'unable' -e 'asan' "$work/pip.log" | tr '\n' ' ')"
(cd "$work" && PYTHONPATH=$work/site with_toy "$py" - "$work" <<'PY') >"$work/python.out" 2>&1
import sys
import numpy as np
import skysweep
from skysweep._lib import PRODUCTS
rows = open(f"{sys.argv[1]}/dem.asc").read().splitlines()[5:]
dem = np.array([[float(v) for v in row.split()] for row in rows])
want = np.loadtxt(f"{sys.argv[1]}/brute.txt").reshape(dem.shape)
got = skysweep.toy(dem, 10, directions=8, curvature="off")
banded = skysweep.toy(dem, 10, directions=8, curvature="off", memory="1G")
print("PRODUCTS", "toy" in PRODUCTS, "__all__", "toy" in skysweep.__all__,
      "toy_file" in skysweep.__all__, "worst", float(np.abs(got - want).max()),
      "banded", float(np.abs(banded - want).max()))
PY
grep -q "^PRODUCTS True __all__ True True worst [0-9.e-]* banded" "$work/python.out" &&
    python3 -c '
import sys
words = open(sys.argv[1]).read().split()
sys.exit(not (float(words[words.index("worst") + 1]) < 1e-4 and float(words[words.index("banded") + 1]) < 1e-4))
' "$work/python.out"
tap_ok $? "Python: skysweep._lib.PRODUCTS, skysweep.toy and toy_file, equal to the brute force, whole and within memory=: $(tail -n 1 "$work/python.out" | head -c 300)"
tap_done
