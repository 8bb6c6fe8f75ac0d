"""A year on an unobstructed plane: skysweep's annual and monthly global
(kWh/m^2) and PV yield (kWh/kWp) at the centre of a plane DEM equal the sums
of pvlib's per-record plane-of-array irradiance (get_total_irradiance) and
PVWatts DC yield (temperature.faiman or sapm_cell, pvsystem.pvwatts_dc, less
the losses) and AC yield (inverter.pvwatts), within 0.5 %.

Usage: python year_open_plane.py SKYSWEEP WEATHER PLANE.tif TILT AZIMUTH
SKY_MODEL TEMPERATURE_MODEL WORKDIR [DC_AC_RATIO]. Prints TAP-style lines;
exits non-zero if any sum disagrees.
"""
import io
import subprocess
import sys

import numpy as np
import pandas as pd
import pvlib

skysweep, weather, plane, tilt, azimuth, model, temp_model, work = sys.argv[1:9]
ratio = float(sys.argv[9]) if len(sys.argv) > 9 else 1.2
tilt, azimuth = float(tilt), float(azimuth)
gamma, losses = -0.0047, 0.1142
col, row = 30, 30
out = f"{work}/year_{model}_{temp_model}.tif"
subprocess.run([skysweep, "insolation", "-q", "--device", "reference", "--weather", weather,
                "--sky-model", model, "--directions", "64", "--albedo", "0.2", "--pv",
                "--temperature-model", temp_model, "--gamma-pdc", str(gamma),
                "--losses", str(100 * losses), "--dc-ac-ratio", str(ratio), plane, out],
               check=True)
ours = [float(v) for v in subprocess.run(["gdallocationinfo", "-valonly", out, str(col),
                                          str(row)], check=True, capture_output=True,
                                         text=True).stdout.split()]

rec = pd.read_csv(io.StringIO(subprocess.run([skysweep, "weather", weather], check=True,
                                             capture_output=True, text=True).stdout),
                  comment="#")
times = pd.DatetimeIndex(pd.to_datetime(rec["sun_time"], utc=True))
info = pd.read_json(io.StringIO(subprocess.run(["gdalinfo", "-json", plane], check=True,
                                               capture_output=True, text=True).stdout),
                    typ="series")
gt = info["geoTransform"]
x, y = gt[0] + (col + 0.5) * gt[1], gt[3] + (row + 0.5) * gt[5]
lon, lat, lon_n, lat_n = (float(v) for v in subprocess.run(
    ["gdaltransform", "-s_srs", "EPSG:32632", "-t_srs", "EPSG:4326", "-output_xy"],
    input=f"{x} {y}\n{x} {y + 1000}\n", check=True, capture_output=True,
    text=True).stdout.split())
p1, p2, dl = np.radians(lat), np.radians(lat_n), np.radians(lon_n - lon)
azimuth += np.degrees(np.arctan2(np.sin(dl) * np.cos(p2),
                                 np.cos(p1) * np.sin(p2) - np.sin(p1) * np.cos(p2) * np.cos(dl)))
sun = pvlib.solarposition.get_solarposition(times, lat, lon, altitude=500)
dni_extra = 1367.0 / pvlib.solarposition.nrel_earthsun_distance(times) ** 2
up = sun["zenith"].values < 90
dni, ghi, dhi = (rec[c].clip(lower=0).values for c in ("dni", "ghi", "dhi"))
poa = pvlib.irradiance.get_total_irradiance(
    tilt, azimuth, sun["zenith"].values, sun["azimuth"].values, dni, ghi, dhi,
    dni_extra=dni_extra.values, albedo=0.2, model=model)
# Below the horizontal (sunrise and sunset hours) skysweep takes the record's
# diffuse light as isotropic; pvlib's Perez gives NaN or 0 there.
iso = pvlib.irradiance.get_total_irradiance(
    tilt, azimuth, sun["zenith"].values, sun["azimuth"].values, dni, ghi, dhi,
    dni_extra=dni_extra.values, albedo=0.2, model="isotropic")
g = np.where(up, poa["poa_global"], iso["poa_sky_diffuse"] + iso["poa_ground_diffuse"])
g = np.nan_to_num(np.where(up & np.isnan(g), poa["poa_direct"] + poa["poa_ground_diffuse"], g))
if temp_model == "faiman":
    cell = pvlib.temperature.faiman(g, rec["temp_air"].values, rec["wind_speed"].values)
else:
    p = pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"]["open_rack_glass_glass"]
    cell = pvlib.temperature.sapm_cell(g, rec["temp_air"].values, rec["wind_speed"].values, **p)
dc = np.maximum(pvlib.pvsystem.pvwatts_dc(g, cell, 1.0, gamma), 0) * (1 - losses)

failed = 0


def check(name, a, b):
    global failed
    ok = abs(a - b) <= 0.005 * abs(b)
    failed += not ok
    print(("ok" if ok else "not ok"), f"- {model}, {temp_model}: {name} skysweep {a:.2f}, "
          f"pvlib {b:.2f} ({100 * (a - b) / b:+.3f} %)")


check("global, year (kWh/m2)", ours[0], g.sum() / 1000)
month = times.month  # the PVGIS file is in UTC, the zone skysweep takes months in
for m in (1, 6):
    check(f"global, month {m}", ours[4 + m], g[month == m].sum() / 1000)
check("PV yield, year (kWh/kWp)", ours[17], dc.sum())
# AC: pvlib's PVWatts inverter, 96 % nominal, modules `ratio` times its AC rating.
pdc0 = 1.0 / (ratio * 0.96)
ac = pvlib.inverter.pvwatts(dc, pdc0, eta_inv_nom=0.96)
clipped = int((ac >= 0.96 * pdc0 - 1e-9).sum())
check(f"PV AC yield, year (kWh/kWp; DC/AC {ratio:g}, {clipped} records clipped)", ours[18],
      ac.sum())
sys.exit(1 if failed else 0)
