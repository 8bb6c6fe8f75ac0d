/* GDAL adapter: a raster brought onto a DEM's grid (canopy heights for
 * shadow --canopy), read as it is where it lies on the grid, else warped. */
#ifndef SS_GRID_WARP_H
#define SS_GRID_WARP_H

#include "dem_io.h"

/* Band 1 of path on dem's grid into values (width * height, SS_NODATA at
 * nodata): read as it is when it has the DEM's size and geotransform (to a
 * millionth of a cell), else warped by GDAL (the highest source cell over
 * each DEM cell) when both are georeferenced and it covers the whole DEM;
 * otherwise refused (SS_ERR_INPUT) in one line naming `what`. *warped says
 * which. */
ss_status ss_raster_onto_dem(ss_ctx *ctx, const char *path, const char *what, const ss_dem *dem,
                             float *values, int *warped);

#endif
