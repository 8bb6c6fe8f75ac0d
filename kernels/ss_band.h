/* Bands of rows, the unit of work of the one sweep driver (shared by
 * kernels and C; the driver is src/core/engine.c).
 *
 * A band owns rows [row0, row1) of the grid and holds rows [lo, lo +
 * held_rows) in its buffers: its own and SS_BAND_HALO rows either side
 * (more for radius walks), clipped to the grid. The whole grid is the case
 * of one band: every line is walked whole and no hull is handed on.
 *
 * A direction's lines cross the bands in one order: downward for the
 * directions whose lines walk toward growing rows, upward for the others
 * (its pass). Each line's walk stops at the band's edge and resumes in the
 * next band with its hull handed on as whole points (ss_walker_take_hull;
 * the hull is exact, so bands change nothing but the order of float
 * additions over directions).
 *
 * Which band walks a sample: the one holding its "owner" row. Every row a
 * sample touches is the owner or next to it, and owners only grow along a
 * walk in the down pass (shrink in the up pass):
 *   - lines along columns (one row per step): the step's row;
 *   - lines along rows, down pass: the row at or above the line (minor0),
 *     which may also feed the row below, the next band's first row;
 *   - lines along rows, up pass: the row below (minor0 + 1), which may also
 *     feed the row above, the next band's last row.
 * So a band holds its rows plus halo rows on each side (two: the radiative
 * SVF's slope at a halo cell reads one row further), and what its samples
 * add into its first row beyond (the "fed" row) is carried into the next
 * band's nearest own row (its "landing" row).
 *
 * Hulls handed on live in one array per band visit (hull_in from the band
 * before, hull_out for the next). A round's walks record each line's state
 * and count the points it hands on; the driver makes room for them, and
 * ss_band_hand_on copies each line's hull to a place taken with an atomic
 * add: one small read-back per round of a batch, and no bound to guess. */
#ifndef SS_BAND_H
#define SS_BAND_H

#include "ss_sweep.h"
#include "ss_terms.h"

#define SS_BAND_HALO 2 /* rows held above and below a band */

/* Shadow walks' bounds (src/core/lit_levels.h): sectors of azimuth, and
 * in bands the blocks of 2^SS_LIT_BLOCK_SHIFT cells whose largest level
 * tells a walk whether the line's steps in the bands ahead need it. */
#define SS_LIT_SECTORS 8
#define SS_LIT_BLOCK_SHIFT 3

/* One direction of a batch: host-made; each work-item copies its own into
 * private memory. Layout shared with the host: 4-byte members after the
 * line set. */
typedef struct {
    ss_line_set ls;       /* the direction's lines, re-based to the band's held rows */
    float sin_az, cos_az; /* its azimuth in the grid's frame (the radiative SVF) */
    int pass;             /* +1: its lines meet the bands downward; -1: upward */
    int line_base;        /* its first entry in the per-line hull arrays */
    int slot;             /* its place in the batch: stack grid and output planes */
    int carry;            /* its rows of sums carried between bands (horizon walks) */
    int lit_level;        /* horizon walks: cells whose bound level (src/core/lit_levels.h)
                             is at most this are lit whatever the walk finds; -1: none known */
    int lit_sector;       /* the bounds' sector of its azimuth: their plane it reads */
} ss_band_dir;

/* What a band walk shares across its directions and lines (4-byte
 * members only: a kernel takes it by value). */
typedef struct {
    int row0, row1;       /* the band's own rows */
    int lo, held_rows;    /* the first row held, and how many */
    int height, width;    /* the grid's */
    int whole;            /* 1: the band is the whole grid */
    int term;             /* SS_TERM_* (ss_terms.h) */
    int want;             /* horizon walks: SS_HORIZON_WANT_* bits */
    int planes;           /* horizon walks: output planes per direction */
    int lines;            /* work-items per direction in this round ... */
    int slots;            /* ... and directions in the batch */
    float curv_k;         /* 1 / (2 R_eff), 0: no curvature */
    float none_deg;       /* horizon walks: where nothing lies ahead */
    float radius_m;       /* > 0: the highest terrain within it (radius walks) */
    float cell_x_m, cell_y_m;
    int stack_per_cell;   /* stack grid slots per held cell (box lines: SS_BOX_EVENTS;
                             radius walks with hulls: SS_RADIUS_SLOTS, a hull point) */
} ss_band_run;

/* Counters of a band visit (ints in one small buffer). */
#define SS_BAND_PENDING 0     /* hull points the walks so far will hand on */
#define SS_BAND_USED 1        /* hull points placed in hull_out */
#define SS_BAND_HANDOFFS 2    /* lines that handed a hull on */
#define SS_BAND_HULL_MAX 3    /* the largest hull handed on */
#define SS_BAND_COUNTERS 4

/* Each line's walk state at the band's edge, three ints per line: the hull's
 * depth (0: nothing to hand on), its slots carried in whole, and the step
 * its slots walked in this band count from. */
#define SS_BAND_STATE 3

/* Order in which a line set's owner rows are walked: +1 down, -1 up. */
SS_FN int ss_band_pass_of(const ss_line_set *ls)
{
    if (ls->major_is_row)
        return ls->step;
    return (ls->slope_fx < 0) == (ls->step < 0) || ls->slope_fx == 0 ? 1 : -1;
}

SS_FN int ss_band_owner_row(const ss_line_set *ls, const ss_walker *w, int s, int pass,
                            int height)
{
    ss_line_sample q = ss_walker_sample(ls, w, s);
    int row = ls->major_is_row ? q.major : (pass > 0 ? q.minor0 : q.minor0 + 1);
    return row < 0 ? 0 : (row >= height ? height - 1 : row);
}

/* First step of the walk whose owner row is at or past `row` in the
 * pass's order (owners are monotone along the walk); count if none. */
SS_FN int ss_band_first_step_past(const ss_line_set *ls, const ss_walker *w, int count, int row,
                                  int pass, int height)
{
    int lo = 0, hi = count;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        int r = ss_band_owner_row(ls, w, mid, pass, height);
        if (pass > 0 ? r >= row : r <= row)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* A band walk's hulls: what the band before handed on, and where each
 * line's state at the band's edge goes. */
typedef struct {
    SS_GLOBAL const ss_hull_point *in;
    SS_GLOBAL const int *in_off, *in_cnt;
    SS_GLOBAL int *state, *counters;
} ss_band_hulls;

/* A line with no steps in the band keeps its hull (one that has begun
 * always has steps in the next band; this keeps any other case exact). */
SS_FN void ss_band_line_untouched(const ss_band_dir *d, const ss_band_run *run, int line,
                                  SS_GLOBAL const int *in_cnt, SS_GLOBAL int *state,
                                  SS_GLOBAL int *counters)
{
    if (run->whole)
        return;
    int k = d->line_base + line;
    SS_GLOBAL int *st = state + SS_BAND_STATE * k;
    st[0] = st[1] = in_cnt[k];
    st[2] = 0;
    if (st[0] > 0)
        SS_ATOMIC_ADD(&counters[SS_BAND_PENDING], st[0]);
}

/* The steps [s_lo, s_hi) of a line of `count` steps whose owner rows the
 * band holds (all of them on the whole grid). */
SS_FN void ss_band_own_steps(const ss_walker *w, const ss_band_dir *d, const ss_band_run *run,
                             int count, int *s_lo, int *s_hi)
{
    if (run->whole) {
        *s_lo = 0;
        *s_hi = count;
        return;
    }
    int pass = d->pass;
    /* Owners in [row0, row1): entered at row0 going down, at row1 - 1 going up. */
    *s_lo = ss_band_first_step_past(&d->ls, w, count, pass > 0 ? run->row0 : run->row1 - 1, pass,
                                    run->height);
    *s_hi = ss_band_first_step_past(&d->ls, w, count, pass > 0 ? run->row1 : run->row0 - 1, pass,
                                    run->height);
}

/* Begins line `line` of direction d in the band: [*s_lo, *s_hi) are the
 * steps whose owner rows lie in the band, and the walk resumes with the
 * hull handed on from the band before. Returns 0 when the band holds
 * none of the line's steps (its hull is then kept as it is); *count gets
 * the line's step count. */
SS_FN int ss_band_line_begin(ss_walker *w, const ss_band_dir *d, const ss_band_run *run,
                             int line, ss_band_hulls hulls, int *s_lo, int *s_hi, int *count)
{
    *count = ss_walker_begin(w, &d->ls, line);
    ss_band_own_steps(w, d, run, *count, s_lo, s_hi);
    if (run->whole)
        return *count > 0;
    if (*s_lo >= *s_hi) {
        ss_band_line_untouched(d, run, line, hulls.in_cnt, hulls.state, hulls.counters);
        return 0;
    }
    int k = d->line_base + line;
    ss_walker_take_hull(w, *s_lo, hulls.in + hulls.in_off[k], hulls.in_cnt[k]);
    return 1;
}

/* Records a line's state once the band's steps [.., s_hi) of its count
 * are walked (a line that is done hands nothing on), and counts the points
 * it will hand on. */
SS_FN void ss_band_line_end(const ss_walker *w, const ss_band_dir *d, const ss_band_run *run,
                            int line, int s_hi, int count, SS_GLOBAL int *state,
                            SS_GLOBAL int *counters)
{
    if (run->whole)
        return;
    SS_GLOBAL int *st = state + SS_BAND_STATE * (d->line_base + line);
    st[0] = s_hi >= count ? 0 : w->depth;
    st[1] = w->slot_base;
    st[2] = w->sample_base;
    if (st[0] > 0)
        SS_ATOMIC_ADD(&counters[SS_BAND_PENDING], st[0]);
}

/* Hands a line's hull on, after its round's walks and before the next
 * round's (lines of the two rounds may share the stack grid's cells): its
 * slots carried in whole come from hull_in, the others are rebuilt from the
 * stack grid, into hull_out at a place taken with an atomic add (the
 * driver has made room for every point the walks counted). */
SS_FN void ss_band_hand_on(const ss_band_dir *d, int line,
                           SS_GLOBAL const float *z, SS_GLOBAL const int *stack,
                           SS_GLOBAL const ss_hull_point *hull_in, SS_GLOBAL const int *in_off,
                           SS_GLOBAL const int *state, SS_GLOBAL ss_hull_point *hull_out,
                           SS_GLOBAL int *out_off, SS_GLOBAL int *out_cnt,
                           SS_GLOBAL int *counters)
{
    int k = d->line_base + line;
    SS_GLOBAL const int *st = state + SS_BAND_STATE * k;
    int n = st[0];
    out_cnt[k] = n;
    out_off[k] = 0; /* where the next band takes none: an offset in bounds all the same */
    if (n == 0)
        return;
    int at = SS_ATOMIC_ADD(&counters[SS_BAND_USED], n);
    out_off[k] = at;
    SS_ATOMIC_ADD(&counters[SS_BAND_HANDOFFS], 1);
    SS_ATOMIC_MAX(&counters[SS_BAND_HULL_MAX], n);
    ss_walker w;
    ss_walker_begin(&w, &d->ls, line);
    w.carried = hull_in + in_off[k];
    w.slot_base = st[1];
    w.sample_base = st[2];
    for (int i = 0; i < n; ++i)
        hull_out[at + i] = ss_walker_load(&d->ls, &w, z, stack, i);
}

/* A direction's whole-grid line set re-based to a band's buffers, whose
 * first row is lo. */
SS_FN ss_line_set ss_band_lines_of(const ss_line_set *whole, int lo)
{
    ss_line_set ls = *whole;
    if (ls.major_is_row)
        ls.base_major = lo;
    else
        ls.base_minor = lo;
    return ls;
}

/* Rows of a band relative to its buffers: where the rows of sums carried
 * in from the band before land (its first own row going down, its last
 * going up), and the row beyond the band its walk feeds (-1: none, at the
 * grid's edge). */
SS_FN int ss_band_landing_row(const ss_band_run *run, int pass)
{
    return (pass > 0 ? run->row0 : run->row1 - 1) - run->lo;
}

SS_FN int ss_band_fed_row(const ss_band_run *run, int pass)
{
    if (pass > 0)
        return run->row1 < run->height ? run->row1 - run->lo : -1;
    return run->row0 > 0 ? run->row0 - 1 - run->lo : -1;
}

#endif
