/* The C twin: runs the kernels' own per-line code (kernels/ss_passes.h,
 * ss_band.h) on the host, lines in parallel with OpenMP. It walks a
 * batch's directions one after the other with one stack grid, adding
 * summed terms straight into the band's sums, so its results do not depend
 * on the batch. It is what --device reference selects and what the OpenCL
 * path is tested against alongside the brute-force references of the
 * tests. */
#include "config.h"

#include <stdlib.h>
#include <string.h>

#include "backend.h"
#include "ss_passes.h"

typedef struct {
    const float *z;     /* the band's heights: the caller's (backend.h, load) */
    const float *grad;  /* the band's gradients (the radiative SVF) */
    int *stack;
    float *sums;        /* summed walks: the band's sums */
    float *outs;        /* horizon walks: planes per batch slot */
    float *carry;       /* rows of sums kept between bands */
    /* Hulls handed on (ss_band.h): in from the band before, out to the next. */
    ss_hull_point *hull_in, *hull_out;
    size_t hull_cap_in, hull_cap_out;
    int *in_off, *in_cnt, *out_off, *out_cnt, *state;
    int n_lines;
    int counters[SS_BAND_COUNTERS];
} ref_backend;

static size_t held_cells(const ss_backend *b)
{
    return (size_t)b->max_held_rows * (size_t)b->width;
}

static size_t run_cells(const ss_band_run *run)
{
    return (size_t)run->held_rows * (size_t)run->width;
}

static ss_status ref_load(ss_backend *b, const ss_band_run *run, const float *z, const float *grad)
{
    (void)run;
    ref_backend *r = b->impl;
    r->z = z;
    r->grad = grad;
    return SS_OK;
}

static ss_status grow_ints(ss_ctx *ctx, int **p, int n)
{
    int *q = ss_realloc(*p, sizeof(int) * (size_t)(n > 0 ? n : 1));
    if (!q)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the hulls of %d lines", n);
    *p = q;
    return SS_OK;
}

/* Grows a hull array to hold at least n points (one at least: offsets are
 * added to it even where a line takes no points). */
static ss_status grow_hull(ss_ctx *ctx, ss_hull_point **p, size_t *cap, size_t n)
{
    if (n <= *cap && *p)
        return SS_OK;
    size_t want = n + n / 2 + 1024;
    ss_hull_point *q = ss_realloc(*p, sizeof *q * want);
    if (!q)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory for %zu hull points handed on", n);
    *p = q;
    *cap = want;
    return SS_OK;
}

static ss_status ref_pass_begin(ss_backend *b, int n_lines)
{
    ref_backend *r = b->impl;
    ss_status st = grow_hull(b->ctx, &r->hull_in, &r->hull_cap_in, 1);
    int **arrays[] = {&r->in_off, &r->in_cnt, &r->out_off, &r->out_cnt};
    for (int i = 0; i < 4 && st == SS_OK; ++i)
        st = grow_ints(b->ctx, arrays[i], n_lines);
    if (st == SS_OK)
        st = grow_ints(b->ctx, &r->state, SS_BAND_STATE * n_lines);
    if (st != SS_OK)
        return st;
    r->n_lines = n_lines;
    for (int i = 0; i < 4; ++i)
        memset(*arrays[i], 0, sizeof(int) * (size_t)n_lines);
    memset(r->counters, 0, sizeof r->counters);
    if (r->carry)
        memset(r->carry, 0, sizeof(float) * ss_backend_carry_floats(b));
    return SS_OK;
}

static ss_status ref_sums_begin(ss_backend *b, const ss_band_run *run, int pass)
{
    ref_backend *r = b->impl;
    memset(r->sums, 0, run_cells(run) * sizeof(float));
    int row = ss_band_landing_row(run, pass);
    if (b->carried && row >= 0)
        memcpy(r->sums + (size_t)row * run->width, r->carry, sizeof(float) * (size_t)run->width);
    return SS_OK;
}

/* Makes room in hull_out for every point the walks so far will hand on. */
static ss_status hull_room(ss_backend *b)
{
    ref_backend *r = b->impl;
    return grow_hull(b->ctx, &r->hull_out, &r->hull_cap_out,
                     (size_t)r->counters[SS_BAND_PENDING]);
}

/* One round of one direction's lines, and their hulls handed on. */
static ss_status walk_round(ss_backend *b, const ss_band_run *run, const ss_band_dir *d,
                            int round)
{
    ref_backend *r = b->impl;
    ss_band_hulls hulls = {r->hull_in, r->in_off, r->in_cnt, r->state, r->counters};
    int n = ss_round_lines(&d->ls, round), term = b->walk.term;
    const ss_ctx *ctx = b->ctx;
    long skipped = 0;
    /* Guided: long runs of neighbouring lines first, which share cache lines,
     * then short ones to even the threads out (3 to 15 % faster than runs
     * of 16 lines throughout, doc/performance.md). Lines of a round share
     * no cell, so the order changes no sum. */
#pragma omp parallel for schedule(guided, 16) reduction(+ : skipped)
    for (int i = 0; i < n; ++i) {
        if (ctx->cancel_requested)
            continue;
        int line = ss_round_line(&d->ls, round, i);
        if (term == SS_TERM_HORIZON)
            skipped += ss_band_horizon_line(d, run, line, r->z, r->stack, r->outs, hulls,
                                            b->walk.lit_levels);
        else if (b->walk.radius_m > 0)
            ss_band_radius_line(d, run, line, r->z, r->stack, r->sums);
        else
            ss_band_sum_line(d, run, line, r->z, r->grad, r->stack, r->sums, hulls);
    }
    b->ctx->counters.shadow_steps_skipped += (uint64_t)skipped;
    if (ctx->cancel_requested)
        return ss_check_cancel(b->ctx, "the sweep");
    if (run->whole || b->walk.radius_m > 0)
        return SS_OK;
    ss_status st = hull_room(b);
    if (st != SS_OK)
        return st;
#pragma omp parallel for schedule(guided, 16)
    for (int i = 0; i < n; ++i)
        ss_band_hand_on(d, ss_round_line(&d->ls, round, i), r->z, r->stack, r->hull_in,
                        r->in_off, r->state, r->hull_out, r->out_off, r->out_cnt, r->counters);
    return SS_OK;
}

/* A horizon walk's rows of sums in (into) from, or out to, the rows kept
 * between bands. */
static void carry_rows(ss_backend *b, const ss_band_run *run, const ss_band_dir *d, int into)
{
    ref_backend *r = b->impl;
    int row = into ? ss_band_landing_row(run, d->pass) : ss_band_fed_row(run, d->pass);
    if (!b->carried || row < 0)
        return;
    size_t w = (size_t)run->width;
    for (int p = 0; p < run->planes; ++p) {
        float *plane = ss_band_plane(r->outs, run, d->slot, p) + (size_t)row * w;
        float *kept = r->carry + ((size_t)d->carry * run->planes + p) * w;
        memcpy(into ? plane : kept, into ? kept : plane, w * sizeof(float));
    }
}

/* The samples of every line of a direction (the whole grid's). */
static uint64_t direction_samples(const ss_line_set *ls)
{
    uint64_t n = 0;
    int first;
    for (int line = 0; line < ss_line_count(ls); ++line)
        n += (uint64_t)ss_line_extent(ls, line, &first);
    return n;
}

static ss_status ref_walk(ss_backend *b, const ss_band_run *run, const ss_band_dir *dirs, int n)
{
    ref_backend *r = b->impl;
    ss_status st = SS_OK;
    int horizon = b->walk.term == SS_TERM_HORIZON;
    for (int k = 0; k < n && st == SS_OK; ++k) {
        const ss_band_dir *d = &dirs[k];
        if (horizon) {
            float *planes = ss_band_plane(r->outs, run, d->slot, 0);
            size_t n_floats = (size_t)run->planes * run_cells(run);
            /* Zeroed on both cores (64 horizon walks of the sample: 0.285 to 0.280 s). */
#pragma omp parallel for schedule(static)
            for (size_t c = 0; c < n_floats; ++c)
                planes[c] = 0.0f;
            carry_rows(b, run, d, 1);
        }
        /* Counted once, at the pass's first band. */
        int first_band = d->pass > 0 ? run->row0 == 0 : run->row1 == run->height;
        if (horizon && b->walk.lit_levels && (run->whole || first_band) && d->lit_level >= 0)
            b->ctx->counters.shadow_steps += direction_samples(&d->ls);
        for (int round = 0; round < ss_line_rounds(&d->ls) && st == SS_OK; ++round)
            st = walk_round(b, run, d, round);
        if (st != SS_OK || !horizon)
            continue;
        carry_rows(b, run, d, 0);
        float *angle = ss_band_plane(r->outs, run, d->slot, 0);
        const float *weight = ss_band_plane(r->outs, run, d->slot, 1);
        int first = (run->row0 - run->lo) * run->width;
        int last = (run->row1 - run->lo) * run->width;
#pragma omp parallel for schedule(static)
        for (int c = first; c < last; ++c)
            ss_pass_horizon_finish(c, run->none_deg, angle, weight);
    }
    return st;
}

static ss_status ref_sums_end(ss_backend *b, const ss_band_run *run, int pass, float **own)
{
    ref_backend *r = b->impl;
    int row = ss_band_fed_row(run, pass);
    if (b->carried && row >= 0)
        memcpy(r->carry, r->sums + (size_t)row * run->width, sizeof(float) * (size_t)run->width);
    *own = r->sums + (size_t)(run->row0 - run->lo) * run->width;
    return SS_OK;
}

static ss_status ref_view(ss_backend *b, const ss_band_run *run, int slot, int plane, float **own)
{
    ref_backend *r = b->impl;
    *own = ss_band_plane(r->outs, run, slot, plane) + (size_t)(run->row0 - run->lo) * run->width;
    return SS_OK;
}

static ss_status ref_hulls_swap(ss_backend *b, ss_band_stats *stats)
{
    ref_backend *r = b->impl;
    ss_hull_point *p = r->hull_in;
    r->hull_in = r->hull_out;
    r->hull_out = p;
    size_t cap = r->hull_cap_in;
    r->hull_cap_in = r->hull_cap_out;
    r->hull_cap_out = cap;
    int *t = r->in_off;
    r->in_off = r->out_off;
    r->out_off = t;
    t = r->in_cnt;
    r->in_cnt = r->out_cnt;
    r->out_cnt = t;
    if (stats) {
        stats->handoffs += (size_t)r->counters[SS_BAND_HANDOFFS];
        stats->hull_points_handed_on += (size_t)r->counters[SS_BAND_USED];
        if ((size_t)r->counters[SS_BAND_HULL_MAX] > stats->max_hull_points)
            stats->max_hull_points = (size_t)r->counters[SS_BAND_HULL_MAX];
    }
    memset(r->counters, 0, sizeof r->counters);
    return SS_OK;
}

static ss_status ref_bare(ss_backend *b, const ss_band_run *run, const ss_band_dir *d,
                          float **out)
{
    ref_backend *r = b->impl;
    memset(r->sums, 0, run_cells(run) * sizeof(float));
    for (int round = 0; round < ss_line_rounds(&d->ls); ++round) {
        int n = ss_round_lines(&d->ls, round);
#pragma omp parallel for schedule(guided, 16)
        for (int i = 0; i < n; ++i) {
            if (b->ctx->cancel_requested)
                continue;
            ss_walker w;
            int count = ss_walker_begin(&w, &d->ls, ss_round_line(&d->ls, round, i));
            ss_bare_steps(&w, &d->ls, 0, count, r->z, r->sums);
        }
    }
    *out = r->sums;
    return ss_check_cancel(b->ctx, "the sweep");
}

static void ref_close(ss_backend *b)
{
    ref_backend *r = b->impl;
    if (!r)
        return;
    free(r->stack);
    free(r->sums);
    free(r->outs);
    free(r->carry);
    free(r->hull_in);
    free(r->hull_out);
    free(r->in_off);
    free(r->in_cnt);
    free(r->out_off);
    free(r->out_cnt);
    free(r->state);
    free(r);
    b->impl = NULL;
}

/* No cells_*: the consumer computes its steps where the rows lie. */
static const ss_backend_ops ref_ops = {.load = ref_load,
                                       .pass_begin = ref_pass_begin,
                                       .sums_begin = ref_sums_begin,
                                       .walk = ref_walk,
                                       .sums_end = ref_sums_end,
                                       .view = ref_view,
                                       .hulls_swap = ref_hulls_swap,
                                       .bare = ref_bare,
                                       .close = ref_close};

ss_status ss_backend_ref_open(ss_backend *b)
{
    ref_backend *r = ss_calloc(1, sizeof *r);
    b->impl = r;
    b->ops = &ref_ops;
    if (!r)
        return ss_fail(b->ctx, SS_ERR_MEMORY, "out of memory opening the C twin");
    size_t n = held_cells(b);
    int horizon = b->walk.term == SS_TERM_HORIZON, planes = ss_walk_planes(&b->walk);
    int ok = (r->stack = ss_alloc_grid(n * (size_t)b->stack_per_cell * sizeof(int))) != NULL;
    if (ok && horizon)
        ok = (r->outs = ss_alloc_grid(n * sizeof(float) * (size_t)planes * b->batch)) != NULL;
    else if (ok)
        ok = (r->sums = ss_alloc_grid(n * sizeof(float))) != NULL;
    if (ok && b->carried)
        ok = (r->carry = ss_calloc(ss_backend_carry_floats(b), sizeof(float))) != NULL;
    if (!ok) {
        ref_close(b);
        return ss_fail(b->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB of sweep buffers",
                       (n * sizeof(float) * (size_t)(1 + (horizon ? planes * b->batch : 1))) >>
                           20);
    }
    return SS_OK;
}
