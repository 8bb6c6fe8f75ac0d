/* A proven upper bound on every terrain horizon a grid can cast, so that
 * work can be skipped exactly when the sun stands above it. */
#include "config.h"

#include <math.h>

#include "products_internal.h"

/* What the bound is made of (horizon_tan_bound): the largest height
 * differences between neighbouring cells along each axis, the heights'
 * range, and whether any cell is nodata. */
typedef struct {
    double gx, gy, zmin, zmax;
    int holes;
} bound_parts;

/* Adds rows [row0, row1) of a grid whose rows below row1 are there too. */
static void add_rows(bound_parts *b, const float *z, int width, int height, int row0, int row1)
{
    for (int r = row0; r < row1; ++r)
        for (int c = 0; c < width; ++c) {
            float v = z[(size_t)r * width + c];
            if (!isfinite(v)) {
                b->holes = 1;
                continue;
            }
            b->zmin = v < b->zmin ? v : b->zmin;
            b->zmax = v > b->zmax ? v : b->zmax;
            if (c + 1 < width && isfinite(z[(size_t)r * width + c + 1]))
                b->gx = fmax(b->gx, fabs(z[(size_t)r * width + c + 1] - v));
            if (r + 1 < height && isfinite(z[(size_t)(r + 1) * width + c]))
                b->gy = fmax(b->gy, fabs(z[(size_t)(r + 1) * width + c] - v));
        }
}

/* Upper bound of any terrain horizon's tangent on the grid. Along a line,
 * each step rises at most Gmajor + |m| Gminor over a run of
 * sqrt(dmajor^2 + m^2 dminor^2) (G: the largest height difference between
 * neighbouring cells along each axis), which Cauchy-Schwarz bounds by
 * sqrt((Gx/cx)^2 + (Gy/cy)^2); digital lines take up to one cell sideways
 * per step, hence the wider bound. A horizon is an average of such steps,
 * and curvature only lowers it. An interpolated sample at the grid's edge
 * takes one cell's height from up to a cell beside it, which can add one
 * more such step: hence twice the bound. Across nodata holes nothing
 * bounds the step, so there the relief over the smallest cell is used.
 * Box lines see a column's face from a point at most half a line spacing
 * beside the centre: the relief over that nearest distance (none with one
 * line per cell, whose points can touch a face). */
static double bound_deg(const bound_parts *b, double cell_x_m, double cell_y_m,
                        ss_line_model lines, int box_lines)
{
    double t;
    if (lines == SS_LINES_BOX) {
        double nearest = 0.5 * fmin(cell_x_m, cell_y_m) - 0.5 / box_lines * fmax(cell_x_m, cell_y_m);
        if (!(nearest > 0))
            return 90.0;
        t = (b->zmax - b->zmin) / nearest;
    } else if (b->holes) {
        t = (b->zmax - b->zmin) / fmin(cell_x_m, cell_y_m);
    } else {
        double sx = b->gx / cell_x_m, sy = b->gy / cell_y_m;
        t = lines == SS_LINES_DIGITAL ? M_SQRT2 * (sx + sy) : 2.0 * sqrt(sx * sx + sy * sy);
    }
    return atan(t) * 180.0 / M_PI;
}

double ss_horizon_bound_deg(const ss_grid *grid, ss_line_model lines, int box_lines)
{
    if (!grid->z) /* not in memory: nothing is bounded */
        return 90.0;
    bound_parts b = {0, 0, INFINITY, -INFINITY, 0};
    add_rows(&b, grid->z, grid->width, grid->height, 0, grid->height);
    return bound_deg(&b, grid->cell_x_m, grid->cell_y_m, lines, box_lines);
}

/* Each band's own rows, with the row below them held. */
static ss_status bound_band(void *user, const ss_band_view *band, float *planes)
{
    (void)planes;
    add_rows(user, band->z, band->width, band->held_rows,
             band->row0 - band->lo, band->row0 - band->lo + band->n_rows);
    return SS_OK;
}

ss_status ss_horizon_bound_of(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                              double *deg)
{
    bound_parts b = {0, 0, INFINITY, -INFINITY, 0};
    ss_consumer consumer = {.planes = 0, .finish = bound_band};
    ss_engine_job job = {.walk = {.term = SS_TERM_NONE},
                         .consumer = &consumer,
                         .user = &b,
                         .what = "heights"};
    ss_status st = ss_engine_run(ctx, src, opt, &job);
    *deg = bound_deg(&b, src->cell_x_m, src->cell_y_m, opt->lines, opt->box_lines);
    return st;
}
