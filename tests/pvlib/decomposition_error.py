"""How far Erbs's split (GHI alone) and the closure (GHI and DHI) land from
the DNI and DHI a weather file gives: the table of doc/weather.md.

Usage: python decomposition_error.py SKYSWEEP FILE...

Reads each file with `skysweep weather` (records, sun times, site) and
completes it as skysweep does (pvlib.irradiance.erbs and .dni, equal to
skysweep's within 0.1 % per record: tests/pvlib/decomposition.py) at the
file's site. Prints one Markdown row per file and model: the year's DNI
and DHI sums against the file's, and the hourly RMSE and bias of DNI over
records with the sun up.
"""
import io
import re
import subprocess
import sys

import numpy as np
import pandas as pd
import pvlib

skysweep = sys.argv[1]
print("| file | model | DNI, year (kWh/m²): file → model | DHI, year: file → model "
      "| DNI hourly RMSE / bias (W/m², sun up) |")
print("|---|---|---|---|---|")
for path in sys.argv[2:]:
    text = subprocess.run([skysweep, "weather", path], check=True, capture_output=True,
                          text=True).stdout
    site = re.search(r"^# site ([-\d.]+), ([-\d.]+)", text, re.M)
    lon, lat = float(site.group(1)), float(site.group(2))
    rec = pd.read_csv(io.StringIO(text), comment="#").dropna(subset=["ghi", "dni", "dhi"])
    times = pd.DatetimeIndex(pd.to_datetime(rec["sun_time"], utc=True))
    hours = rec["duration_h"].to_numpy()
    zenith = pvlib.solarposition.get_solarposition(times, lat, lon)["zenith"].to_numpy()
    ghi, dni, dhi = (rec[c].clip(lower=0).to_numpy() for c in ("ghi", "dni", "dhi"))
    erbs = pvlib.irradiance.erbs(ghi, zenith, times)
    closure = pvlib.irradiance.dni(pd.Series(ghi), pd.Series(dhi), pd.Series(zenith))
    closure = closure.fillna(0).to_numpy()
    up = zenith < 90
    name = path.rsplit("/", 1)[-1]
    for model, m_dni, m_dhi in (("Erbs (GHI alone)", np.asarray(erbs["dni"]),
                                 np.asarray(erbs["dhi"])),
                                ("closure (GHI, DHI)", closure, dhi)):
        d = m_dni[up] - dni[up]
        print(f"| {name} | {model} | {np.sum(dni * hours) / 1000:.0f} → "
              f"{np.sum(m_dni * hours) / 1000:.0f} ({np.sum(m_dni * hours) / np.sum(dni * hours) - 1:+.1%}) "
              f"| {np.sum(dhi * hours) / 1000:.0f} → {np.sum(m_dhi * hours) / 1000:.0f} "
              f"({np.sum(m_dhi * hours) / np.sum(dhi * hours) - 1:+.1%}) "
              f"| {np.sqrt(np.mean(d ** 2)):.0f} / {np.mean(d):+.0f} |")
