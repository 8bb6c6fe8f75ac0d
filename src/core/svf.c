/* Sky-view factor: one sweep per direction adds each cell's term into one
 * accumulator grid (never all D horizon grids), then the mean over
 * directions is turned into the chosen definition (doc/model.md). With a
 * radius, each direction's horizon is the highest terrain within it (the
 * radius scan), as RVT and SAGA compute SVF. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "products_internal.h"
#include "ss_terms.h"

ss_status ss_svf(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                 ss_svf_definition definition, float *out)
{
    return ss_svf_within(ctx, grid, opt, definition, 0.0, out);
}

ss_status ss_svf_within(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                        ss_svf_definition definition, double radius_m, float *out)
{
    if (definition != SS_SVF_DEF_GEOMETRIC && definition != SS_SVF_DEF_HORIZONTAL &&
        definition != SS_SVF_DEF_TILTED)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown SVF definition %d", (int)definition);
    if (!(radius_m >= 0) || !isfinite(radius_m))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "SVF radius must be >= 0 m (0: unlimited), not %g",
                       radius_m);
    if (radius_m > 0 && definition == SS_SVF_DEF_TILTED)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a radius-limited SVF is geometric or horizontal, not radiative (tilted)");
    ss_session *s;
    ss_status st = ss_product_begin(ctx, grid, opt, 1, &s);
    if (st != SS_OK)
        return st;
    float curv_k = ss_curvature_k(opt);
    double t0 = ss_seconds_now();
    for (int i = 0; i < opt->directions && st == SS_OK; ++i) {
        ss_line_set ls;
        double az = ss_product_lines(grid, opt, i, &ls);
        st = radius_m > 0
                 ? ss_session_radius_terms(s, &ls, (int)definition, (float)radius_m, curv_k)
                 : ss_session_svf(s, &ls, (int)definition, curv_k, az);
        if (st == SS_OK)
            st = ss_progress(ctx, (double)(i + 1) / opt->directions, "sky-view factor");
    }
    float *acc = NULL;
    if (st == SS_OK)
        st = ss_session_view(s, 0, &acc);
    ctx->counters.sweep_seconds += ss_seconds_now() - t0;
    if (st == SS_OK) {
        size_t n = (size_t)grid->width * (size_t)grid->height;
        float inv_d = 1.0f / (float)opt->directions;
        for (size_t c = 0; c < n; ++c) {
            if (!isfinite(grid->z[c])) {
                out[c] = SS_NODATA;
                continue;
            }
            float mean = acc[c] * inv_d;
            float v = definition == SS_SVF_DEF_GEOMETRIC ? 1.0f - mean : mean;
            out[c] = v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
        }
    }
    ss_session_close(s);
    return st;
}
