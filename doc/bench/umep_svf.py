"""UMEP's sky-view factor (the `solweig` package from PyPI), for umep_svf.sh.

usage (with the Python of a venv that has `pip install solweig`):
  umep_svf.py svf DSM OUT.tif [--canopy CDSM]
      Reads the DSM (and the CDSM: tree heights above the ground, UMEP's
      convention), runs solweig's own SVF as its SurfaceData.prepare() does
      (SurfaceData.preprocess(), then compute_svf(): the Rust
      skyview.calculate_svf over 153 sky patches, patch_option 2), and writes
      svf, svf_veg and svfbuveg (svf - (1 - svf_veg)(1 - 0.03), solweig's
      adjust_svfbuveg_with_psi at transmissivity 0.03) as three Float32
      bands on the DSM's grid.
      Prints one line: "svf_seconds S", the time of compute_svf() alone.
  umep_svf.py compare OURS.tif OURS_BAND THEIRS.tif THEIRS_BAND
      Prints "mean P95 MAX N": |ours - theirs| over the cells where both are
      finite, leaving out a 2-cell border.

Without --canopy no DEM is given: solweig's SVF reads only the DSM. With it,
no DEM either, so that solweig adds the CDSM to the DSM, as UMEP's SVF
calculator and skysweep's `--canopy-heights above-ground` do (given a DEM,
solweig adds it to the DEM instead).
"""
import sys
import time

import numpy as np
import rasterio

TRANSMISSIVITY = 0.03


def read(path):
    with rasterio.open(path) as src:
        band = src.read(1).astype(np.float32)
        nodata = src.nodata
        profile = src.profile
    if nodata is not None:
        band[band == np.float32(nodata)] = np.nan
    return band, profile


def umep_svf(dsm_path, out_path, canopy_path):
    import solweig
    from solweig.components.svf_resolution import adjust_svfbuveg_with_psi

    dsm, profile = read(dsm_path)
    cdsm = read(canopy_path)[0] if canopy_path else None
    pixel = abs(profile["transform"].a)
    surface = solweig.SurfaceData(dsm=dsm, cdsm=cdsm, pixel_size=pixel)
    surface.preprocess()
    start = time.perf_counter()
    surface.compute_svf()
    seconds = time.perf_counter() - start
    svf = surface.svf
    # UMEP's svfbuveg with the crowns' transmissivity, as SOLWEIG's model uses it
    # (skysweep's band 3 at its default --transmissivity 0.03).
    svfbuveg = adjust_svfbuveg_with_psi(svf.svf, svf.svf_veg, TRANSMISSIVITY, cdsm is not None)
    profile.update(count=3, dtype="float32", nodata=None, compress="deflate")
    with rasterio.open(out_path, "w", **profile) as dst:
        dst.write(np.stack([svf.svf, svf.svf_veg, svfbuveg]).astype(np.float32))
        dst.set_band_description(1, "svf")
        dst.set_band_description(2, "svf_veg")
        dst.set_band_description(3, "svfbuveg")
    print(f"svf_seconds {seconds:.4f}")


def compare(ours_path, ours_band, theirs_path, theirs_band):
    with rasterio.open(ours_path) as src:
        ours = src.read(int(ours_band)).astype(np.float64)
    with rasterio.open(theirs_path) as src:
        theirs = src.read(int(theirs_band)).astype(np.float64)
    diff = np.abs(ours - theirs)[2:-2, 2:-2]
    diff = diff[np.isfinite(diff)]
    print(f"{diff.mean():.4f} {np.percentile(diff, 95):.4f} {diff.max():.4f} {diff.size}")


def main(argv):
    if len(argv) >= 3 and argv[0] == "svf":
        canopy = None
        if len(argv) == 5 and argv[3] == "--canopy":
            canopy = argv[4]
        elif len(argv) != 3:
            sys.exit(__doc__)
        umep_svf(argv[1], argv[2], canopy)
    elif len(argv) == 5 and argv[0] == "compare":
        compare(*argv[1:])
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv[1:])
