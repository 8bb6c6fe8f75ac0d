/* Topographic openness (Yokoyama, Shirasawa & Pike 2002; physics.md 2.3):
 * positive openness is 90 degrees minus the mean over directions of the
 * highest elevation angle of the terrain, unclipped (negative on peaks);
 * negative openness is 90 degrees plus the mean lowest angle, computed as
 * the positive openness of the inverted surface -z. By default the horizon
 * is the sweep's, at unlimited distance; with a radius it is the classical
 * radius-limited maximum. Where no terrain lies ahead (the DEM's edge, or
 * nothing within the radius) the angle is taken as 0, the horizontal. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "products_internal.h"
#include "ss_terms.h"

ss_status ss_openness(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                      int negative, double radius_m, float *out)
{
    if (!(radius_m >= 0) || !isfinite(radius_m))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "openness radius must be >= 0 m (0: unlimited), not %g",
                       radius_m);
    size_t n = (size_t)grid->width * grid->height;
    ss_grid inverted = *grid;
    if (negative) {
        inverted.z = ss_alloc_grid(n * sizeof(float));
        if (!inverted.z)
            return ss_fail(ctx, SS_ERR_MEMORY, "out of memory inverting the DEM");
        for (size_t c = 0; c < n; ++c)
            inverted.z[c] = -grid->z[c];
    }
    const ss_grid *g = negative ? &inverted : grid;
    ss_session *s;
    ss_status st = ss_product_begin(ctx, g, opt, 1, &s);
    if (st == SS_OK) {
        float curv_k = ss_curvature_k(opt);
        double t0 = ss_seconds_now();
        for (int i = 0; i < opt->directions && st == SS_OK; ++i) {
            ss_line_set ls;
            double az = ss_product_lines(g, opt, i, &ls);
            st = radius_m > 0
                     ? ss_session_radius_terms(s, &ls, SS_TERM_ELEVATION, (float)radius_m, curv_k)
                     : ss_session_svf(s, &ls, SS_TERM_ELEVATION, curv_k, az);
            if (st == SS_OK)
                st = ss_progress(ctx, (double)(i + 1) / opt->directions, "openness");
        }
        float *acc = NULL;
        if (st == SS_OK)
            st = ss_session_view(s, 0, &acc);
        ctx->counters.sweep_seconds += ss_seconds_now() - t0;
        for (size_t c = 0; st == SS_OK && c < n; ++c)
            out[c] = isfinite(grid->z[c]) ? (float)(90.0 - acc[c] / opt->directions) : SS_NODATA;
        ss_session_close(s);
    }
    if (negative)
        free(inverted.z);
    return st;
}
