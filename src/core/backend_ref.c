/* The C twin: runs the kernels' own per-line code (kernels/ss_passes.h) on
 * the host, lines in parallel with OpenMP. It is what --device reference
 * selects and what the OpenCL path is tested against alongside the
 * brute-force reference of the tests. */
#include "config.h"

#include <stdlib.h>
#include <string.h>

#include "session.h"
#include "ss_passes.h"

typedef struct {
    int *stack;
    float *out[SS_SESSION_MAX_OUTPUTS];
    float *weight; /* horizon weights (ss_pass_horizon_walk), made on first use */
    float *grad;   /* gradients for the radiative SVF (ss_gradient_grid), made on first use */
} ref_session;

static ss_status ref_clear(ss_session *s, int output)
{
    ref_session *r = s->impl;
    memset(r->out[output], 0, sizeof(float) * (size_t)s->grid->width * s->grid->height);
    return SS_OK;
}

static ss_status ref_svf(ss_session *s, const ss_line_set *ls, int definition, float curv_k,
                         float sin_az, float cos_az)
{
    ref_session *r = s->impl;
    const ss_grid *g = s->grid;
    float cx = (float)g->cell_x_m, cy = (float)g->cell_y_m;
    if (definition == SS_SVF_TILTED && !r->grad) {
        size_t bytes = 2 * (size_t)g->width * g->height * sizeof(float);
        if (!(r->grad = ss_alloc_grid(bytes)))
            return ss_fail(s->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB of surface gradients",
                           bytes >> 20);
        ss_gradient_grid(g, r->grad);
    }
    for (int round = 0; round < 2; ++round) {
        int n = ss_round_lines(ls, round);
#pragma omp parallel for schedule(dynamic, 16)
        for (int i = 0; i < n; ++i)
            if (!s->ctx->cancel_requested)
                ss_pass_svf(ls, ss_round_line(ls, round, i), definition, curv_k, sin_az, cos_az, cx,
                            cy, g->height, g->z, r->grad, r->stack, r->out[0]);
    }
    return ss_check_cancel(s->ctx, "the sweep");
}

static ss_status ref_horizon(ss_session *s, const ss_line_set *ls, float curv_k, float none_deg,
                             int want)
{
    ref_session *r = s->impl;
    size_t n_cells = (size_t)s->grid->width * s->grid->height;
    /* Only horizon sessions pay for the weight grid. */
    if (!r->weight && !(r->weight = ss_alloc_grid(n_cells * sizeof(float))))
        return ss_fail(s->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB of horizon weights",
                       (n_cells * sizeof(float)) >> 20);
    memset(r->weight, 0, n_cells * sizeof(float));
    /* Grids not asked for are never written: output 0 stands in. */
    float *dist = want & SS_HORIZON_WANT_DIST ? r->out[1] : r->out[0];
    float *cast = want & SS_HORIZON_WANT_CAST ? r->out[2] : r->out[0];
    for (int round = 0; round < 2; ++round) {
        int n = ss_round_lines(ls, round);
#pragma omp parallel for schedule(dynamic, 16)
        for (int i = 0; i < n; ++i)
            if (!s->ctx->cancel_requested)
                ss_pass_horizon(ls, ss_round_line(ls, round, i), curv_k, s->grid->z, r->stack,
                                r->out[0], r->weight, dist, cast, want);
    }
    if (s->ctx->cancel_requested)
        return ss_check_cancel(s->ctx, "the sweep");
#pragma omp parallel for schedule(static)
    for (int c = 0; c < (int)n_cells; ++c)
        ss_pass_horizon_finish(c, none_deg, r->out[0], r->weight);
    return SS_OK;
}

static ss_status ref_bare(ss_session *s, const ss_line_set *ls)
{
    ref_session *r = s->impl;
    for (int round = 0; round < 2; ++round) {
        int n = ss_round_lines(ls, round);
#pragma omp parallel for schedule(dynamic, 16)
        for (int i = 0; i < n; ++i)
            if (!s->ctx->cancel_requested)
                ss_pass_bare(ls, ss_round_line(ls, round, i), s->grid->z, r->out[0]);
    }
    return ss_check_cancel(s->ctx, "the sweep");
}

static ss_status ref_radius_terms(ss_session *s, const ss_line_set *ls, int definition,
                                  float radius_m, float curv_k)
{
    ref_session *r = s->impl;
    for (int round = 0; round < 2; ++round) {
        int n = ss_round_lines(ls, round);
#pragma omp parallel for schedule(dynamic, 16)
        for (int i = 0; i < n; ++i)
            if (!s->ctx->cancel_requested)
                ss_pass_radius_terms(ls, ss_round_line(ls, round, i), definition, radius_m,
                                     curv_k, s->grid->z, r->out[0]);
    }
    return ss_check_cancel(s->ctx, "the sweep");
}

static ss_status ref_view(ss_session *s, int output, float **host)
{
    ref_session *r = s->impl;
    *host = r->out[output];
    return SS_OK;
}

static void ref_close(ss_session *s)
{
    ref_session *r = s->impl;
    if (!r)
        return;
    free(r->stack);
    for (int i = 0; i < SS_SESSION_MAX_OUTPUTS; ++i)
        free(r->out[i]);
    free(r->weight);
    free(r->grad);
    free(r);
}

static const ss_backend ref_backend = {ref_clear, ref_svf,  ref_horizon, ref_bare,
                                       ref_radius_terms, ref_view, ref_close};

ss_status ss_backend_ref_open(ss_session *s)
{
    size_t n = (size_t)s->grid->width * (size_t)s->grid->height;
    ref_session *r = ss_calloc(1, sizeof *r);
    s->impl = r;
    s->backend = &ref_backend;
    if (!r)
        return ss_fail(s->ctx, SS_ERR_MEMORY, "out of memory opening the C reference");
    r->stack = ss_alloc_grid(n * sizeof(int));
    int ok = r->stack != NULL;
    for (int i = 0; i < s->n_outputs; ++i) {
        r->out[i] = ss_alloc_grid(n * sizeof(float));
        ok = ok && r->out[i];
    }
    if (!ok) {
        ref_close(s);
        s->impl = NULL;
        return ss_fail(s->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB of sweep buffers",
                       (n * sizeof(float) * (size_t)(1 + s->n_outputs)) >> 20);
    }
    for (int i = 0; i < s->n_outputs; ++i)
        memset(r->out[i], 0, n * sizeof(float));
    return SS_OK;
}
