/* Cast shadows: one exact sweep along the sun's azimuth, not an
 * interpolation between stored directions. A cell is sunlit when the sun
 * stands above its terrain horizon in that azimuth; where no terrain lies
 * ahead inside the grid the horizon is taken as the horizontal, so a sun
 * below 0 degrees lights nothing there. A cell beside the grid's edge or
 * a hole whose two samples disagree takes the mean of those with terrain
 * ahead, never a mix with the horizontal (doc/model.md, Edges). */
#include "config.h"

#include <math.h>

#include "products_internal.h"

ss_status ss_sun_horizon(ss_session *s, const ss_grid *grid, const ss_sweep_options *opt,
                         double azimuth_deg, float **horizon_deg)
{
    ss_line_set ls;
    ss_product_lines_at(grid, opt, azimuth_deg, &ls);
    ss_status st = ss_session_clear(s, 0);
    if (st == SS_OK)
        st = ss_session_horizon(s, &ls, ss_curvature_k(opt), 0.0f, 0);
    if (st == SS_OK)
        st = ss_session_view(s, 0, horizon_deg);
    return st;
}

ss_status ss_cast_shadow(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                         double sun_azimuth_deg, double sun_elevation_deg,
                         const float *sun_elevation_per_cell_deg, float *sunlit,
                         float *horizon_deg)
{
    if (!isfinite(sun_azimuth_deg) || !isfinite(sun_elevation_deg) ||
        fabs(sun_elevation_deg) > 90.0)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun azimuth %g / elevation %g degrees is not a sun position",
                       sun_azimuth_deg, sun_elevation_deg);
    ss_session *s;
    ss_status st = ss_product_begin(ctx, grid, opt, 1, &s);
    if (st != SS_OK)
        return st;
    float *h = NULL;
    double t0 = ss_seconds_now();
    st = ss_sun_horizon(s, grid, opt, sun_azimuth_deg, &h);
    ctx->counters.sweep_seconds += ss_seconds_now() - t0;
    size_t n = (size_t)grid->width * (size_t)grid->height;
    for (size_t c = 0; st == SS_OK && c < n; ++c) {
        if (!isfinite(grid->z[c])) {
            sunlit[c] = SS_NODATA;
            if (horizon_deg)
                horizon_deg[c] = SS_NODATA;
            continue;
        }
        double sun = sun_elevation_per_cell_deg ? sun_elevation_per_cell_deg[c]
                                                : sun_elevation_deg;
        sunlit[c] = sun > h[c] ? 1.0f : 0.0f;
        if (horizon_deg)
            horizon_deg[c] = h[c];
    }
    ss_session_close(s);
    return st;
}
