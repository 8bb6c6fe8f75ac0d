/* Horizon profiles of single sites (solar PV and the like): for any
 * azimuths, the horizon that the grid sweep (ss_horizon) gives the site,
 * computed exactly along the same lines of the same line model without
 * sweeping the grid. doc/pv-horizons.md has the conventions and the
 * definition for a site between cell centres. */
#ifndef SKYSWEEP_SITES_H
#define SKYSWEEP_SITES_H

#include "skysweep.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A grid prepared for point horizons: it borrows the grid (which must
 * outlive it) and keeps the block maxima that let a walk skip stretches of
 * a line that cannot cast the horizon. */
typedef struct ss_point_grid ss_point_grid;

SS_API ss_status ss_point_grid_new(ss_ctx *ctx, const ss_grid *grid, ss_point_grid **out);
SS_API void ss_point_grid_free(ss_point_grid *pg);

/* A site. col, row: cell-centre position (the centre of cell (c, r) is
 * col = c, row = r; the grid's outer edges are at -0.5 and width - 0.5).
 * The horizon is the bilinear mix of the four surrounding cells' horizons
 * (cells outside the grid or nodata drop out, and in a direction so do
 * cells with nothing ahead); the site must lie on the grid and its own
 * cell (the nearest centre) must have a height. */
typedef struct {
    double col, row;
    double observer_height_m; /* eye above the ground (>= 0): lifts each cell's viewpoint */
    double grid_north_deg;    /* true azimuth of grid north at the site (0: grid frame) */
} ss_point_site;

/* One direction of a profile. Where no terrain lies ahead inside the grid
 * the elevation is -90, the distance 0 and the casting point NAN. */
typedef struct {
    double azimuth_deg;        /* clockwise from true north (grid north if grid_north_deg is 0) */
    double elevation_deg;      /* above the horizontal; may be negative */
    double distance_m;         /* horizontal, from the site to the casting point */
    double cast_col, cast_row; /* casting point, cell-centre coordinates */
    double cast_height_m;      /* its ground height, z_origin_m included */
} ss_point_horizon_result;

/* Ground height at the site (the same bilinear weights), z_origin_m included.
 * Fails with SS_ERR_ARGUMENT off the grid or on nodata. */
SS_API ss_status ss_point_ground_height(ss_ctx *ctx, const ss_point_grid *pg, double col, double row,
                                 double *height_m);

/* The profile of one site at opt's directions (opt->directions results in
 * out, azimuths ss_direction_azimuth(opt, i)), in opt's line model, with
 * opt's earth curvature and refraction. opt->grid_north_deg is not used:
 * grid north varies over a projected grid, so each site brings its own. At
 * observer height 0 and a cell centre it equals ss_horizon's value for
 * that cell in each direction. */
SS_API ss_status ss_point_horizon(ss_ctx *ctx, const ss_point_grid *pg, const ss_sweep_options *opt,
                           const ss_point_site *site, ss_point_horizon_result *out);

/* Receives one site's profile (opt->directions results); return 0 to stop
 * the run (it then ends with SS_ERR_CANCELLED). */
typedef int (*ss_point_sink)(int site_index, const ss_point_horizon_result *profile, void *user);

/* Profiles of many sites, one after another, each handed to sink, with
 * progress reported to the context's callback. */
SS_API ss_status ss_point_horizons(ss_ctx *ctx, const ss_point_grid *pg, const ss_sweep_options *opt,
                            const ss_point_site *sites, int n_sites, ss_point_sink sink,
                            void *user);

#ifdef __cplusplus
}
#endif
#endif
