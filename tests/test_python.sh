#!/bin/bash
# The Python package (python/, doc/python.md): pip installs it from the
# source tree, pytest runs its tests (one TAP line each: array calls equal
# the CLI's files cell for cell, closed forms, pvlib's sun, errors, progress,
# Ctrl-C, the GIL), and the README's "From Python" example runs.
set -u
. "${TOP_SRCDIR:-.}/tests/tap.sh"
top=$(realpath "${TOP_SRCDIR:-.}")
py=${SKYSWEEP_PVLIB_PYTHON:-$top/tests/pyvenv/bin/python}
work=$(mktemp -d "${TMPDIR:-/tmp}/ss-python.XXXXXX")
trap 'rm -rf "$work"' EXIT

if ! "$py" -c "import cffi, numpy, pytest, wheel" 2>/dev/null; then
    tap_skip "the Python package" "no venv with cffi, numpy, pytest and wheel ($py; tests/run.sh makes it)"
    tap_done
    exit
fi
# A library built with the sanitizers needs their runtime loaded first.
preload=""
if ldd "$top/.libs/libskysweep.so.0" | grep -q libasan; then
    preload="$(gcc -print-file-name=libasan.so) $(gcc -print-file-name=libubsan.so)"
fi
# No alternate signal stack per thread: on a Firecracker VM's kernel (6.18)
# AddressSanitizer could not unmap one when a PoCL thread ended inside the
# long-lived pytest process, and aborted it ("unable to unmap"; 8f2033f
# too, so not the library's doing).
export ASAN_OPTIONS=detect_leaks=0:use_sigaltstack=0:${ASAN_OPTIONS:-}

# Installed into a folder of its own, so that the venv stays as run.sh made it.
# From a copy of python/: pip builds in the folder it is given (build/,
# *.egg-info), and the Python tests, run in parallel, would race there.
# (tar leaves out what other builds write, which cp could find half gone).
tar -C "$top" --exclude=python/build --exclude='python/*.egg-info' -cf - python | tar -C "$work" -xf - &&
    mv "$work/python" "$work/package"
SKYSWEEP_BUILD_DIR=$top "$py" -m pip install -q --disable-pip-version-check --no-build-isolation \
    --no-deps --target "$work/site" "$work/package" >"$work/pip.log" 2>&1
tap_ok $? "pip installs the package from the source tree $(tail -n 3 "$work/pip.log" | tr '\n' ' ')"

(cd "$work" && LD_PRELOAD=$preload PYTHONPATH=$work/site "$py" -m pytest -p no:cacheprovider \
    -q -rA "$top/python/tests" >"$work/pytest.out" 2>&1)
n=0
while read -r outcome name rest; do
    n=$((n + 1))
    case $outcome in
    PASSED) tap_ok 0 "pytest ${name#*python/tests/}" ;;
    SKIPPED) tap_skip "pytest $name $rest" "skipped by pytest" ;;
    *) tap_ok 1 "pytest $outcome ${name#*python/tests/} $rest" ;;
    esac
done < <(grep -E '^(PASSED|FAILED|ERROR|SKIPPED) ' "$work/pytest.out")
[ "$n" -gt 0 ] && ! grep -qE '^(FAILED|ERROR) ' "$work/pytest.out"
tap_ok $? "pytest ran $n tests: $(tail -n 1 "$work/pytest.out")"
[ "$n" -gt 0 ] || tail -n 20 "$work/pytest.out" | sed 's/^/# /'

# The README's example, as a reader would run it beside the samples.
sed -n '/^<!-- python-example -->$/,/^```$/p' "$top/README.md" | sed '1,2d;$d' >"$work/example.py"
ln -s "$top/samples" "$work/samples"
(cd "$work" && LD_PRELOAD=$preload PYTHONPATH=$work/site "$py" example.py) >"$work/example.out" 2>&1
rc=$?
[ "$rc" -eq 0 ] && [ -s "$work/example.py" ] && grep -q "sky-view factor" "$work/example.out" &&
    [ -s "$work/kilauea_svf.tif" ]
tap_ok $? "the README's Python example runs (exit $rc): $(tail -n 2 "$work/example.out" | tr '\n' ' ')"
tap_done
