"""Shared helpers: DEMs, and the command line run on ESRI ASCII grids (which
Python writes without GDAL) into ENVI rasters (which it reads without GDAL)."""
import pathlib
import subprocess

import numpy as np
import pytest

import skysweep
from skysweep.files import command_line


def rough_dem(rows=48, cols=56, seed=1, hole=True):
    """Rough terrain in metres, some hundreds of metres of relief at 10 m
    cells, with a nodata hole."""
    rng = np.random.default_rng(seed)
    z = np.cumsum(np.cumsum(rng.normal(size=(rows, cols)), 0), 1) * 2.0 + 1234.5
    if hole:
        z[10:13, 20:24] = np.nan
    # GDAL reads an ASCII grid with decimals as Float32: heights it can hold
    # exactly reach the CLI as they reach the array calls.
    return z.astype(np.float32).astype(np.float64)


def write_asc(path, z, cell=10.0, prj=None, centred=False):
    """An ESRI ASCII grid; prj (WKT) goes beside it as its CRS, and centred
    puts the grid's centre on the CRS's origin."""
    x0, y0 = (-z.shape[1] * cell / 2, -z.shape[0] * cell / 2) if centred else (0.0, 0.0)
    with open(path, "w") as f:
        f.write(f"ncols {z.shape[1]}\nnrows {z.shape[0]}\nxllcorner {x0!r}\nyllcorner {y0!r}\n"
                f"cellsize {cell!r}\nNODATA_value -9999\n")
        for row in z:
            f.write(" ".join("-9999" if np.isnan(v) else repr(float(v)) for v in row) + "\n")
    if prj:
        pathlib.Path(path).with_suffix(".prj").write_text(prj)
    return path


def read_envi(path):
    """All bands of an ENVI raster (float32, band-sequential), nodata as NaN."""
    path = pathlib.Path(path)
    header = {}
    for line in path.with_suffix(".hdr").read_text().splitlines():
        if "=" in line:
            key, value = line.split("=", 1)
            header[key.strip()] = value.strip()
    types = {"1": "u1", "2": "i2", "4": "f4", "5": "f8", "12": "u2"}
    assert header.get("interleave", "bsq") == "bsq"
    order = ">" if header.get("byte order") == "1" else "<"
    shape = (int(header["bands"]), int(header["lines"]), int(header["samples"]))
    data = np.fromfile(path, dtype=order + types[header["data type"]]).reshape(shape)
    data = data.astype(np.float32)
    nodata = header.get("data ignore value", "-9999")
    data[data == np.float32(nodata)] = np.nan
    return data


@pytest.fixture
def cli_run(tmp_path):
    """cli_run(command, dem, *options) -> the bands the CLI writes for dem
    (10 m cells; no CRS unless prj gives one), read back."""
    def run(command, z, *options, cell=10.0, prj=None, centred=False):
        dem = write_asc(tmp_path / "dem.asc", z, cell, prj, centred)
        out = tmp_path / f"{command}.envi"
        place = [] if prj else ["--cell-size", repr(cell)]
        proc = subprocess.run([command_line(), command, "-q", "-of", "ENVI", *place,
                               *map(str, options), str(dem), str(out)],
                              capture_output=True, text=True)
        assert proc.returncode == 0, proc.stderr
        return read_envi(out)
    return run


def same(a, b):
    """Equal cell for cell, NaN where the other is NaN."""
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape
    assert np.array_equal(np.isnan(a), np.isnan(b))
    assert np.array_equal(a[~np.isnan(a)], b[~np.isnan(b)]), \
        f"max difference {np.nanmax(np.abs(a - b))}"
    return True
