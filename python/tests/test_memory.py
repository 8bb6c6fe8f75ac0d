"""memory=: array calls in bands within a budget (doc/python.md, "Memory").

Results in bands equal the whole-grid call's (within tests/test_banded*.c's
tolerances: float sums over directions in another order), a budget too small
for one band raises OutOfMemory naming the least that would do, and the peak
resident memory of a call on a DEM several times the budget stays within the
process's memory before the call, plus the result, plus the budget."""
import os
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import skysweep
import skysweep._memory as memory_module
from skysweep._memory import parse_size

from conftest import rough_dem

MIB = 1048576

#: A tall, narrow DEM: a band costs less than the whole grid there (the
#: hulls handed on between bands cost per column), so small budgets band it.
TALL = rough_dem(4000, 60, seed=5)
#: Interpolated lines given: with memory= the DEM is not searched for walls,
#: as the command line's DEM read in bands is not (rough_dem's steps look
#: like walls to the planner, which would take box lines for the whole grid).
SWEEP = {"device": "reference", "directions": 4, "lines": "interpolated"}
BOX = dict(SWEEP, lines="box")
SUN = {"time": "2026-06-21T00:00Z/P1D", "step": "PT3H", "latitude": 46.0, "longitude": 14.0}

#: Each call with memory=, and the largest difference allowed from its
#: whole-grid result (tests/test_banded.c: 2e-6 for SVF, 2e-4 degrees for
#: openness; 0 where every cell's value comes from one walk).
CALLS = {
    "svf": (lambda **kw: skysweep.svf(TALL, 10.0, **SWEEP, **kw), 2e-6),
    "svf within a radius": (
        lambda **kw: skysweep.svf(TALL, 10.0, radius=150.0, definition="horizontal", **SWEEP,
                                  **kw), 2e-6),
    "openness": (lambda **kw: skysweep.openness(TALL, 10.0, kind="negative", **SWEEP, **kw),
                 2e-4),
    "horizon": (lambda **kw: skysweep.horizon(TALL, 10.0, distance=True, cast_height=True,
                                              **SWEEP, **kw), 0.0),
    "shadow": (lambda **kw: skysweep.shadow(TALL, 10.0, sun_azimuth=200.0, sun_elevation=12.0,
                                            **SWEEP, **kw), 0.0),
    "hillshade with cast shadows": (
        lambda **kw: skysweep.hillshade(TALL, 10.0, cast_shadows=True, sky_view=0.3, **SWEEP,
                                        **kw), 2e-4),
    "vat": (lambda **kw: skysweep.vat(TALL, 10.0, radius=100.0, **SWEEP, **kw), 2e-6),
    "insolation": (lambda **kw: skysweep.insolation(TALL, 10.0, **SUN, **SWEEP, **kw), 2e-3),
    # Box lines' cast shadows by each cell's own ray: in bands from the
    # heights held whole (counted), the whole grid's shadows exactly;
    # insolation's then hand on only its sky view's hulls (counted so).
    "shadow on box lines": (
        lambda **kw: skysweep.shadow(TALL, 10.0, sun_azimuth=200.0, sun_elevation=12.0,
                                     **BOX, **kw), 0.0),
    "insolation on box lines": (
        lambda **kw: skysweep.insolation(TALL, 10.0, **SUN, **BOX, **kw), 2e-3),
    # The box model's sky view by each cell's own ray: in bands from the
    # heights held whole (counted), the whole grid's exactly, the radiative
    # SVF's slopes from the rows around each band included.
    "svf on box lines": (
        lambda **kw: skysweep.svf(TALL, 10.0, definition="radiative", **BOX, **kw), 0.0),
    "openness on box lines": (
        lambda **kw: skysweep.openness(TALL, 10.0, kind="negative", **BOX, **kw), 0.0),
}


def planes(result):
    """A call's result as a list of float arrays."""
    if isinstance(result, dict):
        return [result[k] for k in sorted(result)]
    if isinstance(result, tuple):  # Horizons: the cubes, not the azimuths
        return [r for r in result[1:] if r is not None]
    return [result]


# AddressSanitizer's shadow memory and quarantine inflate the process and
# make it grow from call to call (tests/test_python.sh preloads it for a
# sanitizer build): budgets at the edge of the least one named, and peaks,
# are not measured there.
UNDER_ASAN = pytest.mark.skipif("libasan" in os.environ.get("LD_PRELOAD", ""),
                                reason="AddressSanitizer inflates the process's memory")


def least_memory(call):
    """The least memory= (MiB) the refusal of a 1000-byte budget names."""
    with pytest.raises(skysweep.OutOfMemory) as refused:
        call(memory=1000)
    found = re.search(r"at least memory='(\d+)M'", str(refused.value))
    assert found, str(refused.value)
    return int(found.group(1))


@pytest.mark.parametrize("size, expected", [
    ("512M", 512 * MIB), ("4G", 4 * 1024 * MIB), ("1.5k", 1536.0), ("2T", 2 * 1024 ** 4),
    ("123456", 123456.0), (" 64M ", 64 * MIB), (1000, 1000.0), (2.5e9, 2.5e9),
    (np.int64(4096), 4096.0)])
def test_memory_takes_the_clis_sizes_and_bytes(size, expected):
    assert parse_size(size) == expected


@pytest.mark.parametrize("size", ["", "M", "12X", "12MB", "4 G", "-1G", "0", 0, -5, float("inf"),
                                  float("nan")])
def test_memory_refuses_what_is_not_a_size(size):
    with pytest.raises(skysweep.ArgumentError, match="memory expects"):
        parse_size(size)


@pytest.mark.parametrize("size", [True, None, [512], b"512M"])
def test_memory_of_another_type_is_a_type_error(size):
    with pytest.raises(TypeError, match="memory must be"):
        parse_size(size)


def test_a_bad_size_is_refused_by_the_call():
    with pytest.raises(skysweep.ArgumentError, match="memory expects"):
        skysweep.svf(TALL, 10.0, memory="lots", **SWEEP)


def test_calls_that_do_not_sweep_take_no_memory():
    with pytest.raises(TypeError, match="unexpected keyword"):
        skysweep.plan(TALL, 10.0, memory="1G")


@UNDER_ASAN
@pytest.mark.parametrize("name", sorted(CALLS))
def test_bands_equal_the_whole_grid(name, monkeypatch):
    call, tolerance = CALLS[name]
    whole = planes(call())
    least = least_memory(call)
    planned = []
    plan_bands = memory_module.plan_bands
    monkeypatch.setattr(memory_module, "plan_bands",
                        lambda *a: planned.append(plan_bands(*a)) or planned[-1])
    banded = planes(call(memory=f"{least + 1}M"))
    assert planned and 0 < planned[0] < TALL.shape[0], f"not run in bands: {planned}"
    for w, b in zip(whole, banded, strict=True):
        assert w.shape == b.shape and w.dtype == b.dtype
        np.testing.assert_array_equal(np.isnan(w), np.isnan(b))
        np.testing.assert_allclose(b, w, rtol=0, atol=tolerance, equal_nan=True)


@UNDER_ASAN
def test_the_least_budget_named_would_do():
    call = CALLS["svf"][0]
    least = least_memory(call)
    assert least > 16  # the planner's fixed 16 MiB and a band
    # The budget named is the least rounded up and 1 MiB more (what the
    # process holds moves from call to call): 3 MiB less is below it.
    with pytest.raises(skysweep.OutOfMemory) as refused:
        call(memory=f"{least - 3}M")
    assert isinstance(refused.value, MemoryError) and refused.value.status == 6
    assert "is too small for this DEM and call" in str(refused.value)
    assert call(memory=f"{least}M").shape == TALL.shape


def test_a_budget_the_whole_grid_fits_runs_it_whole(monkeypatch):
    planned = []
    plan_bands = memory_module.plan_bands
    monkeypatch.setattr(memory_module, "plan_bands",
                        lambda *a: planned.append(plan_bands(*a)) or planned[-1])
    call = CALLS["svf"][0]
    assert np.array_equal(call(memory="1G"), call(), equal_nan=True)
    assert planned == [0]


@UNDER_ASAN
def test_masked_and_nodata_cells_read_in_bands_as_whole():
    z = TALL.copy()
    z[100:140, 10:30] = -32768.0
    masked = np.ma.masked_array(z, mask=np.zeros(z.shape, bool))
    masked.mask[500:520, :] = True
    whole = skysweep.svf(masked, 10.0, nodata=-32768.0, **SWEEP)
    banded = skysweep.svf(masked, 10.0, nodata=-32768.0, memory="18M", **SWEEP)
    assert np.isnan(banded[510, 5]) and np.isnan(banded[120, 20])
    np.testing.assert_array_equal(np.isnan(banded), np.isnan(whole))
    np.testing.assert_allclose(banded, whole, rtol=0, atol=CALLS["svf"][1], equal_nan=True)


#: The peak-memory check, in a process of its own: a float64 DEM of
#: 1000 x 12000 (96 MiB, four times the 24 MiB budget), filled in place a
#: few rows at a time so that making it leaves no peak of its own. The rule
#: checked: peak resident (after the call) <= resident before the call
#: (interpreter, numpy, skysweep, the DEM) + the result's bytes (a float32
#: plane, written as bands finish) + memory=. The peak is the kernel's
#: VmHWM (/proc/self/status), which getrusage's ru_maxrss reports for a
#: process started on its own; in a child of pytest, Linux's ru_maxrss
#: also keeps the parent's resident size at the fork (285 MB measured under
#: the whole suite), which is not this process's. The whole-grid call would
#: hold a float64 and a float32 copy of the DEM and 24 bytes a cell
#: besides: about 430 MiB more.
PEAK_SCRIPT = textwrap.dedent("""
    import numpy as np
    import skysweep
    from skysweep._memory import resident_bytes
    rows, cols, budget = 12000, 1000, 24 * 1048576
    dem = np.empty((rows, cols))
    x = np.arange(cols) * 0.02
    for r in range(0, rows, 50):  # small temporaries: no peak of their own
        np.multiply(np.sin(x)[None, :], np.cos(np.arange(r, r + 50) * 0.013)[:, None],
                    out=dem[r:r + 50])
        dem[r:r + 50] *= 150
        dem[r:r + 50] += 800 + 0.7 * (r % 7)
    def peak_resident():
        with open("/proc/self/status") as f:
            return next(int(l.split()[1]) * 1024 for l in f if l.startswith("VmHWM:"))
    before = resident_bytes()
    peak_before = peak_resident()
    out = skysweep.svf(dem, 10.0, device="reference", directions=4, lines="interpolated",
                       memory=budget)
    peak = peak_resident()
    print(before, peak_before, peak, out.nbytes, budget, float(np.nanmean(out)))
""")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="VmHWM: Linux's /proc")
@UNDER_ASAN
def test_peak_resident_memory_stays_within_the_budget():
    done = subprocess.run([sys.executable, "-c", PEAK_SCRIPT], capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    before, peak_before, peak, result, budget, mean = (float(v) for v in done.stdout.split())
    assert 96 * MIB >= 4 * budget  # the DEM is four times the budget
    assert peak_before <= before + 8 * MIB, "making the DEM left a peak of its own"
    assert 0 < mean <= 1
    assert peak <= before + result + budget, (
        f"peak {peak / MIB:.1f} MiB > {before / MIB:.1f} before + {result / MIB:.1f} result + "
        f"{budget / MIB:.1f} budget")


@UNDER_ASAN
def test_a_dataarray_with_rising_y_runs_in_bands_as_whole():
    xr = pytest.importorskip("xarray")
    rows, cols = TALL.shape
    da = xr.DataArray(TALL[::-1], dims=("y", "x"),
                      coords={"y": np.arange(rows) * 10.0, "x": np.arange(cols) * 10.0})
    whole = skysweep.svf(da, **SWEEP)
    banded = skysweep.svf(da, memory="18M", **SWEEP)
    assert banded.dims == whole.dims and banded.attrs == whole.attrs
    np.testing.assert_allclose(banded.values, whole.values, rtol=0, atol=CALLS["svf"][1],
                               equal_nan=True)


@pytest.mark.parametrize("dem, cell", [
    (TALL, 1e9),                      # cells beyond the library's sizes
    (TALL[:1, :1], 10.0),             # one cell: no horizon
    (np.full((300, 40), np.nan), 10.0),  # no valid height
    # Heights 2e7 m apart, the far one in a later chunk of rows than the first.
    (np.where(np.arange(40) == 7, 1e7, 4.0) * np.where(np.arange(3000) < 2000, 1, -1)[:, None],
     10.0),
])
def test_a_dem_read_in_bands_is_refused_as_whole(dem, cell):
    with pytest.raises(skysweep.InputError) as whole:
        skysweep.svf(dem, cell, **SWEEP)
    with pytest.raises(skysweep.InputError) as banded:
        skysweep.svf(dem, cell, memory="1G", **SWEEP)
    assert str(banded.value) == str(whole.value)


#: The same rule for a DEM in a file that rasterio or rioxarray opened: the
#: heights are read a window of rows at a time through the band source, and
#: rasterio's GDAL block cache is capped (16 MiB, counted by the plan), so the
#: budget bounds the read too. Before, the dataset was read whole first (a
#: float64 copy of 183 MiB: memory='80M' was refused), and a DataArray's
#: result was copied by rioxarray's write_crs. A GeoTIFF of 16000 x 1500
#: float64, written a strip at a time in the test's own process; opened in
#: the child after its resident memory is measured (opening reads no heights).
FILE_PEAK_SCRIPT = textwrap.dedent("""
    import sys
    import numpy as np
    import rasterio
    import skysweep
    from skysweep._memory import resident_bytes
    path, how, budget = sys.argv[1], sys.argv[2], 80 * 1048576
    def peak_resident():
        with open("/proc/self/status") as f:
            return next(int(l.split()[1]) * 1024 for l in f if l.startswith("VmHWM:"))
    if how == "rioxarray":
        import rioxarray
    before = resident_bytes()
    peak_before = peak_resident()
    if how == "rioxarray":
        dem = rioxarray.open_rasterio(path).squeeze("band", drop=True)
    else:
        dem = rasterio.open(path)
    out = skysweep.svf(dem, device="reference", directions=4, lines="interpolated",
                       memory=budget)
    peak = peak_resident()
    lazy = how != "rioxarray" or not dem.variable._in_memory
    print(before, peak_before, peak, out.nbytes, budget, float(np.nanmean(out)), int(lazy))
""")


def write_tall_geotiff(path, rows=16000, cols=1500):
    rasterio = pytest.importorskip("rasterio")
    from rasterio.transform import from_origin
    x = np.arange(cols) * 0.02
    with rasterio.open(path, "w", driver="GTiff", width=cols, height=rows, count=1,
                       dtype="float64", crs="EPSG:32633", nodata=-9999.0,
                       transform=from_origin(500000.0, 5200000.0, 10.0, 10.0)) as dataset:
        for r in range(0, rows, 200):
            strip = np.sin(x)[None, :] * np.cos(np.arange(r, r + 200) * 0.013)[:, None] * 150
            dataset.write(strip + 800 + 0.7 * (r % 7), 1,
                          window=((r, r + 200), (0, cols)))
    return path


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="VmHWM: Linux's /proc")
@UNDER_ASAN
@pytest.mark.parametrize("how", ["rasterio", "rioxarray"])
def test_a_file_dataset_is_read_in_bands_within_the_budget(tmp_path, how):
    if how == "rioxarray":
        pytest.importorskip("rioxarray")
    path = write_tall_geotiff(tmp_path / "tall.tif")
    done = subprocess.run([sys.executable, "-c", FILE_PEAK_SCRIPT, str(path), how],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    before, peak_before, peak, result, budget, mean, lazy = (
        float(v) for v in done.stdout.split())
    assert 16000 * 1500 * 8 >= 2 * budget  # the DEM's heights are more than twice the budget
    assert 0 < mean <= 1 and lazy, "the DataArray was loaded whole"
    assert peak <= before + result + budget, (
        f"peak {peak / MIB:.1f} MiB > {before / MIB:.1f} before + {result / MIB:.1f} result + "
        f"{budget / MIB:.1f} budget")


@UNDER_ASAN
@pytest.mark.parametrize("how", ["rasterio", "rioxarray"])
def test_a_file_dataset_read_in_windows_equals_the_whole_read(tmp_path, how, monkeypatch):
    rasterio = pytest.importorskip("rasterio")
    if how == "rioxarray":
        pytest.importorskip("rioxarray")
    from rasterio.transform import from_origin
    z = TALL.astype(np.float32)
    z[700:720, 10:30] = -9999.0  # the file's nodata
    path = tmp_path / "tall.tif"
    with rasterio.open(path, "w", driver="GTiff", width=z.shape[1], height=z.shape[0], count=1,
                       dtype="float32", crs="EPSG:32633", nodata=-9999.0,
                       transform=from_origin(500000.0, 5200000.0, 10.0, 10.0)) as dataset:
        dataset.write(z, 1)

    def call(**kw):
        if how == "rioxarray":
            import rioxarray
            dem = rioxarray.open_rasterio(path).squeeze("band", drop=True)
            return dem, skysweep.svf(dem, **SWEEP, **kw)
        with rasterio.open(path) as dem:
            return dem, skysweep.svf(dem, **SWEEP, **kw)

    _, whole = call()  # first: GDAL's set-up in the process is not the banded call's
    least = least_memory(call)
    planned = []
    plan_bands = memory_module.plan_bands
    monkeypatch.setattr(memory_module, "plan_bands",
                        lambda *a: planned.append(plan_bands(*a)) or planned[-1])
    dem, banded = call(memory=f"{least + 1}M")
    assert planned and 0 < planned[0] < z.shape[0], f"not run in bands: {planned} at {least + 1}M"
    if how == "rioxarray":
        assert not dem.variable._in_memory  # read a window at a time, never whole
    assert np.isnan(np.asarray(banded)[710, 20])
    np.testing.assert_allclose(np.asarray(banded), np.asarray(whole), rtol=0,
                               atol=CALLS["svf"][1], equal_nan=True)
