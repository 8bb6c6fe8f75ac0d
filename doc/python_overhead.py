"""What the Python package costs on top of the library and the CLI, on the
sample DEM (512 x 643 cells of 30 m): medians of repeated runs, the CLI's
whole process beside the array and file calls. Run with the test venv's
Python where the package is installed:

    tests/pyvenv/bin/python doc/python_overhead.py [REPEATS]

Needs gdal_translate (gdal-bin) to hand the sample's heights to numpy.
Prints a Markdown table (doc/python.md, "Overhead")."""
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import skysweep
from skysweep._context import context
from skysweep._lib import lib
from skysweep.files import command_line

TOP = pathlib.Path(__file__).resolve().parent.parent
SAMPLE = TOP / "samples" / "kilauea_summit_30m.tif"
REPEATS = int(sys.argv[1]) if len(sys.argv) > 1 else 7


def median_time(fn):
    times = []
    for _ in range(REPEATS):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def sweep_seconds(device):
    return lib.ss_ctx_counters(context(device).ptr).sweep_seconds


with tempfile.TemporaryDirectory() as tmp:
    raw = pathlib.Path(tmp, "dem.envi")
    subprocess.run(["gdal_translate", "-q", "-of", "ENVI", "-ot", "Float64", str(SAMPLE),
                    str(raw)], check=True)
    dem = np.fromfile(raw, "<f8").reshape(643, 512)
    dem[dem == -32768] = np.nan
    out = pathlib.Path(tmp, "svf.tif")
    rows = []
    for device, label in ((None, "PoCL"), ("reference", "C twin")):
        first = time.perf_counter()
        skysweep.svf(dem, 30, directions=16, device=device)
        first = time.perf_counter() - first
        before = sweep_seconds(device)
        array_call = median_time(lambda: skysweep.svf(dem, 30, directions=16, device=device))
        sweep = (sweep_seconds(device) - before) / REPEATS
        cli_args = [command_line(), "svf", "-q", "--directions", "16", str(SAMPLE), str(out)]
        if device:
            cli_args[2:2] = ["--device", device]
        cli = median_time(lambda: subprocess.run(cli_args, check=True))
        file_call = median_time(lambda: skysweep.svf_file(SAMPLE, out, directions=16,
                                                          device=device))
        rows.append((label, first, array_call, sweep, cli, file_call))
    print(f"`svf --directions 16` on the sample DEM (512 x 643), medians of {REPEATS}:\n")
    print("| device | first array call (context set-up) | array call | of which sweeps | "
          "CLI whole process | file call |")
    print("|---|---|---|---|---|---|")
    for label, first, array_call, sweep, cli, file_call in rows:
        print(f"| {label} | {first:.3f} s | {array_call:.3f} s | {sweep:.3f} s | {cli:.3f} s | "
              f"{file_call:.3f} s |")
