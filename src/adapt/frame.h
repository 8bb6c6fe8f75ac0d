/* Where a DEM lies on the Earth, as the sweep needs it: ground cell sizes,
 * the true azimuth of grid north, the local earth radius, and the numbers
 * that say how far one value of each misses over the whole grid (for the
 * planner and the metadata). Built from the DEM's CRS by the geodesy
 * adapter; heightmaps without a CRS get a local flat frame. */
#ifndef SS_FRAME_H
#define SS_FRAME_H

#include "dem_io.h"
#include "geodesy.h"

typedef struct {
    int georeferenced;       /* 0: plain heightmap, no CRS: grid north, sphere radius */
    int geographic;          /* the grid is in degrees of lat/lon */
    double centre_lon_deg, centre_lat_deg;
    double grid_north_deg;   /* true azimuth of grid north at the centre */
    double grid_north_min_deg, grid_north_max_deg; /* over the grid */
    double cell_x_m, cell_y_m; /* ground size of a cell at the centre */
    double cell_variation;   /* max relative difference of cell sizes from the centre's */
    double earth_radius_m;   /* Gaussian mean radius at the centre */
    double diagonal_m;       /* longest geodesic diagonal of the grid */
    ss_geo *geo;             /* open georeferencing (NULL for heightmaps) */
} ss_dem_frame;

/* Computes the frame and sets dem->grid's cell sizes to the ground sizes at
 * the centre (metres; lat/lon grids need this before any sweep). */
ss_status ss_dem_frame_open(ss_ctx *ctx, ss_dem *dem, ss_dem_frame *frame);
void ss_dem_frame_close(ss_dem_frame *frame);

#endif
