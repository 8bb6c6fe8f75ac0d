"""Plane-of-array irradiance on an unobstructed plane: skysweep's per-record
global irradiance at the centre of a plane DEM equals
pvlib.irradiance.get_total_irradiance for the same sun, weather, surface and
sky model, within 0.5 % or 1 W/m^2.

Usage: python poa_open_plane.py SKYSWEEP WEATHER PLANE.tif TILT AZIMUTH MODEL
TIME WORKDIR [module]. The plane faces AZIMUTH (clockwise from grid north), tilted TILT
degrees; TIME (ISO 8601 START/DURATION) selects the records. The sun for
pvlib is pvlib's own SPA at the cell; the extraterrestrial normal
irradiance is skysweep's (1367 W/m^2 at pvlib's earth-sun distance). A
file with GHI alone is split by pvlib's Erbs.
Prints TAP-style lines; exits non-zero if any record disagrees.
"""
import io
import subprocess
import sys

import numpy as np
import pandas as pd
import pvlib

skysweep, weather, plane, tilt, azimuth, model, window, work = sys.argv[1:9]
# With a 9th argument, the plane is level and skysweep is given --surface
# TILT,AZIMUTH (a fixed module, azimuth from true north) instead.
module = len(sys.argv) > 9
tilt, azimuth = float(tilt), float(azimuth)
col, row = 30, 30
steps = f"{work}/steps_{model}.tif"
subprocess.run([skysweep, "insolation", "-q", "--device", "reference", "--weather", weather,
                "--time", window, "--sky-model", model, "--directions", "64",
                "--albedo", "0.2", "--steps", steps, plane, f"{work}/out_{model}.tif"]
               + (["--surface", f"{tilt:g},{azimuth:g}"] if module else []),
               check=True)
values = subprocess.run(["gdallocationinfo", "-valonly", steps, str(col), str(row)],
                        check=True, capture_output=True, text=True).stdout.split()
ours = np.array([float(v) for v in values])  # Wh/m^2 over 1 h records: W/m^2

records = pd.read_csv(io.StringIO(subprocess.run(
    [skysweep, "weather", weather], check=True, capture_output=True, text=True).stdout),
    comment="#")
sun_time = pd.to_datetime(records["sun_time"], utc=True)
start, duration = window.split("/")
t0 = pd.Timestamp(start)
t1 = t0 + pd.Timedelta(duration)
inside = (sun_time >= t0) & (sun_time < t1)
rec = records[inside.values]
times = pd.DatetimeIndex(sun_time[inside.values])

# The cell's place, from its centre in the plane's CRS.
info = subprocess.run(["gdalinfo", "-json", plane], check=True, capture_output=True,
                      text=True).stdout
gt = pd.read_json(io.StringIO(info), typ="series")["geoTransform"]
x, y = gt[0] + (col + 0.5) * gt[1], gt[3] + (row + 0.5) * gt[5]
lonlat = subprocess.run(["gdaltransform", "-s_srs", "EPSG:32632", "-t_srs", "EPSG:4326",
                         "-output_xy"], input=f"{x} {y}\n{x} {y + 1000}\n", check=True,
                        capture_output=True, text=True).stdout.split()
lon, lat, lon_n, lat_n = (float(v) for v in lonlat)
# The plane faces AZIMUTH in the grid; its true azimuth adds grid north's
# (meridian convergence: the bearing from the cell to a point up the grid).
p1, p2, dl = np.radians(lat), np.radians(lat_n), np.radians(lon_n - lon)
grid_north = np.degrees(np.arctan2(np.sin(dl) * np.cos(p2),
                                   np.cos(p1) * np.sin(p2) - np.sin(p1) * np.cos(p2) * np.cos(dl)))
if not module:
    azimuth = azimuth + grid_north
sun = pvlib.solarposition.get_solarposition(times, lat, lon, altitude=500)
r = pvlib.solarposition.nrel_earthsun_distance(times)
dni_extra = 1367.0 / r ** 2
ghi = rec["ghi"].clip(lower=0).values
if rec["dni"].isna().all() and rec["dhi"].isna().all():
    # GHI alone: skysweep splits it by Erbs, at the DEM's centre
    split = pvlib.irradiance.erbs(ghi, sun["zenith"].values, times)
    dni, dhi = split["dni"].values, split["dhi"].values
elif rec["dni"].isna().all():  # GHI and DHI: DNI by closure (pvlib's NaN: no beam)
    dhi = rec["dhi"].clip(lower=0).values
    dni = pvlib.irradiance.dni(pd.Series(ghi, index=times), pd.Series(dhi, index=times),
                               sun["zenith"]).fillna(0).values
else:
    dni, dhi = rec["dni"].clip(lower=0).values, rec["dhi"].clip(lower=0).values
poa = pvlib.irradiance.get_total_irradiance(
    tilt, azimuth, sun["zenith"].values, sun["azimuth"].values, dni, ghi, dhi,
    dni_extra=dni_extra.values, albedo=0.2, model=model)
theirs = np.asarray(poa["poa_global"], dtype=float)
# pvlib's Perez gives NaN where DHI is 0 (no clearness bin): there the sky
# adds nothing, and the rest is beam and ground.
no_sky = np.isnan(theirs) & (np.asarray(dhi) == 0)
theirs[no_sky] = np.asarray(poa["poa_direct"] + poa["poa_ground_diffuse"], dtype=float)[no_sky]

failed = 0
ok = len(ours) == len(theirs)
print(("ok" if ok else "not ok"), f"- {len(ours)} steps, {len(theirs)} records")
if ok:
    up = sun["zenith"].values < 90
    diff = np.abs(ours - theirs)
    allowed = np.maximum(1.0, 0.005 * np.abs(theirs))
    bad = up & ~(diff <= allowed)  # NaN counts as a disagreement
    worst = np.argmax(np.where(up, np.nan_to_num(diff / allowed, nan=1e9), 0))
    ok = not bad.any()
    print(("ok" if ok else "not ok"),
          f"- {model}, tilt {tilt:g}, azimuth {azimuth:g}: {up.sum()} daylight records, "
          f"{bad.sum()} beyond 0.5 % or 1 W/m2; worst at {times[worst]}: skysweep "
          f"{ours[worst]:.2f}, pvlib {theirs[worst]:.2f} W/m2 (zenith "
          f"{sun['zenith'].values[worst]:.2f})")
sys.exit(0 if ok else 1)
