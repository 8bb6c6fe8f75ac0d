/* Shade over time on roof planes (doc/roofs.md, "Shade over time"): per
 * plane, the share of its cells in direct sun in each month and hour of
 * the day, averaged over the weather file's records of that month and
 * hour, from one cast-shadow sweep per record with the sun up. */
#ifndef SS_ROOF_SHADE_H
#define SS_ROOF_SHADE_H

#include <stddef.h>
#include <stdint.h>

#include "skysweep.h"

#define SHADE_SLOTS (12 * 24) /* month (0..11) x local hour (0..23) */

typedef struct {
    size_t first; /* its cells: cells[first .. first + n_cells) */
    int n_cells;
    double tilt_deg, aspect_grid_deg;
} shade_plane;

typedef struct {
    shade_plane *planes;
    size_t n_planes, cap_planes;
    int *cells; /* grid cells (row * width + col) */
    size_t n_cells, cap_cells;
    double *lit;               /* n_planes x SHADE_SLOTS: sums of the sunlit share */
    int records[SHADE_SLOTS];  /* records in each month and hour */
    size_t sweeps;             /* cast-shadow sweeps made (records with the sun up) */
    /* NULL, or hourly shade masks of every grid cell (Google's hourlyShade):
     * SHADE_SLOTS planes of width x height, bit d - 1 set where the cell
     * was sunlit at the record of day d of that month and hour */
    uint32_t *masks;
} roof_shade;

/* Adds a plane of tilt and grid aspect (the way it descends) whose cells
 * are counted. Returns 0, or -1 out of memory. */
int roof_shade_add_plane(roof_shade *s, double tilt_deg, double aspect_grid_deg,
                         const int *cells, int n_cells);

/* For each step (the weather's records, azimuths true, as roofs makes
 * them), counted in its month and hour of local time (utc_offset_h):
 * with the sun's apparent elevation above 0, the cast shadows of src by
 * the shadow product's sweep for the sun at the grid's centre (grid_north_deg: the frame's grid north
 * from true north), and each plane's share of cells that are sunlit and
 * face the sun; and with masks (allocated by the caller), the cells'
 * sunlit bits. */
ss_status roof_shade_sweep(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                           double grid_north_deg, const ss_sun_step *steps, int n_steps,
                           double utc_offset_h, roof_shade *s);

/* Plane k's mean share in direct sun in a month (0..11) and hour; NAN
 * where no record falls in them. */
double roof_shade_fraction(const roof_shade *s, size_t k, int month, int hour);

void roof_shade_free(roof_shade *s);

#endif
