"""How each kind of input is read (doc/python.md): masked arrays, the nodata
and CRS of xarray and rioxarray, implausible fills, and a rioxarray round
trip that writes what the command line writes."""
import pathlib
import warnings

import numpy as np
import pytest

import skysweep
from conftest import rough_dem, same

SAMPLES = pathlib.Path(__file__).resolve().parents[2] / "samples"
#: Transverse Mercator at 45 N, 8 E (metres), as test_insolation uses it.
TM = ("+proj=tmerc +lat_0=45 +lon_0=8 +k=1 +x_0=0 +y_0=0 +ellps=WGS84 +units=m +no_defs")

#: Each array call, on a DEM and its cell size.
CALLS = {
    "svf": lambda d, c: skysweep.svf(d, c, directions=8),
    "openness": lambda d, c: skysweep.openness(d, c, directions=8),
    "horizon": lambda d, c: skysweep.horizon(d, c, directions=4).elevation[0],
    "shadow": lambda d, c: skysweep.shadow(d, c, sun_azimuth=200, sun_elevation=20),
    "hillshade": lambda d, c: skysweep.hillshade(d, c),
    "vat": lambda d, c: skysweep.vat(d, c, directions=8),
    "sun_incidence": lambda d, c: skysweep.sun_incidence(d, c, sun_azimuth=200,
                                                         sun_elevation=20),
    "insolation": lambda d, c: skysweep.insolation(
        d, c, time="2026-06-21T10:00Z/PT2H", step="PT1H", latitude=45, longitude=8,
        directions=8)["poa_global"],
}


def int16_dem(fill=-9999):
    """Rough terrain as int16 metres, with a hole of `fill`."""
    z = np.rint(rough_dem(hole=False)).astype(np.int16)
    z[10:13, 20:24] = fill
    return z


def no_warnings():
    return warnings.catch_warnings(record=True)


@pytest.mark.parametrize("call", sorted(CALLS))
def test_a_masked_array_masks_its_cells(call):
    z = int16_dem(fill=-32768)
    holes = z == -32768
    with no_warnings() as seen:
        warnings.simplefilter("always")
        out = np.asarray(CALLS[call](np.ma.masked_equal(z, -32768), 10))
    assert not seen, [str(w.message) for w in seen]  # masked: declared, not guessed
    assert np.isnan(out[holes]).all()
    assert same(out, CALLS[call](np.where(holes, np.nan, z.astype(np.float64)), 10))
    # Masked cells of plausible heights are nodata too.
    some = np.zeros(z.shape, bool)
    some[30:33, 5:9] = True
    plain = z.astype(np.float64)
    assert np.isnan(np.asarray(CALLS[call](np.ma.masked_array(plain, some), 10))[some]).all()


def test_a_dataarray_s_declared_nodata_is_nodata():
    """rioxarray's nodata, a CF _FillValue in attrs and one in encoding:
    each is nodata for an int16 DEM read without masked=True."""
    xr = pytest.importorskip("xarray")
    z = int16_dem()
    expect = skysweep.svf(np.where(z == -9999, np.nan, z.astype(np.float64)), 10, directions=8)
    coords = {"y": 5000 - np.arange(z.shape[0]) * 10.0, "x": np.arange(z.shape[1]) * 10.0}
    by_attrs = xr.DataArray(z, dims=("y", "x"), coords=coords, attrs={"_FillValue": -9999})
    by_encoding = xr.DataArray(z, dims=("y", "x"), coords=coords)
    by_encoding.encoding["_FillValue"] = np.int16(-9999)
    for da in (by_attrs, by_encoding):
        assert same(skysweep.svf(da, directions=8).values, expect)


def write_tif(path, z, crs, nodata, cell=10.0):
    rasterio = pytest.importorskip("rasterio")
    h, w = z.shape
    with rasterio.open(path, "w", driver="GTiff", width=w, height=h, count=1, dtype=z.dtype,
                       crs=crs, nodata=nodata,
                       transform=rasterio.Affine(cell, 0, -w * cell / 2, 0, -cell,
                                                 h * cell / 2)) as ds:
        ds.write(z, 1)
    return path


def test_rioxarray_nodata_of_an_int16_dem_is_nodata(tmp_path):
    rioxarray = pytest.importorskip("rioxarray")
    z = int16_dem()
    path = write_tif(tmp_path / "dem.tif", z, TM, -9999)
    da = rioxarray.open_rasterio(path).squeeze("band", drop=True)
    assert da.dtype == np.int16 and da.rio.nodata == -9999
    out = skysweep.svf(da, directions=8)
    assert np.isnan(out.values[z == -9999]).all() and np.isfinite(out.values[z != -9999]).all()
    skysweep.svf_file(path, tmp_path / "svf.tif", directions=8)
    with rioxarray.open_rasterio(tmp_path / "svf.tif", masked=True) as theirs:
        assert same(out.values, theirs.values[0])


def test_a_dataarray_without_coordinates_needs_a_cell_size():
    xr = pytest.importorskip("xarray")
    da = xr.DataArray(rough_dem(30, 20), dims=("y", "x"))
    with pytest.raises(TypeError, match="cell_size is needed"):
        skysweep.horizon(da, directions=4)
    # The caller's cell size is the caller's word.
    assert np.isfinite(skysweep.horizon(da, 10.0, directions=4).elevation.values).any()


def test_a_geographic_dataarray_is_refused_not_taken_as_metres():
    rioxarray = pytest.importorskip("rioxarray")
    da = rioxarray.open_rasterio(SAMPLES / "oetztal_srtm3_crop.tif").squeeze("band", drop=True)
    with pytest.raises(ValueError, match=r"EPSG:4326.*geographic.*svf_file"):
        skysweep.svf(da, directions=8)
    # Cell sizes the caller gives are the caller's word.
    assert np.isfinite(skysweep.svf(da[:40, :40], (66.0, 92.0), directions=8).values).any()


def test_the_product_has_its_own_attributes():
    rioxarray = pytest.importorskip("rioxarray")
    dem = rioxarray.open_rasterio(SAMPLES / "kilauea_summit_30m.tif",
                                  masked=True).squeeze("band", drop=True)[:60, :60]
    assert dem.attrs["long_name"] == "z" and "actual_range" in dem.attrs
    out = skysweep.svf(dem, directions=8)
    assert out.attrs["long_name"] == "sky-view factor" and out.attrs["units"] == "1"
    assert "actual_range" not in out.attrs and "_FillValue" not in out.attrs
    assert np.isnan(out.rio.nodata) and out.rio.encoded_nodata == -9999
    assert out.rio.crs == dem.rio.crs and out.rio.transform() == dem.rio.transform()
    assert skysweep.openness(dem, directions=8).attrs["units"] == "degree"
    assert skysweep.horizon(dem, directions=4).elevation.attrs["units"] == "degree"
    sums = skysweep.insolation(dem, time="2026-06-21T20:00Z/PT2H", step="PT1H", latitude=19.4,
                               longitude=-155.3, directions=8)
    assert sums["poa_global"].attrs["units"] == "Wh m-2"


def test_implausible_fills_are_warned_about_and_taken_as_nodata():
    z = int16_dem(fill=-32768)
    with pytest.warns(UserWarning, match="12 heights of -32768"):
        out = skysweep.svf(z, 10, directions=8)
    assert np.isnan(out[z == -32768]).all() and np.isfinite(out[z != -32768]).all()
    f = rough_dem(hole=False).astype(np.float32)
    f[4, 4:7] = np.finfo(np.float32).min
    with pytest.warns(UserWarning, match="3 heights beyond"):
        out = skysweep.svf(f, 10, directions=8)
    assert np.isnan(out[4, 4:7]).all()
    with no_warnings() as seen:  # declared: no warning
        warnings.simplefilter("always")
        skysweep.svf(z, 10, directions=8, nodata=-32768)
    assert not seen


def test_rioxarray_round_trip_writes_what_the_cli_writes(tmp_path):
    """rioxarray's open of a GeoTIFF whose grid mapping it names
    `grid_mapping`, svf, rio.to_raster: the CRS, transform and nodata of
    svf_file's output, and its values."""
    rioxarray = pytest.importorskip("rioxarray")
    rasterio = pytest.importorskip("rasterio")
    dem = rioxarray.open_rasterio(SAMPLES / "kilauea_summit_30m.tif",
                                  masked=True).squeeze("band", drop=True)
    assert dem.rio.grid_mapping == "grid_mapping"
    skysweep.svf(dem, directions=16).rio.to_raster(tmp_path / "mine.tif")
    # An array has no place: its azimuths are the grid's (north="grid").
    written = skysweep.svf_file(SAMPLES / "kilauea_summit_30m.tif", tmp_path / "cli.tif",
                                directions=16, north="grid")
    assert written == tmp_path / "cli.tif"
    with rasterio.open(tmp_path / "mine.tif") as mine, rasterio.open(written) as cli:
        assert mine.crs == cli.crs and mine.crs is not None
        assert mine.transform == cli.transform
        assert mine.nodata == cli.nodata
        a, b = mine.read(1), cli.read(1)
    assert np.array_equal(a == cli.nodata, b == cli.nodata)
    assert np.max(np.abs(a - b)) <= 1e-6
