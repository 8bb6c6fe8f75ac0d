"""Compares `skysweep weather FILE` with pvlib's reader of the same file:
the same records, the same stamps (as instants) and the same values.

Usage: python weather_readers.py SKYSWEEP FILE READER
READER: epw | tmy3 | tmy2 | pvgis | pvgis_hourly | psm4. Prints one line per check, TAP-style
("ok" / "not ok"), and exits non-zero if any fails.
"""
import io
import subprocess
import sys

import numpy as np
import pandas as pd
from pvlib import iotools

skysweep, path, reader = sys.argv[1:4]
text = subprocess.run([skysweep, "weather", path], check=True, capture_output=True,
                      text=True).stdout
ours = pd.read_csv(io.StringIO(text), comment="#")
stamps = pd.to_datetime(ours["stamp"], utc=True)

if reader == "epw":
    theirs, meta = iotools.read_epw(path)
    pressure = theirs["atmospheric_pressure"] / 100.0
elif reader == "tmy3":
    theirs, meta = iotools.read_tmy3(path)
    pressure = theirs["pressure"]
elif reader == "tmy2":
    theirs, meta = iotools.read_tmy2(path)
    # pvlib stamps every record in the first record's year; skysweep in the
    # record's own (the year column, which pvlib keeps): the instants are
    # compared in the record's year.
    local = theirs.index.tz_localize(None)
    own = [t.replace(year=1900 + int(y)) for t, y in zip(local, theirs["year"])]
    theirs.index = pd.DatetimeIndex(own).tz_localize(theirs.index.tz)
    # As the manual writes them: tenths of a degree and of a metre a second.
    theirs = theirs.rename(columns={"GHI": "ghi", "DNI": "dni", "DHI": "dhi"})
    theirs["temp_air"] = theirs["DryBulb"] / 10.0
    theirs["wind_speed"] = theirs["Wspd"] / 10.0
    pressure = theirs["Pressure"]
elif reader == "pvgis":
    theirs, *_ = iotools.read_pvgis_tmy(path)
    pressure = theirs["pressure"] / 100.0
elif reader == "pvgis_hourly":
    # seriescalc on a horizontal plane: its global is GHI, its sky diffuse
    # DHI; skysweep completes DNI by the closure (decomposition.py checks it).
    theirs, *_ = iotools.read_pvgis_hourly(path)
    theirs["ghi"] = (theirs["poa_direct"] + theirs["poa_sky_diffuse"]
                     + theirs["poa_ground_diffuse"])
    theirs["dhi"] = theirs["poa_sky_diffuse"]
    theirs["dni"] = ours["dni"].values  # the model's, not the file's
    pressure = pd.Series(np.nan, index=theirs.index)
elif reader == "psm4":
    theirs, meta = iotools.read_nsrdb_psm4(path)
    pressure = theirs.get("pressure", pd.Series(np.nan, index=theirs.index))
else:
    sys.exit(f"unknown reader {reader}")

failed = 0


def check(ok, what):
    global failed
    print(("ok" if ok else "not ok"), "-", what)
    failed += not ok


check(len(ours) == len(theirs), f"{len(ours)} records, pvlib {len(theirs)}")
n = min(len(ours), len(theirs))
their_stamps = theirs.index[:n].tz_convert("UTC")
same_times = (stamps[:n].values == their_stamps.values)
# pvlib's read_tmy3 moves a leap day's first hour (24:00 on 28 February of a
# leap year) to 1 March; skysweep keeps the instant the file names.
leap = ((stamps[:n].dt.month == 2) & (stamps[:n].dt.day == 29)).values
moved = leap & (their_stamps.month == 3) & (their_stamps.day == 1)
check((same_times | moved).all(), f"stamps equal pvlib's index ({(~same_times).sum()} differ, "
      f"{moved.sum()} of them leap days pvlib moves; first ours {stamps.iloc[0]}, "
      f"pvlib {their_stamps[0]})")


def compare(col, their_values, tolerance=1e-4, ignore=None):
    a = ours[col].values[:n].astype(float)
    b = np.asarray(their_values, dtype=float)[:n]
    if ignore is not None:
        b = np.where(ignore(b), np.nan, b)
    both = ~np.isnan(a) & ~np.isnan(b)
    only = np.isnan(a) != np.isnan(b)
    err = np.max(np.abs(a[both] - b[both]) / np.maximum(1.0, np.abs(b[both]))) if both.any() else 0
    check(err <= tolerance and not only.any(),
          f"{col}: max relative difference {err:.2g} over {both.sum()} values, "
          f"{only.sum()} missing on one side only")


def marker(*values):
    return lambda b: np.isin(b, values) | (b > 2000) | (b < -100)


for col in ("ghi", "dni", "dhi"):
    compare(col, theirs[col], ignore=marker(9999, -9900, -9999))
compare("temp_air", theirs["temp_air"], ignore=lambda b: (b > 70) | (b < -90))
compare("wind_speed", theirs["wind_speed"], ignore=lambda b: (b > 100) | (b < 0))
if "albedo" in theirs:
    compare("albedo", theirs["albedo"], ignore=lambda b: (b <= 0) | (b > 1))
compare("pressure", pressure, ignore=lambda b: (b > 1200) | (b < 300))
sys.exit(1 if failed else 0)
