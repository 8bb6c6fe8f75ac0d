/* The digital-line model of one sweep direction (shared by kernels and C).
 *
 * For an azimuth, the grid is cut into parallel "digital lines": along the
 * major axis (columns when the direction is closer to east-west, rows
 * otherwise) a line has exactly one cell per major index, at minor index
 *     minor = b + floor(major * slope + 1/2)
 * where b is the line's intercept and |slope| <= 1 is the minor cells per
 * major step. For every major index the map b -> minor is a shift, so the
 * lines partition the grid: every cell belongs to exactly one line, whatever
 * the slope. The floor is computed in 32.32 fixed point with integers only,
 * so the host, PoCL and a GPU assign every cell identically.
 *
 * Lines are walked from the far end in the azimuth's direction back toward
 * the opposite edge, so when a cell is reached, every cell of its line that
 * lies ahead of it in the azimuth has already been seen. A cell's position
 * along the walk is the projection of its centre on the azimuth (doc/model.md).
 */
#ifndef SS_LINES_H
#define SS_LINES_H

#include "ss_compat.h"

/* Layout shared with the host: members ordered by size, no implicit padding. */
typedef struct {
    ss_i64 slope_fx;        /* minor cells per major step, 32.32 fixed point */
    int major_len;          /* cells along the major axis */
    int minor_len;          /* cells along the minor axis */
    int major_is_row;       /* 1: major index is the row, 0: the column */
    int step;               /* +1 or -1: walk order along the major axis */
    int line_min;           /* intercept b of line number 0 */
    int n_lines;            /* lines needed to cover the grid */
    int width;              /* grid row length, to form cell indices */
    float along_per_step_m; /* distance walked per major step (> 0) */
    float along_per_minor_m;/* distance walked per +1 of the minor index */
    int reserved;
} ss_line_set;

/* Minor index of line b at a major index in [0, major_len). The 2^56 bias
 * keeps the shifted value non-negative, so the shift is a floor everywhere. */
SS_FN int ss_line_minor(const ss_line_set *ls, int b, int major)
{
    ss_i64 biased = (ss_i64)major * ls->slope_fx + ((ss_i64)1 << 31) + ((ss_i64)1 << 56);
    return b + (int)((biased >> 32) - ((ss_i64)1 << 24));
}

/* First major index at which line b reaches `target` on the minor axis
 * (from below when the slope rises, from above when it falls); major_len if
 * it never does. The minor index is monotone in the major index. */
SS_FN int ss_line_first_reaching(const ss_line_set *ls, int b, int target)
{
    int lo = 0, hi = ls->major_len;
    int rising = ls->slope_fx >= 0;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        int m = ss_line_minor(ls, b, mid);
        int reached = rising ? m >= target : m <= target;
        if (reached)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* Cells of line number `line` inside the grid: they occupy the major
 * indices [*first, *first + count). Returns count (0 for an empty line). */
SS_FN int ss_line_extent(const ss_line_set *ls, int line, int *first)
{
    int b = ls->line_min + line;
    int rising = ls->slope_fx >= 0;
    int lo = ss_line_first_reaching(ls, b, rising ? 0 : ls->minor_len - 1);
    int end = ss_line_first_reaching(ls, b, rising ? ls->minor_len : -1);
    *first = lo;
    return end > lo ? end - lo : 0;
}

/* Major index of the s-th cell in walk order of a line starting at `first`. */
SS_FN int ss_line_major_at(const ss_line_set *ls, int first, int count, int s)
{
    return ls->step > 0 ? first + s : first + count - 1 - s;
}

SS_FN int ss_line_cell(const ss_line_set *ls, int major, int minor)
{
    return ls->major_is_row ? major * ls->width + minor : minor * ls->width + major;
}

#endif
