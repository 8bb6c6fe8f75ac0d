/* Heightmaps through OpenImageIO (see heightmap_input.h): 16-bit PNGs, EXR
 * and float TIFFs whose raw sample values are heights, which GDAL would
 * read too but without the EXR support or the alpha channel as nodata. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "heightmap_input.h"
#ifdef HAVE_OIIO
#include "images.h"
#endif

/* Heights beyond this are fill values, not terrain (as dem_read.c). */

ss_status heightmap_read(run_state *run, const char *const *paths, int n_paths,
                         const common_settings *common, ss_dem *dem)
{
    memset(dem, 0, sizeof *dem);
#ifndef HAVE_OIIO
    (void)paths;
    (void)n_paths;
    (void)common;
    return ss_ctx_error(run->ctx, SS_ERR_DEVICE,
                        "skysweep was built without OpenImageIO: --heightmap is unavailable "
                        "(install libopenimageio-dev and rebuild)");
#else
    if (n_paths != 1)
        return ss_ctx_error(run->ctx, SS_ERR_ARGUMENT,
                            "--heightmap reads one image, not %d (mosaics need georeferenced "
                            "tiles)",
                            n_paths);
    if (!(common->cell_size_m > 0))
        return ss_ctx_error(run->ctx, SS_ERR_ARGUMENT,
                            "--heightmap needs the cell size: --cell-size METRES");
    ss_status st = ss_image_read_heightmap(run->ctx, paths[0], common->cell_size_m, common->z_scale,
                                           0.0, &dem->grid);
    if (st != SS_OK)
        return st;
    const double identity[6] = {0, 1, 0, 0, 0, -1};
    memcpy(dem->geotransform, identity, sizeof identity);
    size_t n = (size_t)dem->grid.width * (size_t)dem->grid.height;
    for (size_t i = 0; i < n; ++i) {
        float *z = &dem->grid.z[i];
        if (isnan(*z))
            dem->nodata_cells++;
        else if (!(fabs(*z) <= SS_Z_PLAUSIBLE_M)) {
            *z = NAN;
            dem->rejected_cells++;
        }
    }
    dem->z_unit_m = common->z_scale;
    snprintf(dem->z_unit_source, sizeof dem->z_unit_source, "%g m per pixel value (--z-scale)",
             common->z_scale);
    snprintf(dem->description, sizeof dem->description,
             "%s (heightmap: %g m cells, height = pixel x %g)", paths[0], common->cell_size_m,
             common->z_scale);
    return SS_OK;
#endif
}
