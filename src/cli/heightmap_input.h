/* --heightmap: a plain image read through OpenImageIO as the DEM. */
#ifndef SS_CLI_HEIGHTMAP_INPUT_H
#define SS_CLI_HEIGHTMAP_INPUT_H

#include "run.h"

/* Reads the one input image as a DEM of --cell-size metre cells with
 * heights pixel * --z-scale. Without a CRS the DEM has grid north and
 * GDAL's identity geotransform, as a heightmap read by GDAL would, so its
 * outputs and drapes compare alike. */
ss_status heightmap_read(run_state *run, const char *const *paths, int n_paths,
                         const common_settings *common, ss_dem *dem);

#endif
