"""Clear-sky insolation on arrays against the CLI, and its own sums."""
import numpy as np
import pytest

import skysweep
from conftest import rough_dem, same

# A transverse Mercator of scale 1 centred on 45 N 8 E: a DEM centred on its
# origin lies at that latitude and longitude, with ground cells of the grid's
# size and grid north true to within the tolerance, so the CLI's place is
# the array call's.
TM_45N_8E = ('PROJCS["tm",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,'
             '298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],'
             'PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",45],'
             'PARAMETER["central_meridian",8],PARAMETER["scale_factor",1],'
             'PARAMETER["false_easting",0],PARAMETER["false_northing",0],UNIT["metre",1]]')
PARTS = ("global", "beam", "diffuse", "reflected", "sun_hours")


@pytest.mark.parametrize("shadow", ["exact", "interpolated"])
def test_insolation_equals_the_cli(cli_run, shadow):
    z = rough_dem()
    mine = skysweep.insolation(z, 10, time="2026-06-21T04:00Z/PT6H", step="PT1H", latitude=45,
                               longitude=8, directions=16, shadow=shadow, linke=3.5)
    theirs = cli_run("insolation", z, "--time", "2026-06-21T04:00Z/PT6H", "--step", "PT1H",
                     "--directions", 16, "--shadow", shadow, "--linke", 3.5, "--sun-per-cell",
                     "off", prj=TM_45N_8E, centred=True)
    for k, part in enumerate(PARTS):
        assert same(mine[part], theirs[k]), part


def test_instants_and_ranges_are_the_same_steps():
    z = rough_dem()
    by_range = skysweep.insolation(z, 10, time="2026-03-20T08:00Z/PT3H", step="PT1H",
                                   latitude=-33.9, longitude=18.4, directions=8)
    middles = np.array(["2026-03-20T08:30", "2026-03-20T09:30", "2026-03-20T10:30"],
                       dtype="datetime64[s]")
    by_instants = skysweep.insolation(z, 10, time=middles, step="PT1H", latitude=-33.9,
                                      longitude=18.4, directions=8)
    for part in PARTS:
        assert same(by_range[part], by_instants[part])


def test_twelve_turbidities_take_the_step_month():
    """Twelve Linke values are read by month: a June run with June's value
    equals the run with that one value for the year, and differs from one
    with another June value."""
    z = rough_dem()
    run = dict(time="2026-06-21T08:00Z/PT2H", step="PT1H", latitude=45, longitude=8,
               directions=8)
    twelve = [2.0] * 12
    twelve[5] = 4.5
    by_month = skysweep.insolation(z, 10, linke=twelve, **run)
    june = skysweep.insolation(z, 10, linke="4.5", **run)
    other = skysweep.insolation(z, 10, linke=2.0, **run)
    assert same(by_month["global"], june["global"])
    assert np.nanmax(np.abs(by_month["beam"] - other["beam"])) > 0


def test_a_module_is_given_as_text_or_numbers():
    z = rough_dem()
    run = dict(time="2026-06-21T08:00Z/PT2H", step="PT1H", latitude=45, longitude=8,
               directions=8)
    by_text = skysweep.insolation(z, 10, surface="30,180", **run)
    by_numbers = skysweep.insolation(z, 10, surface=(30, 180), **run)
    on_slopes = skysweep.insolation(z, 10, **run)
    assert same(by_text["global"], by_numbers["global"])
    assert np.nanmax(np.abs(by_text["global"] - on_slopes["global"])) > 0


def test_the_parts_add_up_and_the_night_is_dark():
    z = rough_dem()
    day = skysweep.insolation(z, 10, time="2026-06-21T00:00Z/P1D", step="PT30M", latitude=45,
                              longitude=8, directions=16)
    parts = day["beam"] + day["diffuse"] + day["reflected"]
    assert np.allclose(day["global"], parts, rtol=1e-5, equal_nan=True)
    assert np.nanmax(day["sun_hours"]) <= 24 and np.nanmin(day["beam"]) >= 0
    flat = skysweep.insolation(np.zeros((20, 20)), 10, time="2026-06-21T00:00Z/P1D",
                               latitude=45, longitude=8, directions=8)
    assert np.all(flat["reflected"] == 0)  # a plane sees no terrain to reflect
    night = skysweep.insolation(z, 10, time="2026-06-21T22:00Z/PT2H", latitude=45, longitude=8,
                                directions=8)
    assert all(np.nanmax(night[p]) == 0 for p in PARTS)


def test_insolation_refuses_what_it_cannot_do():
    z = rough_dem()
    with pytest.raises(skysweep.ArgumentError, match="weather"):
        skysweep.insolation(z, 10, time="2026-06-21T00:00Z/P1D", latitude=45, longitude=8,
                            shadow="cumulative")
    with pytest.raises(skysweep.ArgumentError, match="--surface expects .* not '95.0,180.0'"):
        skysweep.insolation(z, 10, time="2026-06-21T00:00Z/P1D", latitude=45, longitude=8,
                            surface=(95, 180))
    with pytest.raises(skysweep.ArgumentError, match="linke"):
        skysweep.insolation(z, 10, time="2026-06-21T00:00Z/P1D", latitude=45, longitude=8,
                            linke=[3, 4])
    with pytest.raises(skysweep.ArgumentError):
        skysweep.insolation(z, 10, time="2026-06-21T00:00/P1D", latitude=45, longitude=8)
