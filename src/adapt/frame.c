/* Builds a DEM's frame from its CRS through the geodesy adapter. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "skysweep.h"
#include "frame.h"

ss_status ss_dem_frame_open(ss_ctx *ctx, ss_dem *dem, ss_dem_frame *frame)
{
    memset(frame, 0, sizeof *frame);
    frame->earth_radius_m = SS_EARTH_RADIUS_MEAN_M; /* heightmaps without a CRS */
    frame->cell_x_m = dem->grid.cell_x_m;
    frame->cell_y_m = dem->grid.cell_y_m;
    if (!dem->crs_wkt)
        return SS_OK;
    ss_status st = ss_geo_open(ctx, dem->crs_wkt, dem->geotransform, dem->grid.width,
                               dem->grid.height, &frame->geo);
    ss_geo_summary sum;
    if (st == SS_OK)
        st = ss_geo_extent_summary(frame->geo, &sum);
    if (st == SS_OK) {
        double cc = (dem->grid.width - 1) / 2.0, cr = (dem->grid.height - 1) / 2.0;
        st = ss_geo_cell_size(frame->geo, cc, cr, &frame->cell_x_m, &frame->cell_y_m);
    }
    if (st != SS_OK) {
        ss_dem_frame_close(frame);
        return st;
    }
    frame->georeferenced = 1;
    frame->geographic = ss_geo_is_geographic(frame->geo);
    frame->centre_lon_deg = sum.centre_lon_deg;
    frame->centre_lat_deg = sum.centre_lat_deg;
    /* + 0.0 turns a -0 (exactly north on lat/lon grids) into 0 for printing. */
    frame->grid_north_deg = sum.grid_north_centre_deg + 0.0;
    frame->grid_north_min_deg = sum.grid_north_min_deg + 0.0;
    frame->grid_north_max_deg = sum.grid_north_max_deg + 0.0;
    frame->cell_variation = sum.cell_variation;
    frame->earth_radius_m = sum.centre_earth_radius_m;
    frame->diagonal_m = sum.diagonal_m;
    dem->grid.cell_x_m = frame->cell_x_m;
    dem->grid.cell_y_m = frame->cell_y_m;
    return SS_OK;
}

void ss_dem_frame_close(ss_dem_frame *frame)
{
    ss_geo_close(frame->geo);
    frame->geo = NULL;
}
