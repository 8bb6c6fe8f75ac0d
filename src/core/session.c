/* Dispatches session calls to the backend the context selected, and counts
 * the sweeps run. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "session.h"
#include "ss_passes.h"

ss_status ss_session_open(ss_ctx *ctx, const ss_grid *grid, int n_outputs, ss_session **out)
{
    *out = NULL;
    if (n_outputs < 1 || n_outputs > SS_SESSION_MAX_OUTPUTS)
        return ss_fail(ctx, SS_ERR_INTERNAL, "session with %d outputs", n_outputs);
    ss_session *s = ss_calloc(1, sizeof *s);
    if (!s)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory opening a sweep session");
    s->ctx = ctx;
    s->grid = grid;
    s->n_outputs = n_outputs;
    ss_status st = ctx->use_reference ? ss_backend_ref_open(s) : ss_backend_ocl_open(s);
    if (st != SS_OK) {
        free(s);
        return st;
    }
    *out = s;
    return SS_OK;
}

void ss_session_close(ss_session *s)
{
    if (!s)
        return;
    s->backend->close(s);
    free(s);
}

ss_status ss_session_clear(ss_session *s, int output)
{
    return s->backend->clear(s, output);
}

static void count_sweep(ss_session *s)
{
    s->ctx->counters.sweeps++;
    s->ctx->counters.cells_swept += (uint64_t)s->grid->width * (uint64_t)s->grid->height;
}

ss_status ss_session_svf(ss_session *s, const ss_line_set *ls, int definition, float curv_k,
                         double azimuth_rad)
{
    count_sweep(s);
    return s->backend->svf(s, ls, definition, curv_k, (float)sin(azimuth_rad),
                           (float)cos(azimuth_rad));
}

ss_status ss_session_horizon(ss_session *s, const ss_line_set *ls, float curv_k, float none_deg,
                             int want)
{
    /* Casting heights are written with the distances, which mark the
     * cells that already have a caster (ss_horizon_caster). */
    if (want & SS_HORIZON_WANT_CAST)
        want |= SS_HORIZON_WANT_DIST;
    int outputs = want & SS_HORIZON_WANT_CAST ? 3 : want & SS_HORIZON_WANT_DIST ? 2 : 1;
    if (s->n_outputs < outputs)
        return ss_fail(s->ctx, SS_ERR_INTERNAL, "horizon pass needs %d outputs, session has %d",
                       outputs, s->n_outputs);
    count_sweep(s);
    return s->backend->horizon(s, ls, curv_k, none_deg, want);
}

ss_status ss_session_radius_terms(ss_session *s, const ss_line_set *ls, int definition,
                                  float radius_m, float curv_k)
{
    count_sweep(s);
    return s->backend->radius_terms(s, ls, definition, radius_m, curv_k);
}

ss_status ss_session_bare(ss_session *s, const ss_line_set *ls)
{
    return s->backend->bare(s, ls);
}

ss_status ss_session_view(ss_session *s, int output, float **host)
{
    return s->backend->view(s, output, host);
}

void ss_gradient_grid(const ss_grid *g, float *out)
{
    float cx = (float)g->cell_x_m, cy = (float)g->cell_y_m;
#pragma omp parallel for schedule(static)
    for (int row = 0; row < g->height; ++row)
        for (int col = 0; col < g->width; ++col) {
            size_t c = (size_t)row * g->width + col;
            out[2 * c] = out[2 * c + 1] = 0.0f;
            if (isfinite(g->z[c]))
                ss_gradient_horn(g->z, g->width, g->height, col, row, cx, cy, &out[2 * c],
                                 &out[2 * c + 1]);
        }
}
