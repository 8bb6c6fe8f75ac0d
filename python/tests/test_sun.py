"""The sun's position against pvlib's SPA."""
import datetime as dt

import numpy as np
import pytest

import skysweep

pvlib = pytest.importorskip("pvlib")
pd = pytest.importorskip("pandas")


@pytest.mark.parametrize("lat, lon, alt", [(45.0, 8.0, 300.0), (-33.9, 18.4, 0.0),
                                           (19.4, -155.3, 1200.0), (78.2, 15.6, 10.0)])
def test_sun_position_matches_pvlib_spa(lat, lon, alt):
    times = pd.date_range("2026-03-01", "2026-03-04", freq="37min", tz="UTC")
    ref = pvlib.solarposition.spa_python(times, lat, lon, altitude=alt, pressure=95000,
                                         temperature=5, delta_t=67.0)
    mine = skysweep.sun_position(times, lat, lon, altitude=alt, pressure=95000, temperature=5,
                                 delta_t=67.0)
    for key in ("apparent_zenith", "zenith", "apparent_elevation", "elevation",
                "equation_of_time"):
        assert np.allclose(mine[key], ref[key].to_numpy(), atol=1e-6), key
    diff = (mine["azimuth"] - ref["azimuth"].to_numpy() + 180) % 360 - 180
    assert np.max(np.abs(diff)) < 1e-6


def test_instants_outside_nanoseconds_and_nat():
    """datetime64 keeps its own unit (nanoseconds end in 1678 and 2262; SPA
    spans -2000..6000), and NaT has no sun."""
    t = np.array(["1500-06-21T12:00", "2300-06-21T12:00", "NaT"], dtype="datetime64[s]")
    seconds = [(np.datetime64(x, "s") - np.datetime64(0, "s")) / np.timedelta64(1, "s")
               for x in t[:2]]
    by_stamp = skysweep.sun_position(t, 45, 8)
    by_seconds = skysweep.sun_position(np.array(seconds), 45, 8)
    assert np.array_equal(by_stamp["azimuth"][:2], by_seconds["azimuth"])
    assert seconds[0] < -1.4e10 and seconds[1] > 1.0e10
    assert all(np.isnan(v[2]) for v in by_stamp.values())


def test_instants_in_any_form_are_the_same_instants():
    aware = dt.datetime(2026, 6, 21, 12, 0, tzinfo=dt.timezone(dt.timedelta(hours=2)))
    forms = [aware, dt.datetime(2026, 6, 21, 10, 0, tzinfo=dt.timezone.utc),
             np.datetime64("2026-06-21T10:00"),
             pd.Timestamp("2026-06-21 12:00", tz="Europe/Berlin"),
             pd.DatetimeIndex(["2026-06-21 10:00"], tz="UTC"), 1782036000.0]
    azimuths = [float(np.ravel(skysweep.sun_position(t, 45, 8)["azimuth"])[0]) for t in forms]
    assert np.allclose(azimuths, azimuths[0], atol=1e-9)


def test_a_time_without_a_zone_is_refused_as_the_cli_refuses_it(tmp_path):
    """Which zone a naive datetime meant is unknown: array calls refuse it
    as the file calls (the command line) do; datetime64 is UTC."""
    naive = dt.datetime(2026, 6, 21, 10, 0)
    for time in (naive, [naive], pd.Timestamp(naive), pd.DatetimeIndex([naive])):
        with pytest.raises(ValueError, match="no time zone"):
            skysweep.sun_position(time, 45, 8)
    z = np.full((8, 8), 100.0)
    with pytest.raises(ValueError, match="no time zone"):
        skysweep.insolation(z, 10, time=[naive], latitude=45, longitude=8)
    with pytest.raises(ValueError, match="no time zone"):
        skysweep.run("sun", at="8,45", time=naive)
    aware = naive.replace(tzinfo=dt.timezone.utc)
    printed = skysweep.run("sun", at="8,45", time=aware, format="json")
    assert "azimuth" in printed
