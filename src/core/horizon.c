/* Horizon angles: one sweep per direction, each direction's grid handed to
 * the caller's sink at once, so only one direction is held in memory. */
#include "config.h"

#include <math.h>

#include "products_internal.h"
#include "ss_passes.h"

ss_status ss_horizon(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt, int want,
                     ss_horizon_sink sink, void *user)
{
    int want_dist = (want & SS_HORIZON_DISTANCE) != 0;
    int want_cast = (want & SS_HORIZON_CAST_HEIGHT) != 0;
    /* Casting heights ride on the distance grid (ss_horizon_caster). */
    int pass_want = want_cast ? SS_HORIZON_WANT_DIST | SS_HORIZON_WANT_CAST
                    : want_dist ? SS_HORIZON_WANT_DIST
                                : 0;
    int n_outputs = want_cast ? 3 : want_dist ? 2 : 1;
    ss_session *s;
    ss_status st = ss_product_begin(ctx, grid, opt, n_outputs, &s);
    if (st != SS_OK)
        return st;
    float curv_k = ss_curvature_k(opt);
    size_t n_cells = (size_t)grid->width * (size_t)grid->height;
    for (int i = 0; i < opt->directions && st == SS_OK; ++i) {
        ss_line_set ls;
        double t0 = ss_seconds_now();
        ss_product_lines(grid, opt, i, &ls);
        for (int out = 0; out < n_outputs && st == SS_OK; ++out)
            st = ss_session_clear(s, out);
        if (st == SS_OK)
            st = ss_session_horizon(s, &ls, curv_k, -90.0f, pass_want);
        float *angle = NULL, *dist = NULL, *cast = NULL;
        if (st == SS_OK)
            st = ss_session_view(s, 0, &angle);
        if (st == SS_OK && n_outputs > 1)
            st = ss_session_view(s, 1, &dist);
        if (st == SS_OK && want_cast)
            st = ss_session_view(s, 2, &cast);
        ctx->counters.sweep_seconds += ss_seconds_now() - t0;
        if (st == SS_OK)
            for (size_t c = 0; c < n_cells; ++c) {
                int no_height = !isfinite(grid->z[c]);
                if (no_height)
                    angle[c] = SS_NODATA;
                if (cast)
                    cast[c] = no_height || dist[c] == 0.0f
                                  ? SS_NODATA
                                  : (float)(grid->z_origin_m + (double)cast[c]);
                if (dist && no_height)
                    dist[c] = SS_NODATA;
            }
        if (st == SS_OK &&
            !sink(i, ss_direction_azimuth(opt, i), angle, want_dist ? dist : NULL, cast, user))
            st = ss_fail(ctx, SS_ERR_CANCELLED, "stopped while storing direction %d", i);
        if (st == SS_OK)
            st = ss_progress(ctx, (double)(i + 1) / opt->directions, "horizon");
    }
    ss_session_close(s);
    return st;
}

ss_status ss_bare_pass(ss_ctx *ctx, const ss_grid *grid, double azimuth_deg,
                       ss_line_model lines, float *out)
{
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = lines;
    opt.directions = 1;
    opt.offset_deg = isfinite(azimuth_deg) ? fmod(azimuth_deg, 360.0) : azimuth_deg;
    ss_session *s;
    ss_status st = ss_product_begin(ctx, grid, &opt, 1, &s);
    if (st != SS_OK)
        return st;
    ss_line_set ls;
    ss_product_lines(grid, &opt, 0, &ls);
    float *host = NULL;
    st = ss_session_bare(s, &ls);
    if (st == SS_OK)
        st = ss_session_view(s, 0, &host);
    if (st == SS_OK)
        for (size_t c = 0; c < (size_t)grid->width * (size_t)grid->height; ++c)
            out[c] += host[c];
    ss_session_close(s);
    return st;
}
