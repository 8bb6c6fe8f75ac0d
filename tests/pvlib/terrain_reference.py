"""A year of real sky in terrain: skysweep's annual global (kWh/m^2) at
chosen cells of a DEM agrees within 1 % with an independent reference. The
reference combines, per cell:
- a brute-force horizon profile: rays every degree from the cell's centre,
  heights interpolated bilinearly every half cell to the DEM's edge;
- the cell's Horn gradient;
- pvlib's SPA sun (refracted for the shadow test), its Perez model
  (get_total_irradiance's components), and the terrain rules of
  doc/insolation.md: the isotropic part through the tilted sky view
  (Dozier & Frew over the profile, the horizon clipped at the horizontal and
  the cell's tangent plane), the circumsolar part shaded like the beam, the
  horizon band (0 to 6.5 degrees) weighted by the share of it the profile
  leaves open, the
  ground's reflection albedo * GHI * (1 - sky view), and isotropic diffuse
  light while the sun is below the horizontal.

Usage: python terrain_reference.py SKYSWEEP WEATHER DEM.tif WORKDIR. The DEM
must be in EPSG:32632 (the PVGIS file's site lies in UTM 32N). Prints
TAP-style lines; exits non-zero if a cell disagrees.
"""
import io
import subprocess
import sys

import numpy as np
import pandas as pd
import pvlib


def run(*args, **kw):
    return subprocess.run(args, check=True, capture_output=True, text=True, **kw).stdout


skysweep, weather, dem_path, work = sys.argv[1:5]
out = f"{work}/terrain_year.tif"
run(skysweep, "insolation", "-q", "--device", "reference", "--weather", weather,
    "--sky-model", "perez", "--shadow", "exact", "--directions", "64", "--curvature", "off",
    "--albedo", "0.2",
    dem_path, out)
for lines in ("interpolated", "digital"):
    run(skysweep, "svf", "-q", "--device", "reference", "--directions", "64", "--curvature",
        "off", "--definition", "radiative", "--lines", lines, dem_path,
        f"{work}/terrain_svf_{lines}.tif")

# The DEM as text (AAIGrid), read with numpy alone.
run("gdal_translate", "-q", "-of", "AAIGrid", dem_path, f"{work}/dem.asc")
z = np.loadtxt(f"{work}/dem.asc", skiprows=6)
svf_of = {}
for lines in ("interpolated", "digital"):
    run("gdal_translate", "-q", "-of", "AAIGrid", f"{work}/terrain_svf_{lines}.tif",
        f"{work}/svf.asc")
    svf_of[lines] = np.loadtxt(f"{work}/svf.asc", skiprows=6)
svf = svf_of["interpolated"]
info = pd.read_json(io.StringIO(run("gdalinfo", "-json", dem_path)), typ="series")
gt = info["geoTransform"]
cell = gt[1]
rows, cols = z.shape

# Cells: percentiles of the sky view from the most enclosed, and the
# steepest, away from the edges (Horn needs neighbours; horizons must have
# terrain to see), where the DEM pins the horizon down: where the heights a
# model reads between cell centres decide the near horizon (a pit beside a
# cliff), skysweep's two line models, and this bilinear reference, differ by
# design (doc/model.md). Kept: cells whose sky views under interpolated and
# digital lines agree within 0.005.
gy, gx = np.gradient(z, cell)
steep = np.degrees(np.arctan(np.hypot(gx, gy)))
inner = np.zeros_like(z, dtype=bool)
inner[10:-10, 10:-10] = True
inner &= np.abs(svf_of["interpolated"] - svf_of["digital"]) < 0.005
print(f"# {inner.sum()} of {(rows - 20) * (cols - 20)} inner cells are pinned down")
order = np.argsort(np.where(inner, svf, np.inf), axis=None)[:inner.sum()]
picks = [order[int(q * (len(order) - 1))] for q in (0.0, 0.01, 0.05, 0.25, 0.5)]
picks.append(np.argmax(np.where(inner, steep, -1)))
cells = [np.unravel_index(p, z.shape) for p in dict.fromkeys(picks)]

records = pd.read_csv(io.StringIO(run(skysweep, "weather", weather)), comment="#")
times = pd.DatetimeIndex(pd.to_datetime(records["sun_time"], utc=True))
dni, ghi, dhi = (records[c].clip(lower=0).values for c in ("dni", "ghi", "dhi"))


def bilinear(y, x):
    y0 = np.clip(np.floor(y).astype(int), 0, rows - 2)
    x0 = np.clip(np.floor(x).astype(int), 0, cols - 2)
    fy, fx = y - y0, x - x0
    return ((1 - fy) * (1 - fx) * z[y0, x0] + (1 - fy) * fx * z[y0, x0 + 1] +
            fy * (1 - fx) * z[y0 + 1, x0] + fy * fx * z[y0 + 1, x0 + 1])


def horizon_profile(r, c):
    """Elevation angle (deg) of the terrain horizon every degree of grid azimuth."""
    az = np.radians(np.arange(360.0))
    steps = np.arange(0.5, 2.0 * max(rows, cols), 0.5)
    x = c + np.outer(np.sin(az), steps)
    y = r - np.outer(np.cos(az), steps)
    inside = (x >= 0) & (x <= cols - 1) & (y >= 0) & (y <= rows - 1)
    dz = np.where(inside, bilinear(np.where(inside, y, 0), np.where(inside, x, 0)) - z[r, c],
                  -np.inf)
    return np.degrees(np.arctan(np.max(dz / (steps * cell), axis=1)))


failed = 0
for r, c in cells:
    # Horn's gradient: east and north components.
    w = z[r - 1:r + 2, c - 1:c + 2]
    dz_de = ((w[0, 2] + 2 * w[1, 2] + w[2, 2]) - (w[0, 0] + 2 * w[1, 0] + w[2, 0])) / (8 * cell)
    dz_dn = ((w[0, 0] + 2 * w[0, 1] + w[0, 2]) - (w[2, 0] + 2 * w[2, 1] + w[2, 2])) / (8 * cell)
    slope = np.arctan(np.hypot(dz_de, dz_dn))
    aspect = np.degrees(np.arctan2(-dz_de, -dz_dn)) % 360  # the way it faces, grid azimuth
    h = horizon_profile(r, c)
    az = np.radians(np.arange(360.0))
    norm = np.sqrt(1 + dz_de ** 2 + dz_dn ** 2)
    rise = dz_de * np.sin(az) + dz_dn * np.cos(az)
    he = np.maximum(np.maximum(np.radians(h), 0), np.arctan(np.maximum(rise, 0)))
    sky_view = np.mean((np.cos(he) ** 2 - rise * (np.pi / 2 - he - np.sin(he) * np.cos(he)))
                       / norm)
    facing = np.maximum(-rise / norm, 0)
    open_share = np.clip(1 - h / 6.5, 0, 1)  # of the 6.5-degree band, per direction
    band = np.sum(facing * open_share) / np.sum(facing) if facing.sum() > 0 else 1.0

    # Where the cell lies, and the true azimuth of grid north there.
    x, y = gt[0] + (c + 0.5) * gt[1], gt[3] + (r + 0.5) * gt[5]
    lon, lat, lon_n, lat_n = (float(v) for v in run(
        "gdaltransform", "-s_srs", "EPSG:32632", "-t_srs", "EPSG:4326", "-output_xy",
        input=f"{x} {y}\n{x} {y + 1000}\n").split())
    p1, p2, dl = np.radians(lat), np.radians(lat_n), np.radians(lon_n - lon)
    north = np.degrees(np.arctan2(np.sin(dl) * np.cos(p2), np.cos(p1) * np.sin(p2) -
                                  np.sin(p1) * np.cos(p2) * np.cos(dl)))
    sun = pvlib.solarposition.get_solarposition(times, lat, lon, altitude=z[r, c])
    dni_extra = (1367.0 / pvlib.solarposition.nrel_earthsun_distance(times) ** 2).values
    zen, sun_az = sun["zenith"].values, sun["azimuth"].values
    grid_az = (sun_az - north) % 360
    horizon_at_sun = np.interp(grid_az, np.arange(361.0), np.append(h, h[0]))
    up = zen < 90
    aoi = pvlib.irradiance.aoi_projection(np.degrees(slope), aspect + north, zen, sun_az)
    lit = up & (sun["apparent_elevation"].values > horizon_at_sun) & (aoi > 0)
    am = pvlib.atmosphere.get_relative_airmass(zen)
    parts = pvlib.irradiance.perez(np.degrees(slope), aspect + north, dhi, dni, dni_extra, zen,
                                   sun_az, am, return_components=True)
    plane_iso = (1 + np.cos(slope)) / 2
    iso, circ, hor = (np.nan_to_num(np.asarray(parts[k], dtype=float))
                      for k in ("poa_isotropic", "poa_circumsolar", "poa_horizon"))
    diffuse = np.maximum(iso / plane_iso * sky_view + circ * lit + hor * band, 0)
    diffuse = np.where(up, diffuse, dhi * sky_view)
    beam = np.where(lit, dni * np.maximum(aoi, 0), 0)
    reflected = 0.2 * ghi * (1 - sky_view)
    theirs = np.sum(beam + diffuse + reflected) / 1000
    ours = float(run("gdallocationinfo", "-valonly", "-b", "1", out, str(c), str(r)))
    ok = abs(ours - theirs) <= 0.01 * theirs
    failed += not ok
    print(("ok" if ok else "not ok"),
          f"- cell ({c}, {r}): slope {np.degrees(slope):.1f} deg facing {aspect:.0f}, sky view "
          f"{sky_view:.3f} (skysweep {svf[r, c]:.3f}), band open {band:.2f}, lit "
          f"{lit.sum()} h: skysweep {ours:.1f}, reference {theirs:.1f} kWh/m2 "
          f"({100 * (ours - theirs) / theirs:+.2f} %)")
sys.exit(1 if failed else 0)
