"""Results shaped for the ecosystem (doc/python.md, "Names and shapes"):
pandas in gives pvlib's DataFrame out, xarray in gives Datasets with units
and the CRS out, durations in any form, pvlib's names with the former ones
as aliases, and name= on array calls."""
import datetime as dt
import pathlib

import numpy as np
import pytest

import skysweep
from conftest import rough_dem, same

SAMPLES = pathlib.Path(__file__).resolve().parents[2] / "samples"
RUN = dict(time="2026-06-21T06:00Z/PT4H", latitude=45, longitude=8, directions=8)


def test_pandas_times_give_pvlibs_dataframe():
    """The frame pvlib.solarposition.get_solarposition returns: its index,
    its columns in its order, its values (delta_t=67, as pvlib's default)."""
    pvlib = pytest.importorskip("pvlib")
    pd = pytest.importorskip("pandas")
    times = pd.date_range("2026-06-20 18:00", periods=40, freq="37min", tz="Europe/Berlin")
    ref = pvlib.solarposition.get_solarposition(times, 45.0, 8.0, altitude=300, pressure=95000,
                                                method="nrel_numpy", temperature=5,
                                                delta_t=67)
    mine = skysweep.sun_position(times, 45.0, 8.0, altitude=300, pressure=95000,
                                 temperature=5, delta_t=67)
    assert isinstance(mine, pd.DataFrame)
    assert list(mine.columns) == list(ref.columns)
    assert mine.index.equals(ref.index)
    for column in ref.columns:
        diff = mine[column] - ref[column]
        if column == "azimuth":
            diff = (diff + 180) % 360 - 180
        assert np.max(np.abs(diff)) < 1e-6, column
    one = skysweep.sun_position(times[3], 45.0, 8.0, delta_t=67)
    assert isinstance(one, pd.DataFrame) and list(one.index) == [times[3]]
    # Other instants keep the dict of arrays shaped like them.
    seconds = skysweep.sun_position(np.array([1782036000.0]), 45, 8)
    assert isinstance(seconds, dict) and seconds["azimuth"].shape == (1,)


def test_durations_in_any_form_are_the_same_steps():
    pd = pytest.importorskip("pandas")
    z = rough_dem()
    iso = skysweep.insolation(z, 10, step="PT1H", **RUN)["poa_global"]
    for step in ("1h", "60min", pd.Timedelta(hours=1), dt.timedelta(hours=1),
                 np.timedelta64(1, "h"), "PT3600S"):
        assert same(skysweep.insolation(z, 10, step=step, **RUN)["poa_global"], iso), step
    quarter = skysweep.insolation(z, 10, step="15min", **RUN)["poa_global"]
    assert not np.array_equal(quarter, iso, equal_nan=True)  # 16 steps, not 4
    for bad in ("MS", "-1h", "often", dt.timedelta(0)):
        with pytest.raises((ValueError, skysweep.ArgumentError)):
            skysweep.insolation(z, 10, step=bad, **RUN)
    # File calls write a timedelta as the command line's ISO 8601.
    from skysweep.files import _arguments
    assert _arguments("insolation", {"step": pd.Timedelta(minutes=15)}) == ["--step", "PT900S"]


def test_pvlib_names_with_the_former_ones_as_aliases():
    z = rough_dem()
    plain = skysweep.insolation(z, 10, step="PT1H", linke=4.0, surface=(30, 180), **RUN)
    named = skysweep.insolation(z, 10, step="PT1H", linke_turbidity=4.0, surface_tilt=30,
                                surface_azimuth=180, **RUN)
    assert list(named) == ["poa_global", "poa_direct", "poa_sky_diffuse", "poa_ground_diffuse",
                           "sun_hours", "poa_diffuse"]
    for new, old in (("poa_global", "global"), ("poa_direct", "beam"),
                     ("poa_sky_diffuse", "diffuse"), ("poa_ground_diffuse", "reflected")):
        assert same(named[new], plain[old]) and named[old] is named[new]
    assert same(named["poa_diffuse"], named["poa_sky_diffuse"] + named["poa_ground_diffuse"])
    assert np.allclose(named["poa_global"], named["poa_direct"] + named["poa_diffuse"],
                       rtol=1e-5, equal_nan=True)
    with pytest.raises(TypeError, match="linke_turbidity and its alias linke"):
        skysweep.insolation(z, 10, linke=4.0, linke_turbidity=3.5, **RUN)
    with pytest.raises(TypeError, match="both surface and surface_tilt"):
        skysweep.insolation(z, 10, surface=(30, 180), surface_tilt=30, surface_azimuth=180,
                            **RUN)
    with pytest.raises(TypeError, match="together"):
        skysweep.insolation(z, 10, surface_tilt=30, **RUN)
    by_sun = skysweep.hillshade(z, 10, sun_azimuth=300, sun_elevation=30)
    assert same(by_sun, skysweep.hillshade(z, 10, az=300, alt=30))
    assert not np.array_equal(by_sun, skysweep.hillshade(z, 10), equal_nan=True)
    with pytest.raises(TypeError, match="sun_azimuth and its alias az"):
        skysweep.hillshade(z, 10, az=300, sun_azimuth=300)


def test_vats_radius_is_metres_as_every_length():
    """vat's radius is metres, as svf's and openness's; the blend's cells
    (the CLI's --blend-radius) remain as blend_radius."""
    z = rough_dem()
    by_metres = skysweep.vat(z, 10, radius=50.0, directions=8)
    assert same(by_metres, skysweep.vat(z, 10, blend_radius=5, directions=8))
    assert not np.array_equal(by_metres, skysweep.vat(z, 10, radius=5.0, directions=8),
                              equal_nan=True)
    assert same(skysweep.vat(z, 10, directions=8), skysweep.vat(z, 10, radius=100.0,
                                                                directions=8))
    assert same(skysweep.vat(z, 10, radius=0, directions=8),
                skysweep.vat(z, 10, blend_radius=0, directions=8))
    with pytest.raises(TypeError, match="radius .metres. and its former blend_radius"):
        skysweep.vat(z, 10, radius=50.0, blend_radius=5)
    with pytest.raises(skysweep.ArgumentError):
        skysweep.vat(z, 10, radius=-1.0)


def test_dataarrays_give_datasets_with_units_and_the_crs():
    rioxarray = pytest.importorskip("rioxarray")
    xr = pytest.importorskip("xarray")
    dem = rioxarray.open_rasterio(SAMPLES / "kilauea_summit_30m.tif",
                                  masked=True).squeeze("band", drop=True)[:40, :50]
    h = skysweep.horizon(dem, directions=4, distance=True, cast_height=True)
    assert isinstance(h, xr.Dataset)
    assert set(h.data_vars) == {"elevation", "distance", "cast_height"}
    assert h.elevation.dims == ("azimuth", "y", "x")
    assert list(h.azimuth.values) == [0.0, 90.0, 180.0, 270.0]
    assert h.azimuth.attrs["units"] == "degree" and h.elevation.attrs["units"] == "degree"
    assert h.distance.attrs["units"] == "m" and h.cast_height.attrs["units"] == "m"
    assert h.rio.crs == dem.rio.crs and h.rio.transform() == dem.rio.transform()
    numpy_h = skysweep.horizon(dem.values, skysweep._grid._ground_cell_sizes(
        dem.rio.crs.to_wkt(), float(dem.x.mean()), float(dem.y.mean()),
        tuple(abs(v) for v in dem.rio.resolution())), directions=4, distance=True)
    assert same(h.elevation.values, numpy_h.elevation)
    assert "distance" not in skysweep.horizon(dem, directions=4).data_vars
    sums = skysweep.insolation(dem, time="2026-06-21T20:00Z/PT2H", step="PT1H", latitude=19.4,
                               longitude=-155.3, directions=8)
    assert isinstance(sums, xr.Dataset)
    assert {k: v.attrs["units"] for k, v in sums.data_vars.items()} == {
        "poa_global": "Wh m-2", "poa_direct": "Wh m-2", "poa_sky_diffuse": "Wh m-2",
        "poa_ground_diffuse": "Wh m-2", "poa_diffuse": "Wh m-2", "sun_hours": "h"}
    assert sums.rio.crs == dem.rio.crs and sums.attrs["steps"] == 2
    assert sums.poa_global.dims == dem.dims


def test_name_names_the_returned_dataarray():
    xr = pytest.importorskip("xarray")
    z = rough_dem()
    da = xr.DataArray(z, dims=("y", "x"), coords={"y": -10.0 * np.arange(z.shape[0]),
                                                  "x": 10.0 * np.arange(z.shape[1])})
    assert skysweep.svf(da, directions=8).name == "svf"
    assert skysweep.svf(da, directions=8, name="sky").name == "sky"
    assert skysweep.hillshade(da, name="relief").name == "relief"
    assert skysweep.vat(da, directions=8, name="v").name == "v"
    assert skysweep.openness(da, directions=8, name="o").name == "o"
    assert skysweep.shadow(da, sun_azimuth=200, sun_elevation=20, name="lit").name == "lit"
    assert skysweep.sun_incidence(da, sun_azimuth=200, sun_elevation=20,
                                  name="cos").name == "cos"
