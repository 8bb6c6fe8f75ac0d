/* The band machinery shared by the banded sweeps (band_walk.h). */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "band_walk.h"

#define HALO SS_BAND_HALO

size_t ss_band_held_cells(const ss_band_grid *b)
{
    return (size_t)(b->band_rows + 2 * HALO) * (size_t)b->width;
}

ss_status ss_band_grid_alloc(ss_band_grid *b)
{
    size_t held = ss_band_held_cells(b);
    b->z = ss_malloc(held * sizeof(float));
    b->stack = ss_malloc(held * sizeof(int));
    if (b->z && b->stack)
        return SS_OK;
    ss_band_grid_free(b);
    return ss_fail(b->ctx, SS_ERR_MEMORY, "out of memory for a band of %d rows", b->band_rows);
}

void ss_band_grid_free(ss_band_grid *b)
{
    free(b->z);
    free(b->stack);
    b->z = NULL;
    b->stack = NULL;
}

ss_status ss_band_read(ss_band_grid *b, int row0, int rows)
{
    size_t w = (size_t)b->width, held = (size_t)(rows + 2 * HALO) * w;
    /* Halo rows outside the grid are nodata, as the grid's edge is. */
    for (size_t c = 0; c < held; ++c)
        b->z[c] = NAN;
    int lo = row0 - HALO > 0 ? row0 - HALO : 0;
    int hi = row0 + rows + HALO < b->height ? row0 + rows + HALO : b->height;
    unsigned long failures = b->ctx->failures;
    ss_status st = b->read(b->user, lo, hi - lo, b->z + (size_t)(lo - (row0 - HALO)) * w);
    if (st != SS_OK) /* the reader's own message, where it gave one */
        return b->ctx->failures != failures
                   ? st
                   : ss_fail(b->ctx, st, "could not read DEM rows %d..%d", lo, hi - 1);
    if (b->negate)
        for (size_t c = 0; c < held; ++c)
            b->z[c] = -b->z[c];
    return SS_OK;
}

int ss_band_pass_of(const ss_line_set *ls)
{
    if (ls->major_is_row)
        return ls->step;
    return (ls->slope_fx < 0) == (ls->step < 0) || ls->slope_fx == 0 ? 1 : -1;
}

ss_line_set ss_band_lines(const ss_line_set *whole, int row0)
{
    ss_line_set ls = *whole;
    if (ls.major_is_row)
        ls.base_major = row0 - HALO;
    else
        ls.base_minor = row0 - HALO;
    return ls;
}

static int owner_row(const ss_line_set *ls, const ss_walker *w, int s, int pass, int height)
{
    ss_line_sample q = ss_walker_sample(ls, w, s);
    int row = ls->major_is_row ? q.major : (pass > 0 ? q.minor0 : q.minor0 + 1);
    return row < 0 ? 0 : (row >= height ? height - 1 : row);
}

/* First step of the walk whose owner row is at or past `row` in the
 * pass's order (owners are monotone along the walk); count if none. */
static int first_step_past(const ss_line_set *ls, const ss_walker *w, int count, int row, int pass,
                           int height)
{
    int lo = 0, hi = count;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        int r = owner_row(ls, w, mid, pass, height);
        if (pass > 0 ? r >= row : r <= row)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* Sums of what the bands handed on, merged into ss_band_stats. */
typedef struct {
    size_t hull_sum, hull_max, handoffs;
} band_tally;

/* Begins line `line` (of ls from ss_band_lines) in the band [row0, row1):
 * sets [*s_lo, *s_hi) to the steps whose owner rows lie in the band and
 * resumes the walker with the hull handed on. Returns 0 when the band
 * holds none of the line's steps. *count gets the line's step count. */
static int line_begin(const ss_line_set *ls, int line, const ss_carried_hull *hull, int row0,
                      int row1, int pass, int height, ss_walker *wk, int *s_lo, int *s_hi,
                      int *count)
{
    *count = ss_walker_begin(wk, ls, line);
    /* Owners in [row0, row1): entered at row0 going down, at row1 - 1 going up. */
    *s_lo = first_step_past(ls, wk, *count, pass > 0 ? row0 : row1 - 1, pass, height);
    *s_hi = first_step_past(ls, wk, *count, pass > 0 ? row1 : row0 - 1, pass, height);
    if (*s_lo >= *s_hi)
        return 0;
    ss_walker_resume(wk, ls, line, *s_lo, hull->points, hull->count);
    return 1;
}

/* After the band's steps: frees the hull of a line that is done, else
 * hands the walker's hull on (counted in tally). Returns 0, or -1 when out
 * of memory. */
static int line_end(ss_carried_hull *hull, ss_walker *wk, const ss_line_set *ls,
                    const ss_band_grid *b, int s_hi, int count, band_tally *tally)
{
    if (s_hi >= count) { /* the line is done: its hull is no longer needed */
        free(hull->points);
        *hull = (ss_carried_hull){NULL, 0, 0};
        return 0;
    }
    /* Exactly the hull's size: the hulls of every line crossing the band's
     * edge are held at once, and they dominate a banded run's memory. */
    if (wk->depth > hull->capacity || wk->depth < hull->capacity / 2) {
        int cap = wk->depth > 0 ? wk->depth : 1;
        ss_hull_point *p = ss_realloc(hull->points, sizeof *p * (size_t)cap);
        if (!p)
            return -1;
        hull->points = p;
        hull->capacity = cap;
        wk->carried = p; /* the carried slots moved with the array */
    }
    for (int k = wk->slot_base; k < wk->depth; ++k)
        hull->points[k] = ss_walker_slot(wk, ls, b->z, b->stack, k);
    hull->count = wk->depth;
    tally->hull_sum += (size_t)hull->count;
    if ((size_t)hull->count > tally->hull_max)
        tally->hull_max = (size_t)hull->count;
    tally->handoffs++;
    return 0;
}

void ss_carried_hulls_free(ss_carried_hull *hulls, int n)
{
    for (int l = 0; hulls && l < n; ++l)
        free(hulls[l].points);
    free(hulls);
}

static void stats_add(ss_band_stats *stats, const band_tally *t)
{
    stats->hull_points_handed_on += t->hull_sum;
    stats->handoffs += t->handoffs;
    if (t->hull_max > stats->max_hull_points)
        stats->max_hull_points = t->hull_max;
}

ss_status ss_band_walk(const ss_band_grid *b, const ss_line_set *whole, ss_carried_hull *hulls,
                       int row0, int row1, int pass, float curv_k, ss_band_steps_fn steps,
                       void *user, ss_band_stats *stats)
{
    ss_line_set ls = ss_band_lines(whole, row0);
    int flags = ss_walk_flags(&ls, curv_k), failed = 0;
    for (int round = 0; round < 2; ++round) {
        int n = ss_round_lines(&ls, round);
#pragma omp parallel reduction(|| : failed)
        {
            band_tally tally = {0, 0, 0};
#pragma omp for schedule(dynamic, 16)
            for (int i = 0; i < n; ++i) {
                int line = ss_round_line(&ls, round, i), s_lo, s_hi, count;
                ss_carried_hull *hull = &hulls[line];
                ss_walker wk;
                if (!line_begin(&ls, line, hull, row0, row1, pass, b->height, &wk, &s_lo, &s_hi,
                                &count))
                    continue;
                steps(user, &wk, &ls, s_lo, s_hi, flags);
                if (line_end(hull, &wk, &ls, b, s_hi, count, &tally) != 0)
                    failed = 1;
            }
#pragma omp critical(band_tally)
            stats_add(stats, &tally);
        }
    }
    return failed ? ss_fail(b->ctx, SS_ERR_MEMORY, "out of memory for the hulls handed on")
                  : SS_OK;
}
