#!/usr/bin/python3
"""Numeric agreement of a peer tool's output with skysweep's (doc/performance.sh).

usage:
  compare.py horizon OURS.tif PEER [options]
      OURS: degrees, band i = azimuth 360 i / N clockwise from north.
      PEER: a file in the same layout (WhiteboxTools), or a directory of GRASS
      r.horizon maps exported as hor_AAA_B.tif (radians, azimuth AAA.B
      degrees counter-clockwise from east), each matched to the band with the
      same compass azimuth. Both sides are clipped at 0 first: r.horizon's
      manual says it clips there (GRASS 8.2 in fact reports negative
      horizons, and -90 where nothing lies ahead, as skysweep does), and
      what lies below the horizontal matters to neither SVF nor shadows.
  compare.py field OURS.tif PEER.tif [--peer-scale S] [--peer-offset O] [options]
      one band each; the peer's value is mapped to S * value + O first.

options: --tol T (absolute; with --relative, a fraction of |ours|),
         --border CELLS left out along every edge (default 2).

Prints one tab-separated line: mean |peer - ours|, max |peer - ours|,
mean (peer - ours), fraction of cells within the tolerance, cells compared,
Pearson correlation, note.
"""
import argparse
import glob
import math
import os
import sys

import numpy as np
from osgeo import gdal, osr

gdal.UseExceptions()


def read_band(ds, index):
    band = ds.GetRasterBand(index)
    values = band.ReadAsArray().astype(np.float64)
    nodata = band.GetNoDataValue()
    if nodata is not None:
        values[values == nodata] = np.nan
    return values


def grid_convergence_deg(ds):
    """Angle from grid north to true north at the DEM centre (0 if unknown)."""
    wkt = ds.GetProjection()
    if not wkt:
        return 0.0
    srs = osr.SpatialReference(wkt=wkt)
    if srs.IsGeographic():
        return 0.0
    geo = srs.CloneGeogCS()
    for s in (srs, geo):
        s.SetAxisMappingStrategy(osr.OAMS_TRADITIONAL_GIS_ORDER)
    to_geo = osr.CoordinateTransformation(srs, geo)
    gt = ds.GetGeoTransform()
    x = gt[0] + gt[1] * ds.RasterXSize / 2
    y = gt[3] + gt[5] * ds.RasterYSize / 2
    lon0, lat0, _ = to_geo.TransformPoint(x, y)
    lon1, lat1, _ = to_geo.TransformPoint(x, y + 1000.0)
    return math.degrees(math.atan2((lon1 - lon0) * math.cos(math.radians(lat0)), lat1 - lat0))


def pairs_horizon(ours_path, peer_path):
    """(ours, peer) arrays in degrees, clipped at 0, one pair per direction."""
    ours = gdal.Open(ours_path)
    n = ours.RasterCount
    if os.path.isdir(peer_path):
        files = sorted(glob.glob(os.path.join(peer_path, "hor_*.tif")))
        if len(files) != n:
            sys.exit(f"compare.py: {len(files)} r.horizon maps in {peer_path}, {n} bands in {ours_path}")
        for path in files:
            ccw_east = float(os.path.basename(path)[4:-4].replace("_", "."))
            index = round((90.0 - ccw_east) % 360.0 * n / 360.0) % n
            peer = np.degrees(read_band(gdal.Open(path), 1))
            yield np.maximum(read_band(ours, index + 1), 0.0), np.maximum(peer, 0.0)
    else:
        peer = gdal.Open(peer_path)
        if peer.RasterCount != n:
            sys.exit(f"compare.py: {peer.RasterCount} bands in {peer_path}, {n} in {ours_path}")
        for i in range(1, n + 1):
            yield np.maximum(read_band(ours, i), 0.0), np.maximum(read_band(peer, i), 0.0)


def pairs_field(ours_path, peer_path, scale, offset):
    yield read_band(gdal.Open(ours_path), 1), scale * read_band(gdal.Open(peer_path), 1) + offset


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("mode", choices=["horizon", "field"])
    p.add_argument("ours")
    p.add_argument("peer")
    p.add_argument("--tol", type=float, required=True)
    p.add_argument("--relative", action="store_true")
    p.add_argument("--border", type=int, default=2)
    p.add_argument("--peer-scale", type=float, default=1.0)
    p.add_argument("--peer-offset", type=float, default=0.0)
    a = p.parse_args()

    if a.mode == "horizon":
        pairs = pairs_horizon(a.ours, a.peer)
        note = ""
        if os.path.isdir(a.peer):
            note = f"grid convergence at centre {grid_convergence_deg(gdal.Open(a.ours)):+.2f} deg"
    else:
        pairs = pairs_field(a.ours, a.peer, a.peer_scale, a.peer_offset)
        note = ""

    # Running sums, one direction at a time: 64 bands of 4096 x 4096 cells
    # would not fit in memory at once.
    b = a.border
    n = within = 0
    sum_abs = max_abs = sum_d = 0.0
    sx = sy = sxx = syy = sxy = 0.0
    for o, q in pairs:
        if o.shape != q.shape:
            sys.exit(f"compare.py: shapes differ: ours {o.shape}, peer {q.shape}")
        if b:
            o, q = o[b:-b, b:-b], q[b:-b, b:-b]
        keep = np.isfinite(o) & np.isfinite(q)
        o, q = o[keep], q[keep]
        if o.size == 0:
            continue
        d = q - o
        tol = a.tol * np.abs(o) if a.relative else a.tol
        n += o.size
        within += int(np.count_nonzero(np.abs(d) <= tol))
        sum_abs += float(np.abs(d).sum())
        max_abs = max(max_abs, float(np.abs(d).max()))
        sum_d += float(d.sum())
        sx, sy = sx + float(o.sum()), sy + float(q.sum())
        sxx, syy, sxy = sxx + float(o @ o), syy + float(q @ q), sxy + float(o @ q)
    if n == 0:
        sys.exit("compare.py: no cells to compare")
    var_o, var_q = sxx / n - (sx / n) ** 2, syy / n - (sy / n) ** 2
    cov = sxy / n - sx * sy / n / n
    r = cov / math.sqrt(var_o * var_q) if var_o > 0 and var_q > 0 else float("nan")
    print(f"{sum_abs / n:.4g}\t{max_abs:.4g}\t{sum_d / n:+.4g}\t{within / n:.4f}\t{n}\t{r:.5f}\t{note}")


if __name__ == "__main__":
    main()
