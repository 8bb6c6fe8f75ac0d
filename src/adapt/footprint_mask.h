/* GDAL/OGR adapter of skysweep canopy: the cells building footprints
 * cover, each footprint grown by a buffer first (overhanging eaves, a
 * footprint drawn a little off the lidar). */
#ifndef SS_FOOTPRINT_MASK_H
#define SS_FOOTPRINT_MASK_H

#include "roofs_io.h"

/* Sets mask[row * width + col] to 1 where the cell's centre lies inside a
 * footprint of f grown by buffer_m metres (0: as drawn), else 0; mask has
 * the DEM's width * height cells. The footprints' geometries are in the
 * DEM's CRS (ss_footprints_read); a buffer needs a projected one. */
ss_status ss_footprints_mask(ss_ctx *ctx, const ss_dem *dem, const ss_footprints *f,
                             double buffer_m, unsigned char *mask);

#endif
