/* A proven upper bound on every terrain horizon a grid can cast, so that
 * work can be skipped exactly when the sun stands above it. */
#include "config.h"

#include <math.h>

#include "ctx_internal.h"

/* Upper bound of any terrain horizon's tangent on the grid. Along a line,
 * each step rises at most Gmajor + |m| Gminor over a run of
 * sqrt(dmajor^2 + m^2 dminor^2) (G: the largest height difference between
 * neighbouring cells along each axis), which Cauchy-Schwarz bounds by
 * sqrt((Gx/cx)^2 + (Gy/cy)^2); digital lines take up to one cell sideways
 * per step, hence the wider bound. A horizon is an average of such steps,
 * and curvature only lowers it. An interpolated sample at the grid's edge
 * takes one cell's height from up to a cell beside it, which can add one
 * more such step: hence twice the bound. Across nodata holes nothing
 * bounds the step, so there the relief over the smallest cell is used. */
static double horizon_tan_bound(const ss_grid *g, int digital)
{
    double gx = 0, gy = 0, zmin = INFINITY, zmax = -INFINITY;
    int holes = 0;
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            float z = g->z[(size_t)r * g->width + c];
            if (!isfinite(z)) {
                holes = 1;
                continue;
            }
            zmin = z < zmin ? z : zmin;
            zmax = z > zmax ? z : zmax;
            if (c + 1 < g->width && isfinite(g->z[(size_t)r * g->width + c + 1]))
                gx = fmax(gx, fabs(g->z[(size_t)r * g->width + c + 1] - z));
            if (r + 1 < g->height && isfinite(g->z[(size_t)(r + 1) * g->width + c]))
                gy = fmax(gy, fabs(g->z[(size_t)(r + 1) * g->width + c] - z));
        }
    if (holes)
        return (zmax - zmin) / fmin(g->cell_x_m, g->cell_y_m);
    double sx = gx / g->cell_x_m, sy = gy / g->cell_y_m;
    return digital ? M_SQRT2 * (sx + sy) : 2.0 * sqrt(sx * sx + sy * sy);
}

double ss_horizon_bound_deg(const ss_grid *grid, ss_line_model lines)
{
    if (!grid->z) /* not in memory (a banded run): nothing is bounded */
        return 90.0;
    return atan(horizon_tan_bound(grid, lines == SS_LINES_DIGITAL)) * 180.0 / M_PI;
}
