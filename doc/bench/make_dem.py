#!/usr/bin/python3
"""Synthetic DEM for the peer benchmark (doc/performance.sh).

A self-affine surface from spectral synthesis: random phases, power spectrum
P(k) ~ (k^2 + k0^2)^(-beta/2) with beta = 4 and a corner wavelength of 20 km,
scaled to an RMS gradient of 0.35 (about 19 degrees). With beta = 4 every
octave of wavelength contributes alike to the gradient, so DEMs of every size
look like "the same terrain, just more of it": relief grows with the extent
up to the corner wavelength (about 550 m at 128 x 128 cells, 2 km at 1024,
2.9 km at 4096).

Float32 GeoTIFF, 30 m cells, WGS 84 / UTM 31N, centred on the zone's central
meridian near the equator, where grid north is true north to within 0.06
degrees even at 8192 x 8192 cells: GRASS r.horizon turns its directions to
true north, skysweep works in grid directions, and here the two coincide.
Written uncompressed: WhiteboxTools reads DEFLATE + PREDICTOR=3 floats as NaN.

usage: make_dem.py SIZE OUT.tif   (SIZE x SIZE cells; the seed is SIZE)
"""
import sys

import numpy as np
from osgeo import gdal, osr

CELL_M = 30.0
CORNER_WAVELENGTH_M = 20000.0
BETA = 4.0
RMS_GRADIENT = 0.35
BASE_M = 1500.0
EPSG = 32631
CENTRE_E, CENTRE_N = 500000.0, 200000.0


def surface(n):
    rng = np.random.default_rng(n)
    ky = np.fft.fftfreq(n, d=CELL_M)[:, None]
    kx = np.fft.rfftfreq(n, d=CELL_M)[None, :]
    k0 = 1.0 / CORNER_WAVELENGTH_M
    amplitude = (kx * kx + ky * ky + k0 * k0) ** (-BETA / 4.0)
    amplitude[0, 0] = 0.0
    phase = np.exp(2j * np.pi * rng.random(amplitude.shape))
    z = np.fft.irfft2(amplitude * phase, s=(n, n))
    dz_dy, dz_dx = np.gradient(z, CELL_M)
    z *= RMS_GRADIENT / np.sqrt(np.mean(dz_dx * dz_dx + dz_dy * dz_dy))
    return (BASE_M + z).astype(np.float32)


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    n, out = int(sys.argv[1]), sys.argv[2]
    ds = gdal.GetDriverByName("GTiff").Create(
        out, n, n, 1, gdal.GDT_Float32, ["BIGTIFF=IF_SAFER"])
    half = n * CELL_M / 2.0
    ds.SetGeoTransform((CENTRE_E - half, CELL_M, 0.0, CENTRE_N + half, 0.0, -CELL_M))
    srs = osr.SpatialReference()
    srs.ImportFromEPSG(EPSG)
    ds.SetProjection(srs.ExportToWkt())
    ds.GetRasterBand(1).WriteArray(surface(n))
    ds.FlushCache()


if __name__ == "__main__":
    main()
