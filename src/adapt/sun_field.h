/* The sun seen from every cell of a DEM at one instant: SPA once at the
 * grid's centre for the sun's geocentric direction, then that direction
 * rotated into each cell's local frame (with parallax) by the geodesy
 * adapter on a coarse lattice and interpolated between (the field is
 * smooth: it turns by about 0.009 degrees per km), with refraction
 * interpolated the same way where the sun stands above the horizontal at
 * the nodes around a cell, and computed per cell below, where it bends
 * sharply. Azimuths are given in the grid's frame, ready for cell slopes
 * and the sweep's lines. */
#ifndef SS_SUN_FIELD_H
#define SS_SUN_FIELD_H

#include "frame.h"
#include "skysweep_sun.h"

typedef struct {
    int width, height;
    ss_spa_result centre;       /* full SPA at the grid's centre */
    double centre_grid_azimuth_deg; /* the sun's azimuth in the grid frame at the centre */
    /* Per cell of rows [row0, row0 + rows), or NULL when one sun serves the
     * whole grid (cell indices count from the first of those rows): */
    int row0, rows;
    float *grid_azimuth_deg;     /* clockwise from the grid's north */
    float *elevation_deg;        /* true (airless) */
    float *apparent_elevation_deg;
    double spread_deg;          /* largest angle between a cell's sun and the centre's */
    /* The lattice that per-cell positions are interpolated from (NULL when
     * one sun serves the grid). */
    int *lattice_cols, *lattice_rows, n_lattice_cols, n_lattice_rows;
    double *node_azimuth_deg, *node_elevation_deg, *node_refraction_deg;
    ss_spa_params params;
} ss_sun_field;

/* The lattice's nodes as they stay from one instant to the next: where
 * they lie, and each node's longitude, latitude, grid north (the true
 * azimuth of the grid's north) and height. Made once for a run of many
 * instants, so that an instant costs each node's sun direction alone; the
 * heights come from read (NULL: from dem->grid.z). */
typedef struct {
    int *cols, *rows, n_cols, n_rows; /* the whole grid's lattice */
    double *lon_deg, *lat_deg, *north_deg, *height_m; /* per node, row by row */
} ss_sun_nodes;
ss_status ss_sun_nodes_make(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                            ss_rows_read read, void *user, ss_sun_nodes *nodes);
void ss_sun_nodes_free(ss_sun_nodes *nodes);

/* per_cell 0 fills only the centre (one sun for the scene); else every
 * cell. A DEM without a CRS has no place on Earth: it needs an explicit
 * sun (ss_sun_field_fixed). */
ss_status ss_sun_field_compute(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                               double unix_s, const ss_spa_params *params, int per_cell,
                               ss_sun_field *field);
/* The same without filling cells, from the nodes made before (per_cell
 * only): the lattice rows that rows [row_lo, row_hi) lie between;
 * ss_sun_field_rows then fills rows in that range. spread_deg covers those
 * lattice rows only. */
ss_status ss_sun_field_lattice(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                               double unix_s, const ss_spa_params *params, int per_cell,
                               int row_lo, int row_hi, const ss_sun_nodes *nodes,
                               ss_sun_field *field);
/* Per-cell positions for rows [row0, row0 + rows) only (nothing to do for
 * one sun), interpolated by ss_sun_lattice_cells. */
ss_status ss_sun_field_rows(ss_ctx *ctx, ss_sun_field *field, int row0, int rows);
/* The field's lattice (per_cell only) as the library takes it: a view of
 * the field's own arrays, valid while the field is. */
void ss_sun_field_lattice_of(const ss_sun_field *field, ss_sun_lattice *lattice);
/* A sun given by its azimuth (true, or grid for a DEM without a CRS) and
 * apparent elevation, the same for every cell. */
void ss_sun_field_fixed(const ss_dem_frame *frame, int width, int height, double azimuth_deg,
                        double apparent_elevation_deg, ss_sun_field *field);
void ss_sun_field_free(ss_sun_field *field);

/* Whether the cells have suns of their own (else one sun serves the grid). */
static inline int ss_sun_field_per_cell(const ss_sun_field *f)
{
    return f->node_azimuth_deg != NULL;
}

/* The sun at cell c: grid azimuth and apparent elevation, degrees. */
static inline void ss_sun_field_at(const ss_sun_field *f, size_t c, double *grid_azimuth_deg,
                                   double *apparent_elevation_deg)
{
    *grid_azimuth_deg = f->grid_azimuth_deg ? f->grid_azimuth_deg[c] : f->centre_grid_azimuth_deg;
    *apparent_elevation_deg = f->apparent_elevation_deg ? f->apparent_elevation_deg[c]
                                                        : f->centre.apparent_elevation_deg;
}

#endif
