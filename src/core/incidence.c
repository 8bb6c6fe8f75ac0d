/* How directly the sun shines on every cell: the cosine of the incidence
 * angle between the sun and the cell's surface normal (Horn's gradient),
 * from the per-cell formula shared with the kernels (kernels/ss_sun.h). */
#include "config.h"

#include <math.h>

#include "products_internal.h"
#include "ss_sun.h"
#include "ss_terms.h"

void ss_incidence_rows(const ss_grid *grid, int row0, int row1, double grid_azimuth_deg,
                       double elevation_deg, const float *grid_azimuth_per_cell_deg,
                       const float *elevation_per_cell_deg, float *out)
{
    const double rad = M_PI / 180.0;
    float cx = (float)grid->cell_x_m, cy = (float)grid->cell_y_m;
#pragma omp parallel for schedule(static)
    for (int r = row0; r < row1; ++r)
        for (int c = 0; c < grid->width; ++c) {
            size_t k = (size_t)(r - row0) * grid->width + c;
            if (!isfinite(grid->z[(size_t)r * grid->width + c])) {
                out[k] = SS_NODATA;
                continue;
            }
            double az = (grid_azimuth_per_cell_deg ? grid_azimuth_per_cell_deg[k]
                                                   : grid_azimuth_deg) * rad;
            double el = (elevation_per_cell_deg ? elevation_per_cell_deg[k] : elevation_deg) * rad;
            float dz_de, dz_dn;
            ss_gradient_horn(grid->z, grid->width, grid->height, c, r, cx, cy, &dz_de, &dz_dn);
            out[k] = ss_cos_incidence_gradient((float)(cos(el) * sin(az)),
                                               (float)(cos(el) * cos(az)), (float)sin(el), dz_de,
                                               dz_dn);
        }
}

ss_status ss_sun_incidence(ss_ctx *ctx, const ss_grid *grid, double grid_azimuth_deg,
                           double elevation_deg, const float *grid_azimuth_per_cell_deg,
                           const float *elevation_per_cell_deg, float *cos_incidence)
{
    ss_call_begin(ctx);
    if (ss_grid_check(ctx, grid, NULL) != SS_OK)
        return SS_ERR_INPUT;
    ss_incidence_rows(grid, 0, grid->height, grid_azimuth_deg, elevation_deg,
                      grid_azimuth_per_cell_deg, elevation_per_cell_deg, cos_incidence);
    return SS_OK;
}
