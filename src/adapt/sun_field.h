/* The sun seen from every cell of a DEM at one instant: SPA once at the
 * grid's centre for the sun's geocentric direction, then that direction
 * rotated into each cell's local frame (with parallax) by the geodesy
 * adapter on a coarse lattice and interpolated between (the field is
 * smooth: it turns by about 0.009 degrees per km), with refraction applied
 * per cell. Azimuths are given in the grid's frame, ready for cell slopes
 * and the sweep's lines. */
#ifndef SS_SUN_FIELD_H
#define SS_SUN_FIELD_H

#include "frame.h"
#include "spa.h"

typedef struct {
    int width, height;
    ss_spa_result centre;       /* full SPA at the grid's centre */
    double centre_grid_azimuth_deg; /* the sun's azimuth in the grid frame at the centre */
    /* Per cell, or NULL when one sun serves the whole grid: */
    float *grid_azimuth_deg;     /* clockwise from the grid's north */
    float *elevation_deg;        /* true (airless) */
    float *apparent_elevation_deg;
    double spread_deg;          /* largest angle between a cell's sun and the centre's */
} ss_sun_field;

/* per_cell 0 fills only the centre (one sun for the scene). A DEM without a
 * CRS has no place on Earth: it needs an explicit sun (ss_sun_field_fixed). */
ss_status ss_sun_field_compute(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                               double unix_s, const ss_spa_params *params, int per_cell,
                               ss_sun_field *field);
/* A sun given by its azimuth (true, or grid for a DEM without a CRS) and
 * apparent elevation, the same for every cell. */
void ss_sun_field_fixed(const ss_dem_frame *frame, int width, int height, double azimuth_deg,
                        double apparent_elevation_deg, ss_sun_field *field);
void ss_sun_field_free(ss_sun_field *field);

/* The sun at cell c: grid azimuth and apparent elevation, degrees. */
static inline void ss_sun_field_at(const ss_sun_field *f, size_t c, double *grid_azimuth_deg,
                                   double *apparent_elevation_deg)
{
    *grid_azimuth_deg = f->grid_azimuth_deg ? f->grid_azimuth_deg[c] : f->centre_grid_azimuth_deg;
    *apparent_elevation_deg = f->apparent_elevation_deg ? f->apparent_elevation_deg[c]
                                                        : f->centre.apparent_elevation_deg;
}

#endif
