"""Errors, progress, cancellation, Ctrl-C and the GIL."""
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import skysweep
from conftest import rough_dem


@pytest.mark.parametrize("dem, error, words", [
    (np.full((20, 20), np.nan), skysweep.InputError, "no valid heights"),
    (np.ones((1, 1)), skysweep.InputError, "single cell"),
    (np.ones((5, 5), dtype=complex), TypeError, "real numbers"),
    (np.array([["a", "b"], ["c", "d"]]), TypeError, "real numbers"),
    (np.ones((3, 4, 5)), ValueError, "2-D"),
    (np.ones(7), ValueError, "2-D"),
])
def test_bad_arrays_raise_clear_errors(dem, error, words):
    with pytest.raises(error, match=words):
        skysweep.svf(dem, 10)


def test_bad_parameters_raise_what_the_cli_says():
    z = rough_dem()
    with pytest.raises(skysweep.ArgumentError, match="--directions") as e:
        skysweep.svf(z, 10, directions=0)
    assert e.value.status == 2
    with pytest.raises(skysweep.ArgumentError, match="geometric, radiative, horizontal"):
        skysweep.svf(z, 10, definition="bogus")
    with pytest.raises(TypeError, match="unexpected"):
        skysweep.svf(z, 10, directoins=8)
    with pytest.raises(ValueError, match="positive"):
        skysweep.svf(z, -10)
    with pytest.raises(TypeError, match="cell_size"):
        skysweep.svf(z)


def test_progress_reaches_the_end_and_can_cancel():
    z = rough_dem()
    seen = []
    skysweep.svf(z, 10, directions=16, progress=lambda f, m: seen.append(f))
    assert seen and seen[-1] == pytest.approx(1.0) and seen == sorted(seen)
    with pytest.raises(skysweep.Cancelled):
        skysweep.svf(z, 10, directions=16, progress=lambda f, m: f < 0.3)
    # The context stays usable after a cancelled call.
    assert np.nanmean(skysweep.svf(z, 10, directions=16)) > 0


def test_an_exception_in_the_progress_callback_reaches_the_caller():
    def broken(f, m):
        raise RuntimeError("from the callback")
    with pytest.raises(RuntimeError, match="from the callback"):
        skysweep.svf(rough_dem(), 10, directions=8, progress=broken)


def test_the_gil_is_released_during_a_call():
    z = rough_dem(400, 400, hole=False)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.002)

    counter = threading.Thread(target=count)
    counter.start()
    start = time.perf_counter()
    skysweep.svf(z, 10, directions=256, lines="interpolated", device="reference")
    end = time.perf_counter()
    done.set()
    counter.join()
    during = [t for t in ticks if start < t < end]
    # A held GIL would let the counter run only at the call's edges.
    assert end - start > 0.2 and len(during) > 0.3 * (end - start) / 0.002


def test_ctrl_c_stops_a_long_call_within_a_second(tmp_path):
    script = tmp_path / "long.py"
    script.write_text(textwrap.dedent("""
        import signal, sys, numpy as np, skysweep
        # Ctrl-C as an interactive Python takes it, even where the test
        # runs with SIGINT ignored (a background job of a script does).
        signal.signal(signal.SIGINT, signal.default_int_handler)
        z = np.random.default_rng(0).normal(size=(900, 900)).cumsum(0).cumsum(1)
        print("started", flush=True)
        try:
            skysweep.svf(z, 10, directions=4000, device="reference")
        except KeyboardInterrupt:
            # The library call has really ended: no worker left, and the
            # context serves the next call.
            import threading
            alone = threading.active_count() == 1
            skysweep.svf(z[:50, :50], 10, directions=4, device="reference")
            print("interrupted" if alone else "worker still running", flush=True)
            sys.exit(42)
        print("finished", flush=True)
    """))
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "started"
        time.sleep(1.0)
        sent = time.perf_counter()
        proc.send_signal(signal.SIGINT)
        rc = proc.wait(timeout=30)
        took = time.perf_counter() - sent
    finally:
        proc.kill()  # a run that missed the signal must not outlive the test
    assert rc == 42 and proc.stdout.read().strip() == "interrupted"
    assert took < 1.5, f"stopped {took:.2f} s after Ctrl-C"
