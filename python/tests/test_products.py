"""Array calls against the command line (cell for cell) and closed forms."""
import math

import numpy as np
import pytest

import skysweep
from conftest import read_envi, rough_dem, same

# None is --device auto, as the CLI's default; PoCL's CPU device by name.
DEVICES = [None, "reference", "Portable"]


@pytest.mark.parametrize("definition", ["geometric", "radiative", "horizontal"])
@pytest.mark.parametrize("device", DEVICES)
def test_svf_equals_the_cli(cli_run, definition, device):
    z = rough_dem()
    mine = skysweep.svf(z, 10, definition=definition, directions=24, device=device)
    theirs = cli_run("svf", z, "--definition", definition, "--directions", 24,
                     *(["--device", device] if device else []))[0]
    assert same(mine, theirs)


def test_svf_default_directions_follow_the_planner(cli_run):
    z = rough_dem()
    assert same(skysweep.svf(z, 10), cli_run("svf", z)[0])


def test_radius_svf_equals_the_cli(cli_run):
    z = rough_dem()
    assert same(skysweep.svf(z, 10, radius=120, directions=16),
                cli_run("svf", z, "--radius", 120, "--directions", 16)[0])


@pytest.mark.parametrize("kind", ["positive", "negative"])
def test_openness_equals_the_cli(cli_run, kind):
    z = rough_dem()
    assert same(skysweep.openness(z, 10, kind=kind, directions=16),
                cli_run("openness", z, "--kind", kind, "--directions", 16)[0])


def test_openness_default_directions_follow_the_planner(cli_run):
    z = rough_dem()
    assert same(skysweep.openness(z, 10), cli_run("openness", z)[0])
    assert same(skysweep.openness(z, 10, horizon_tolerance=0.01),
                cli_run("openness", z, "--horizon-tolerance", 0.01)[0])


def test_horizon_equals_the_cli(cli_run, tmp_path):
    z = rough_dem()
    h = skysweep.horizon(z, 10, directions=8, distance=True, cast_height=True)
    assert h.elevation.shape == (8,) + z.shape
    assert np.allclose(h.azimuth, np.arange(8) * 45.0)
    assert same(h.elevation, cli_run("horizon", z, "--directions", 8,
                                     "--distance", tmp_path / "distance.envi",
                                     "--cast-height", tmp_path / "cast.envi"))
    # The optional outputs too, nodata and "none ahead" (NaN) where the CLI's are.
    assert same(h.distance, read_envi(tmp_path / "distance.envi"))
    assert same(h.cast_height, read_envi(tmp_path / "cast.envi"))
    # Something lies ahead exactly where a distance is given.
    ahead = h.elevation > -90
    assert np.all(h.distance[ahead] > 0) and np.all(h.distance[~ahead & ~np.isnan(h.elevation)] == 0)
    assert np.all(np.isnan(h.cast_height[~ahead]))


def test_shadow_equals_the_cli(cli_run):
    z = rough_dem()
    mine = skysweep.shadow(z, 10, sun_azimuth=250, sun_elevation=12)
    theirs = cli_run("shadow", z, "--sun-azimuth", 250, "--sun-elevation", 12)[0]
    assert same(mine, theirs)
    assert 0 < np.nanmean(mine) < 1


def box_city():
    """Flat ground with blocks of 5 to 20 m on 1 m cells."""
    rng = np.random.default_rng(4)
    z = np.zeros((60, 70), dtype=np.float32)
    for _ in range(12):
        r, c = rng.integers(0, 55), rng.integers(0, 65)
        z[r:r + rng.integers(4, 12), c:c + rng.integers(4, 12)] = rng.uniform(5, 20)
    return z


@pytest.mark.parametrize("device", ["reference", "Portable"])
def test_box_shadows_by_each_cells_ray_equal_the_cli_and_the_lines(cli_run, device):
    """Box lines' shadows default to each cell's own ray (--box-shadows
    march), on every device (the march runs on the host): the C twin's CLI,
    and the box lines' own walks' on all but a few cells next to walls."""
    z = box_city()
    march = skysweep.shadow(z, 1, sun_azimuth=203, sun_elevation=25, lines="box",
                            device=device)
    theirs = cli_run("shadow", z, "--sun-azimuth", 203, "--sun-elevation", 25, "--lines", "box",
                     "--device", "reference", cell=1.0)[0]
    assert same(march, theirs)
    lines = skysweep.shadow(z, 1, sun_azimuth=203, sun_elevation=25, lines="box",
                            box_shadows="lines", box_lines=64, device="reference")
    assert 0 < np.mean(march) < 1
    assert np.mean(march == lines) >= 0.99
    with pytest.raises(skysweep.ArgumentError, match="box-shadows"):
        skysweep.shadow(z, 1, sun_azimuth=203, sun_elevation=25, box_shadows="rays")


@pytest.mark.parametrize("options", [{}, {"az": 100, "alt": 20, "z": 2.5},
                                     {"alg": "ZevenbergenThorne"}, {"multidirectional": True},
                                     {"alt": 12, "cast_shadows": True},
                                     {"sky_view": 0.4, "directions": 16}])
def test_hillshade_equals_the_cli(cli_run, options):
    z = rough_dem()
    args = []
    for key, value in options.items():
        flag = "--" + key.replace("_", "-")
        args += [flag] if value is True else [flag, value]
    assert same(np.rint(skysweep.hillshade(z, 10, **options)),
                cli_run("hillshade", z, *args)[0])


def test_tilted_plane_has_its_closed_form():
    """On a plane rising east at angle b, every sample ahead in azimuth a
    lies at elevation atan(tan b sin a): the geometric SVF of each cell is
    1 - mean over the directions of sin of that, where positive."""
    b = math.radians(20)
    cols = np.arange(64) * 10.0
    z = np.tile(cols * math.tan(b), (40, 1))
    d = 32
    v = skysweep.svf(z, 10, directions=d, curvature="off")
    a = np.radians(np.arange(d) * 360.0 / d)
    expected = 1 - np.mean(np.sin(np.maximum(0, np.arctan(math.tan(b) * np.sin(a)))))
    # Interior cells: terrain lies ahead in every direction that rises.
    assert np.allclose(v[5:-5, 5:-5], expected, atol=2e-6)
    assert np.all(skysweep.openness(np.zeros((20, 30)), 5, directions=8) == 90)


def test_site_horizon_at_a_cell_centre_is_the_grids():
    z = rough_dem(hole=False)
    grid = skysweep.horizon(z, 10, directions=36, curvature="off")
    sites = skysweep.site_horizon(z, 10, col=[17, 30], row=[21, 8], step=10)
    assert sites["elevation"].shape == (2, 36)
    assert np.allclose(sites["azimuth"][0], grid.azimuth)
    assert np.allclose(sites["elevation"][0], grid.elevation[:, 21, 17], atol=1e-4)
    assert np.allclose(sites["elevation"][1], grid.elevation[:, 8, 30], atol=1e-4)
    one = skysweep.site_horizon(z, 10, col=17, row=21, step=10, height=30)
    assert one["elevation"].shape == (36,)
    assert np.all(one["elevation"] <= sites["elevation"][0] + 1e-9)  # higher eyes see lower
    assert one["ground_height"] == pytest.approx(z[21, 17], abs=1e-3)


def test_dataarray_in_and_out():
    xr = pytest.importorskip("xarray")
    z = rough_dem(hole=False)
    da = xr.DataArray(z, dims=("y", "x"), coords={"y": 5000 - np.arange(z.shape[0]) * 10.0,
                                                  "x": 300000 + np.arange(z.shape[1]) * 10.0})
    out = skysweep.svf(da, directions=16)
    assert isinstance(out, xr.DataArray)
    assert np.array_equal(out["x"], da["x"]) and out.attrs["units"] == "1"
    assert same(out.values, skysweep.svf(z, 10, directions=16))
    # Where it lies goes with it, as rioxarray reads it where installed.
    out = skysweep.svf(da.assign_attrs(crs="EPSG:32633"), directions=16)
    try:
        import rioxarray  # noqa: F401
        assert out.rio.crs == "EPSG:32633"
    except ImportError:
        assert out.attrs["crs"] == "EPSG:32633"
    h = skysweep.horizon(da, directions=4)
    assert h.elevation.dims == ("azimuth", "y", "x")


def test_a_dataarray_with_y_rising_is_read_north_up():
    """netCDF often stores y rising (south first): a wall along the north
    edge must still stand in azimuth 0, and results keep the input's order."""
    xr = pytest.importorskip("xarray")
    z = np.zeros((30, 30))
    z[0, :] = 100.0  # north edge, rows north to south
    # Interpolated lines: a lone wall would make the planner take box lines.
    north_up = skysweep.horizon(z, 10, directions=4, lines="interpolated").elevation
    da = xr.DataArray(z[::-1], dims=("y", "x"),
                      coords={"y": np.arange(30) * 10.0, "x": np.arange(30) * 10.0})
    h = skysweep.horizon(da, directions=4, lines="interpolated").elevation
    assert np.array_equal(h.values, north_up[:, ::-1])
    # Row 24 of the rising y is 5 rows south of the wall: 100 m seen 50 m away, in the north.
    assert h.values[0, 24, 15] == pytest.approx(np.degrees(np.arctan(100 / 50)), abs=1e-3)
    assert h.values[2, 24, 15] < 1
    with pytest.raises(ValueError, match="degrees"):
        skysweep.svf(xr.DataArray(z, dims=("lat", "lon"),
                                  coords={"lat": np.arange(30.0), "lon": np.arange(30.0)}))


def test_nodata_and_implausible_heights():
    z = rough_dem(hole=False).astype(np.float32)
    z[3, 4] = np.float32(-9999.9)
    v = skysweep.svf(z, 10, directions=8, nodata=-9999.9)
    assert np.isnan(v[3, 4]) and np.isfinite(v).sum() == z.size - 1
    z2 = rough_dem(hole=False)
    z2[5, 5] = 3e7
    with pytest.warns(UserWarning, match="1 heights beyond"):
        v = skysweep.svf(z2, 10, directions=8)
    assert np.isnan(v[5, 5])


def test_vat_equals_the_cli(cli_run):
    z = rough_dem()
    mine = skysweep.vat(z, 10, directions=16, blend_radius=5)
    theirs = cli_run("hillshade", z, "--blend", "vat", "--directions", 16, "--blend-radius", 5)[0]
    assert same(np.rint(1 + 254 * mine), theirs)
    with pytest.raises(skysweep.ArgumentError, match="blend-radius"):
        skysweep.vat(z, 10, blend_radius=-1)


def test_cast_shadows_darken_the_shade():
    """With the light low, the shade's cast-shadow cells take 1 exactly
    where the shadow call says the cell is in a cast shadow, and keep the
    plain shade elsewhere."""
    z = rough_dem()
    plain = skysweep.hillshade(z, 10, az=250, alt=8)
    cast = skysweep.hillshade(z, 10, az=250, alt=8, cast_shadows=True)
    lit = skysweep.shadow(z, 10, sun_azimuth=250, sun_elevation=8)
    shaded = lit == 0
    assert shaded.any() and (lit == 1).any()
    assert np.all(cast[shaded] == 1)
    assert same(cast[lit == 1], plain[lit == 1])


def test_plan_says_what_the_run_does():
    z = rough_dem()
    p = skysweep.plan(z, 10, product="svf", directions=24)
    effects = {e["effect"]: e for e in p["effects"]}
    assert p["directions"] == 24 and p["sweeps"] == 24
    assert effects["directions"]["on"] and "as requested" in effects["directions"]["reason"]
    assert p["device"] in ("reference",) or ":" in p["device"]
    assert not effects["curvature"]["on"]  # a 0.7 km grid: curvature is below the tolerance
    with pytest.raises(ValueError, match="product"):
        skysweep.plan(z, 10, product="sky")


def test_every_product_of_the_registry_has_its_calls_and_plans():
    from skysweep._lib import PRODUCTS
    assert {"horizon", "svf", "openness", "hillshade", "shadow", "insolation"} <= set(PRODUCTS)
    z = rough_dem()
    for name, product in PRODUCTS.items():
        assert callable(getattr(skysweep, name)) and callable(getattr(skysweep, f"{name}_file"))
        if name == "insolation":  # its plan needs the steps
            with pytest.raises(ValueError, match="product"):
                skysweep.plan(z, 10, product=name)
            continue
        assert skysweep.plan(z, 10, product=name, directions=8)["directions"] == 8, name


def test_nodata_that_the_dtype_cannot_hold_masks_nothing():
    z = np.full((20, 20), 241, dtype=np.uint8)
    z[3, 3] = 10
    v = skysweep.svf(z, 10, directions=8, nodata=-9999)  # -9999 would wrap to 241 as uint8
    assert np.isfinite(v).all()
    z16 = np.full((20, 20), 3, dtype=np.int16)
    assert np.isfinite(skysweep.svf(z16, 10, directions=8, nodata=3.5)).all()
