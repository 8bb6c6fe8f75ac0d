"""The Python peers of doc/performance.sh: read the DEM, compute, write a
Float32 GeoTIFF on the DEM's grid. Run with the peers' venv interpreter; the
whole process is timed, so interpreter start and imports count against them.

usage:
  peers.py wbw-horizon  DEM N OUT   WhiteboxTools horizon_angle, N azimuths
                                    360 i / N clockwise from north, one band
                                    each (skysweep's layout), unlimited
  peers.py wbw-svf      DEM N OUT   WhiteboxTools sky_view_factor (Zaksek),
                                    N directions, unlimited, observer at 0 m
  peers.py rvt-svf      DEM N OUT R RVT sky_view_factor (Zaksek), N directions,
                                    search radius R cells
  peers.py topocalc-svf DEM N OUT   topocalc viewf (Dozier & Frew), N angles,
                                    whole DEM (nodata filled with the minimum)
"""
import math
import sys

import numpy as np
from osgeo import gdal

gdal.UseExceptions()


class Output:
    """A Float32 GeoTIFF with the DEM's size and georeferencing."""

    def __init__(self, dem, path, bands=1):
        self.ds = gdal.GetDriverByName("GTiff").Create(
            path, dem.RasterXSize, dem.RasterYSize, bands, gdal.GDT_Float32,
            ["TILED=YES", "COMPRESS=DEFLATE", "BIGTIFF=IF_SAFER"])
        self.ds.SetGeoTransform(dem.GetGeoTransform())
        self.ds.SetProjection(dem.GetProjection())

    def write(self, values, band=1):
        self.ds.GetRasterBand(band).WriteArray(np.asarray(values, dtype=np.float32))


def cell_size(dem):
    gt = dem.GetGeoTransform()
    if abs(abs(gt[1]) - abs(gt[5])) > 1e-6 * abs(gt[1]):
        sys.exit("peers.py: the Python peers need square cells")
    return abs(gt[1])


def diagonal(dem):
    """Length of the DEM's diagonal in map units: no horizon lies farther."""
    return math.hypot(dem.RasterXSize, dem.RasterYSize) * cell_size(dem)


def elevations(dem):
    band = dem.GetRasterBand(1)
    z = band.ReadAsArray().astype(np.float64)
    nodata = band.GetNoDataValue()
    if nodata is not None:
        z[z == nodata] = np.nan
    return z


def wbw_horizon(dem, path, n, out):
    import whitebox_workflows as wbw
    wbe = wbw.WbEnvironment()
    wbe.verbose = False
    raster = wbe.read_raster(path)
    for i in range(n):
        h = wbe.horizon_angle(raster, azimuth=360.0 * i / n, max_dist=diagonal(dem))
        out.write(h.to_numpy(), i + 1)


def wbw_svf(dem, path, n, out):
    import whitebox_workflows as wbw
    wbe = wbw.WbEnvironment()
    wbe.verbose = False
    svf = wbe.sky_view_factor(wbe.read_raster(path), az_fraction=360.0 / n,
                              max_dist=diagonal(dem), observer_hgt_offset=0.0)
    out.write(svf.to_numpy())


def rvt_svf(dem, n, out, radius):
    import rvt.vis
    result = rvt.vis.sky_view_factor(elevations(dem), resolution=cell_size(dem),
                                     svf_n_dir=n, svf_r_max=radius, svf_noise=0)
    out.write(result["svf"])


def topocalc_svf(dem, n, out):
    from topocalc.viewf import viewf
    # topocalc has no nodata: a NaN spoils the horizons of whole profiles.
    # Holes become the lowest elevation, which hides nothing from the cells
    # around them, and get NaN back afterwards.
    z = elevations(dem)
    holes = np.isnan(z)
    z[holes] = np.nanmin(z)
    svf, _ = viewf(z, cell_size(dem), nangles=n)
    svf[holes] = np.nan
    out.write(svf)


def main():
    if len(sys.argv) < 5:
        sys.exit(__doc__)
    tool, path, n, out_path = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4]
    dem = gdal.Open(path)
    if tool == "wbw-horizon":
        wbw_horizon(dem, path, n, Output(dem, out_path, n))
    elif tool == "wbw-svf":
        wbw_svf(dem, path, n, Output(dem, out_path))
    elif tool == "rvt-svf":
        rvt_svf(dem, n, Output(dem, out_path), int(sys.argv[5]))
    elif tool == "topocalc-svf":
        topocalc_svf(dem, n, Output(dem, out_path))
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main()
