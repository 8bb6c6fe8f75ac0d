"""Trees in the array calls (doc/vegetation.md): svf(canopy=...) against
`skysweep svf --canopy`, and the file call's canopy= path."""
import numpy as np
import pytest

import skysweep
from conftest import read_envi, rough_dem, same, write_asc


def town():
    """Flat ground at 100 m, 10 m cells, a 12 m block and a nodata hole;
    crowns of 6 to 14 m on a row of cells (heights float32 holds exactly)."""
    z = np.full((40, 44), 100.0)
    z[8:14, 30:36] += 12.0
    z[30:32, 5:8] = np.nan
    canopy = np.zeros_like(z)
    canopy[20, 6:38:3] = np.arange(6.0, 17.0)[:len(range(6, 38, 3))] + 0.5
    canopy[24:27, 14:17] = 9.25
    return z, canopy


def test_a_canopy_of_zeros_leaves_the_sky_alone():
    z = rough_dem()
    alone = skysweep.svf(z, 10, directions=16)
    trees = skysweep.svf(z, 10, directions=16, canopy=np.zeros_like(z))
    assert isinstance(trees, skysweep.SvfTrees)
    assert same(trees.svf, alone)
    ground = ~np.isnan(alone)
    assert np.all(trees.svfveg[ground] == 1)
    assert same(trees.svfbuveg, alone)


def test_without_a_canopy_the_return_is_one_array():
    z = rough_dem()
    assert isinstance(skysweep.svf(z, 10, directions=8), np.ndarray)


@pytest.mark.parametrize("transmissivity", [0.0, 0.03, 1.0])
@pytest.mark.parametrize("gaps", ["open", "ignore"])
def test_svf_canopy_equals_the_cli(cli_run, tmp_path, transmissivity, gaps):
    z, canopy = town()
    path = write_asc(tmp_path / "canopy.asc", canopy)
    mine = skysweep.svf(z, 10, directions=24, canopy=canopy, transmissivity=transmissivity,
                        trunk_gaps=gaps)
    theirs = cli_run("svf", z, "--directions", 24, "--canopy", path, "--transmissivity",
                     transmissivity, "--trunk-gaps", gaps)
    assert len(theirs) == 3
    for band, mine_band in zip(theirs, mine):
        assert same(mine_band, band)
    assert np.nanmin(mine.svfveg) < 0.95  # the crowns hide some sky
    if transmissivity == 1.0:
        assert same(mine.svfbuveg, mine.svf)


def test_svf_trunk_equals_the_cli(cli_run, tmp_path):
    z, canopy = town()
    trunk = np.where(canopy > 0, 2.0, 0.0)
    mine = skysweep.svf(z, 10, directions=16, canopy=canopy, trunk=trunk)
    theirs = cli_run("svf", z, "--directions", 16,
                     "--canopy", write_asc(tmp_path / "canopy.asc", canopy),
                     "--trunk", write_asc(tmp_path / "trunk.asc", trunk))
    for band, mine_band in zip(theirs, mine):
        assert same(mine_band, band)


def test_svf_file_takes_a_canopy_path(tmp_path):
    z, canopy = town()
    dem = write_asc(tmp_path / "dem.asc", z)
    path = write_asc(tmp_path / "canopy.asc", canopy)
    skysweep.svf_file(dem, tmp_path / "svf.envi", cell_size=10, of="ENVI", directions=16,
                      canopy=path, transmissivity=0.2)
    bands = read_envi(tmp_path / "svf.envi")
    mine = skysweep.svf(z, 10, directions=16, canopy=canopy, transmissivity=0.2)
    assert len(bands) == 3
    for band, mine_band in zip(bands, mine):
        assert same(mine_band, band)


def test_a_flipped_dataarray_canopy_follows_its_dem():
    xr = pytest.importorskip("xarray")
    z, canopy = town()
    z[np.isnan(z)] = 100.0
    x, y = np.arange(44) * 10.0, np.arange(40)[::-1] * 10.0
    north_up = skysweep.svf(xr.DataArray(z, dims=("y", "x"), coords={"y": y, "x": x}),
                            directions=16, canopy=canopy)
    # The same grid south up: DEM and canopy flipped alike, the result flipped back.
    south_up = skysweep.svf(xr.DataArray(z[::-1], dims=("y", "x"), coords={"y": y[::-1], "x": x}),
                            directions=16,
                            canopy=xr.DataArray(canopy[::-1], dims=("y", "x")))
    assert isinstance(north_up, xr.Dataset)
    assert set(north_up.data_vars) == {"svf", "svfveg", "svfbuveg"}
    for name in ("svf", "svfveg", "svfbuveg"):
        assert same(north_up[name].values, south_up[name].values[::-1])
    assert north_up["svfveg"].values.min() < 0.95
    with pytest.raises(ValueError, match="canopy's y coordinates are not the DEM's"):
        skysweep.svf(xr.DataArray(z, dims=("y", "x"), coords={"y": y, "x": x}), directions=8,
                     canopy=xr.DataArray(canopy, dims=("y", "x"), coords={"y": y[::-1], "x": x}))


def test_bad_trees_are_refused():
    z, canopy = town()
    with pytest.raises(ValueError, match=r"canopy must be shaped like the DEM \(40, 44\)"):
        skysweep.svf(z, 10, directions=8, canopy=canopy[:, :-1])
    with pytest.raises(ValueError, match="canopy height"):
        skysweep.svf(z, 10, directions=8, canopy=-canopy)
    for bad in (-0.1, 1.5):
        with pytest.raises(ValueError, match="--transmissivity expects 0 to 1"):
            skysweep.svf(z, 10, directions=8, canopy=canopy, transmissivity=bad)
    with pytest.raises(ValueError, match="not radiative"):
        skysweep.svf(z, 10, directions=8, canopy=canopy, definition="radiative")
    with pytest.raises(ValueError, match="takes no --radius"):
        skysweep.svf(z, 10, directions=8, canopy=canopy, radius=50)
    with pytest.raises(ValueError, match="--transmissivity needs --canopy"):
        skysweep.svf(z, 10, directions=8, transmissivity=0.5)
    with pytest.raises(ValueError, match="alternatives"):
        skysweep.svf(z, 10, directions=8, canopy=canopy, trunk=canopy / 4, trunk_ratio=0.3)
    with pytest.raises(ValueError, match="memory="):
        skysweep.svf(z, 10, directions=8, canopy=canopy, memory="64M")


@pytest.mark.parametrize("transmissivity", [0.0, 0.03, 1.0])
@pytest.mark.parametrize("lines", ["interpolated", "box"])
def test_shadow_canopy_equals_the_cli(cli_run, tmp_path, transmissivity, lines):
    z, canopy = town()
    path = write_asc(tmp_path / "canopy.asc", canopy)
    mine = skysweep.shadow(z, 10, sun_azimuth=200, sun_elevation=25, lines=lines,
                           canopy=canopy, transmissivity=transmissivity)
    theirs = cli_run("shadow", z, "--sun-azimuth", 200, "--sun-elevation", 25, "--lines", lines,
                     "--canopy", path, "--transmissivity", transmissivity)
    assert isinstance(mine, skysweep.ShadowTrees) and len(theirs) == 5
    for mine_band, band in zip(mine, (theirs[0], theirs[3], theirs[4])):
        assert same(mine_band, band)
    assert np.count_nonzero(mine.shadow_class == 2) > 0  # the crowns cast shade
    assert np.all(mine.fraction[mine.shadow_class == 2] == np.float32(transmissivity))


def test_shadow_with_a_canopy_of_zeros_has_no_vegetation_shadow():
    z = rough_dem()
    alone = skysweep.shadow(z, 10, sun_azimuth=250, sun_elevation=12)
    trees = skysweep.shadow(z, 10, sun_azimuth=250, sun_elevation=12, canopy=np.zeros_like(z))
    assert same(trees.sunlit, alone)
    assert same(trees.fraction, alone)
    assert same(trees.shadow_class, 1 - alone)


def test_shadow_trees_refused_as_the_cli_refuses_them():
    z, canopy = town()
    with pytest.raises(ValueError, match="--trunk-ratio needs --canopy"):
        skysweep.shadow(z, 10, sun_azimuth=200, sun_elevation=25, trunk_ratio=0.5)
    with pytest.raises(ValueError, match="transmissivity"):
        skysweep.shadow(z, 10, sun_azimuth=200, sun_elevation=25, canopy=canopy,
                        transmissivity=2)
    with pytest.raises(ValueError, match="memory="):
        skysweep.shadow(z, 10, sun_azimuth=200, sun_elevation=25, canopy=canopy, memory="64M")


# insolation(canopy=...) against `skysweep insolation --canopy` (doc/vegetation.md,
# "insolation"): the CLI's DEM lies at 45 N 8 E (test_insolation's TM_45N_8E), its canopy
# on the same grid.
INSOLATION = dict(time="2026-06-21T04:00Z/PT6H", step="PT1H", latitude=45, longitude=8,
                  directions=16, linke=3.5)
INSOLATION_CLI = ("--time", "2026-06-21T04:00Z/PT6H", "--step", "PT1H", "--directions", 16,
                  "--linke", 3.5, "--sun-per-cell", "off")
PARTS = ("global", "beam", "diffuse", "reflected", "sun_hours")


def tm_45n_8e():
    from test_insolation import TM_45N_8E
    return TM_45N_8E


@pytest.mark.parametrize("options, leaf_off_steps", [
    ({}, 0),
    ({"trunk": "file", "transmissivity": 0.1, "trunk_gaps": "ignore", "leaf_on": "07-01",
      "transmissivity_leaf_off": 0.3, "crown_lines": "digital"}, 6),
    ({"crown_light": "beer-lambert", "leaf_area_density": 0.8, "leaf_off": "06-22"}, 0),
    ({"leaf_off": 172, "transmissivity_leaf_off": 0.7}, 6),
], ids=["defaults", "trunk-leaf-off", "beer-lambert", "leaf-off-day"])
def test_insolation_canopy_equals_the_cli(cli_run, tmp_path, options, leaf_off_steps):
    z, canopy = town()
    prj = tm_45n_8e()
    path = write_asc(tmp_path / "canopy.asc", canopy, prj=prj, centred=True)
    cli, mine_options = [], dict(options)
    for key, value in options.items():
        if key == "trunk":
            trunk = np.where(canopy > 0, 2.0, 0.0)
            value = write_asc(tmp_path / "trunk.asc", trunk, prj=prj, centred=True)
            mine_options["trunk"] = trunk
        cli += [f"--{key.replace('_', '-')}", value]
    mine = skysweep.insolation(z, 10, canopy=canopy, **INSOLATION, **mine_options)
    theirs = cli_run("insolation", z, *INSOLATION_CLI, "--canopy", path, *cli, prj=prj,
                     centred=True)
    for k, part in enumerate(PARTS):
        assert same(mine[part], theirs[k]), part
    alone = skysweep.insolation(z, 10, shadow="exact", **INSOLATION)
    assert np.nanmin(mine["beam"] - alone["beam"]) < -100  # the crowns shade the beam
    assert np.nanmin(mine["poa_sky_diffuse"] - alone["poa_sky_diffuse"]) < 0  # and the sky
    assert mine.trees["leaf_off_steps"] == leaf_off_steps
    # The canopy given as its file: read with rasterio, the same cells.
    if not options and pytest.importorskip("rasterio"):
        from_file = skysweep.insolation(z, 10, canopy=path, **INSOLATION)
        for part in PARTS:
            assert same(from_file[part], mine[part]), part


def test_insolation_with_a_canopy_of_zeros_or_clear_crowns_is_without_trees():
    z, canopy = town()
    for shadow in ("exact", "interpolated"):
        alone = skysweep.insolation(z, 10, shadow=shadow, **INSOLATION)
        zeros = skysweep.insolation(z, 10, shadow=shadow, canopy=np.zeros_like(z), **INSOLATION)
        clear = skysweep.insolation(z, 10, shadow=shadow, canopy=canopy, transmissivity=1,
                                    transmissivity_leaf_off=1, **INSOLATION)
        for part in PARTS:
            assert same(zeros[part], alone[part]), (shadow, part)
            assert same(clear[part], alone[part]), (shadow, part)


def test_insolation_trees_refused_as_the_cli_refuses_them():
    z, canopy = town()
    with pytest.raises(ValueError, match=r"canopy must be shaped like the DEM \(40, 44\)"):
        skysweep.insolation(z, 10, canopy=canopy[:-1], **INSOLATION)
    with pytest.raises(ValueError, match="canopy height"):
        skysweep.insolation(z, 10, canopy=-canopy, **INSOLATION)
    with pytest.raises(TypeError, match="canopy must hold real numbers"):
        skysweep.insolation(z, 10, canopy=np.full(z.shape, "tree"), **INSOLATION)
    with pytest.raises(ValueError, match="--leaf-on needs --canopy"):
        skysweep.insolation(z, 10, leaf_on=100, **INSOLATION)
    with pytest.raises(ValueError, match="--leaf-off '13-40' is neither a day of the year"):
        skysweep.insolation(z, 10, canopy=canopy, leaf_off="13-40", **INSOLATION)
    with pytest.raises(ValueError, match="--transmissivity-leaf-off expects 0 to 1"):
        skysweep.insolation(z, 10, canopy=canopy, transmissivity_leaf_off=1.5, **INSOLATION)
    with pytest.raises(ValueError, match="--extinction needs --crown-light beer-lambert"):
        skysweep.insolation(z, 10, canopy=canopy, extinction=0.3, **INSOLATION)
    with pytest.raises(ValueError, match="memory="):
        skysweep.insolation(z, 10, canopy=canopy, memory="64M", **INSOLATION)


def test_a_canopy_file_must_lie_on_a_dataarray_dems_cells(tmp_path):
    xr = pytest.importorskip("xarray")
    rasterio = pytest.importorskip("rasterio")
    from rasterio.transform import from_origin
    z, canopy = town()
    z[np.isnan(z)] = 100.0
    x, y = 5.0 + np.arange(44) * 10.0, 395.0 - np.arange(40) * 10.0  # cell centres
    dem = xr.DataArray(z, dims=("y", "x"), coords={"y": y, "x": x})

    def canopy_file(name, west):
        path = tmp_path / name
        with rasterio.open(path, "w", driver="GTiff", width=44, height=40, count=1,
                           dtype="float32", transform=from_origin(west, 400.0, 10.0, 10.0),
                           nodata=-1.0) as dataset:
            dataset.write(np.where(canopy > 0, canopy, -1.0).astype(np.float32), 1)
        return path

    on_grid = skysweep.insolation(dem, canopy=canopy_file("on.tif", 0.0), **INSOLATION)
    as_array = skysweep.insolation(dem, canopy=canopy, **INSOLATION)
    for part in on_grid.data_vars:  # its nodata is no tree, as the array's zeros
        assert same(on_grid[part].values, as_array[part].values), part
    with pytest.raises(ValueError, match="its cells are not the DEM's"):
        skysweep.insolation(dem, canopy=canopy_file("off.tif", 30.0), **INSOLATION)
