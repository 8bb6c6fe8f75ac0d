"""A roof plane with no horizon: skysweep roofs' unshaded_kwh_m2_year of one
plane equals the sum of pvlib.irradiance.get_total_irradiance's
plane-of-array global over the same weather records on a plane of the tilt
and azimuth roofs fitted (Perez, albedo 0.2, skysweep's extraterrestrial
irradiance), within 1 %; and the plane's per-cell mean (kwh_m2_year, the
insolation run on the DSM) agrees within LIMIT % (the cells' own
surroundings differ from an open plane's by that much at most).

Usage: python roof_plane.py SKYSWEEP WEATHER TIME PLANES.csv BUILDING X Y LIMIT.
X, Y: a point on the plane in EPSG:32632. Prints a line; exits non-zero if
either disagrees.
"""
import io
import subprocess
import sys

import numpy as np
import pandas as pd
import pvlib

skysweep, weather, window, planes, building, x, y, limit = sys.argv[1:9]
plane = pd.read_csv(planes)
plane = plane[plane["building_id"].astype(str) == building].iloc[0]
records = pd.read_csv(io.StringIO(subprocess.run(
    [skysweep, "weather", weather], check=True, capture_output=True, text=True).stdout),
    comment="#")
sun_time = pd.to_datetime(records["sun_time"], utc=True)
start, duration = window.split("/")
t0 = pd.Timestamp(start)
inside = (sun_time >= t0) & (sun_time < t0 + pd.Timedelta(duration))
rec = records[inside.values]
times = pd.DatetimeIndex(sun_time[inside.values])
lon, lat = (float(v) for v in subprocess.run(
    ["gdaltransform", "-s_srs", "EPSG:32632", "-t_srs", "EPSG:4326", "-output_xy"],
    input=f"{x} {y}\n", check=True, capture_output=True, text=True).stdout.split())
sun = pvlib.solarposition.get_solarposition(times, lat, lon, altitude=12)
dni_extra = 1367.0 / pvlib.solarposition.nrel_earthsun_distance(times) ** 2
dni, ghi, dhi = (rec[c].clip(lower=0).values for c in ("dni", "ghi", "dhi"))
args = (plane["tilt_deg"], plane["azimuth_deg"], sun["zenith"].values, sun["azimuth"].values,
        dni, ghi, dhi)
poa = pvlib.irradiance.get_total_irradiance(*args, dni_extra=dni_extra.values, albedo=0.2,
                                            model="perez")
iso = pvlib.irradiance.get_total_irradiance(*args, dni_extra=dni_extra.values, albedo=0.2,
                                            model="isotropic")
up = sun["zenith"].values < 90
# Below the horizontal skysweep takes the diffuse light as isotropic (as
# tests/pvlib/year_open_plane.py); Perez's NaN where DHI is 0 adds no sky.
g = np.where(up, poa["poa_global"], iso["poa_sky_diffuse"] + iso["poa_ground_diffuse"])
g = np.nan_to_num(np.where(up & np.isnan(g), poa["poa_direct"] + poa["poa_ground_diffuse"], g))
theirs = g.sum() / 1000
open_ = float(plane["unshaded_kwh_m2_year"])
cells = float(plane["kwh_m2_year"])
d_open = 100 * (open_ - theirs) / theirs
d_cells = 100 * (cells - theirs) / theirs
print(f"plane {building} ({plane['tilt_deg']:.2f} deg, {plane['azimuth_deg']:.2f} deg), "
      f"{len(rec)} records: pvlib {theirs:.4f} kWh/m2, unshaded {open_:.4f} ({d_open:+.3f} %), "
      f"per-cell mean {cells:.4f} ({d_cells:+.3f} %)")
ok = abs(d_open) <= 1 and abs(d_cells) <= float(limit)
if "kwh_dc_year" in plane:
    hours = rec["duration_h"].values
    poa_w = g / hours
    temp = rec["temp_air"].fillna(20.0).values
    wind = rec["wind_speed"].fillna(0.0).values
    cell = pvlib.temperature.faiman(poa_w, temp, wind)
    pdc = np.clip(pvlib.pvsystem.pvwatts_dc(poa_w, cell, 1.0, -0.0047), 0, None) * (1 - 0.1142)
    pac = pvlib.inverter.pvwatts(pdc, 1.0 / (1.2 * 0.96), eta_inv_nom=0.96)
    theirs_ratio = float(np.sum(np.nan_to_num(pac) * hours) / np.sum(pdc * hours))
    ours_ratio = float(plane["kwh_ac_year"]) / float(plane["kwh_dc_year"])
    d_ratio = 100 * (ours_ratio - theirs_ratio) / theirs_ratio
    print(f"plane {building}: AC/DC {ours_ratio:.5f}, pvlib's PVWatts on the open plane "
          f"{theirs_ratio:.5f} ({d_ratio:+.3f} %)")
    ok = ok and abs(d_ratio) <= 0.2 and float(plane["kwh_dc_year"]) >= float(plane["kwh_ac_year"])
sys.exit(0 if ok else 1)
