/* The line models of one sweep direction (shared by kernels and C).
 *
 * For an azimuth, parallel lines cross the grid. Along the major axis
 * (columns when the direction is closer to east-west, rows otherwise) a
 * line with integer intercept b sits, at major index c, at minor position
 *     y = b + c * slope            (|slope| <= 1)
 * computed in fixed point with integers only, so the host, PoCL and a GPU
 * place every sample identically. Two models use these lines:
 *
 * - interpolated (default): the line is sampled at every major index
 *   exactly at y; the sample's height interpolates linearly between the two
 *   cells that bracket y across the line, and the sample's horizon goes
 *   back to those two cells with the same weights. Every cell receives
 *   weights summing to exactly 1 (weights have 16 fractional bits, so 1-t
 *   and t are exact in float). Exact on planes; converges to the continuous
 *   surface as directions grow (doc/model.md).
 * - digital: the line takes the cell nearest to y (y rounded) at every major
 *   index, so the lines partition the grid and every cell is one sample at
 *   its own centre; a cell's horizon is the exact maximum over cell centres,
 *   but cells sit up to half a cell beside the exact line, which biases
 *   short-range horizons on slopes.
 * - box: every cell is a flat-topped column (city DSMs with vertical walls,
 *   the model of UMEP and SOLWEIG). `families` lines per cell run across
 *   the grid, in one round per family (family f's intercepts are b + f /
 *   families); each family's lines are digital lines whose nearest cells
 *   hold their hull slots. A line meets every column boundary it crosses
 *   (ss_box.h), and delivers a horizon to the cells whose centres lie
 *   within half a family spacing of it.
 *
 * Lines are walked from the far end in the azimuth's direction back toward
 * the opposite edge, so when a sample is reached, every sample of its line
 * that lies ahead of it in the azimuth has been seen.
 */
#ifndef SS_LINES_H
#define SS_LINES_H

#include "ss_compat.h"

#define SS_LINE_MODEL_INTERPOLATED 0
#define SS_LINE_MODEL_DIGITAL 1
#define SS_LINE_MODEL_BOX 2

/* Layout shared with the host: members ordered by size, no implicit padding. */
typedef struct {
    ss_i64 slope_fx;        /* minor cells per major step, 32.32 fixed point */
    ss_i64 round_fx;        /* 2^31 for digital and box lines (round to nearest), else 0 */
    int model;              /* SS_LINE_MODEL_* */
    int major_len;          /* cells along the major axis */
    int minor_len;          /* cells along the minor axis */
    int major_is_row;       /* 1: major index is the row, 0: the column */
    int step;               /* +1 or -1: walk order along the major axis */
    int line_min;           /* intercept b of line number 0 */
    int n_lines;            /* lines needed to cover the grid (box: per family) */
    int width;              /* grid row length, to form cell indices */
    int stride_major;       /* cell index change per +1 of the major index */
    int stride_minor;       /* ... and per +1 of the minor index */
    float along_per_step_m; /* distance walked per major step (> 0) */
    float along_per_minor_m;/* distance walked per +1 of the minor index (digital and box) */
    float weight_per_frac;  /* interpolation weight per 1/65536 cell: 2^-16, or 0 for digital */
    int base_major;         /* the buffers' first major and minor index: 0 for the whole */
    int base_minor;         /* grid; a band of rows starts at its first held row (ss_band.h) */
    int families;           /* box lines: lines per cell across (a power of two); else 1 */
} ss_line_set;

/* floor(x / 65536) for |x| < 2^48 (positions on grids below 2^24 cells a
 * side): the bias makes the shifted value non-negative, so the shift is a
 * floor on every compiler. */
SS_FN ss_i64 ss_floor16(ss_i64 x)
{
    return ((x + ((ss_i64)1 << 48)) >> 16) - ((ss_i64)1 << 32);
}

/* Lines of every round together: families times the lines of one. */
SS_FN int ss_line_count(const ss_line_set *ls)
{
    return ls->n_lines * ls->families;
}

/* Intercept of line number `line`, 16.16 fixed point: box lines are
 * numbered family by family. */
SS_FN ss_i64 ss_line_intercept16(const ss_line_set *ls, int line)
{
    int family = line / ls->n_lines;
    return (ss_i64)(ls->line_min + line - family * ls->n_lines) * 65536 +
           (ss_i64)family * (65536 / ls->families);
}

/* Minor position of the line of 16.16 intercept b16 at a major index in
 * [0, major_len), 16.16 fixed point (plus one half for lines that round to
 * the nearest cell). The 2^56 bias keeps the shifted product non-negative,
 * so the division is a floor on every compiler. */
SS_FN ss_i64 ss_line_y16(const ss_line_set *ls, ss_i64 b16, int major)
{
    ss_i64 biased = (ss_i64)major * ls->slope_fx + ls->round_fx + ((ss_i64)1 << 56);
    return (biased >> 16) - ((ss_i64)1 << 40) + b16;
}

/* Minor index of the cell at or below the line (the nearest cell for digital lines). */
SS_FN int ss_line_minor(const ss_line_set *ls, ss_i64 b16, int major)
{
    return (int)ss_floor16(ss_line_y16(ls, b16, major));
}

/* Lowest 16.16 position that still yields a sample: a digital line must
 * land on a cell; an interpolated sample needs y > -1 (a positive weight on
 * cell 0). Positions must stay below minor_len. */
SS_FN ss_i64 ss_line_y16_low(const ss_line_set *ls)
{
    return ls->model == SS_LINE_MODEL_INTERPOLATED ? -65535 : 0;
}

/* First major index at which the position of the line of intercept b16 is
 * on the far side of `target` (>= target when the slope rises, <= target
 * when it falls); major_len if never. The position is monotone in the
 * major index. */
SS_FN int ss_line_first_reaching(const ss_line_set *ls, ss_i64 b16, ss_i64 target)
{
    int lo = 0, hi = ls->major_len;
    int rising = ls->slope_fx >= 0;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        ss_i64 y = ss_line_y16(ls, b16, mid);
        int reached = rising ? y >= target : y <= target;
        if (reached)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* Samples of line number `line` inside the grid: major indices
 * [*first, *first + count). Returns count (0 for an empty line). */
SS_FN int ss_line_extent(const ss_line_set *ls, int line, int *first)
{
    ss_i64 b16 = ss_line_intercept16(ls, line);
    ss_i64 low = ss_line_y16_low(ls), high = (ss_i64)ls->minor_len * 65536 - 1;
    int rising = ls->slope_fx >= 0;
    int lo = ss_line_first_reaching(ls, b16, rising ? low : high);
    int end = ss_line_first_reaching(ls, b16, rising ? high + 1 : low - 1);
    *first = lo;
    return end > lo ? end - lo : 0;
}

/* Major index of the s-th sample in walk order of a line starting at `first`. */
SS_FN int ss_line_major_at(const ss_line_set *ls, int first, int count, int s)
{
    return ls->step > 0 ? first + s : first + count - 1 - s;
}

/* Index of a cell in the buffers (the whole grid, or a band of rows). */
SS_FN int ss_line_cell(const ss_line_set *ls, int major, int minor)
{
    return (major - ls->base_major) * ls->stride_major + (minor - ls->base_minor) * ls->stride_minor;
}

/* One sample of a line: its height source and where its result goes. */
typedef struct {
    int major;
    int minor0;  /* cell at or below the line (may be -1 for interpolated lines) */
    int home;    /* a grid cell owned by this line alone among lines of the same
                    parity (digital: all lines), where its hull stack slot lives */
    float w1;    /* weight of cell minor0 + 1; cell minor0 has 1 - w1 */
} ss_line_sample;

/* The sample at a major index whose 16.16 position on the line is y. */
SS_FN ss_line_sample ss_line_sample_y16(const ss_line_set *ls, int major, ss_i64 y)
{
    ss_line_sample p;
    ss_i64 floor_y = ss_floor16(y);
    p.major = major;
    p.minor0 = (int)floor_y;
    p.w1 = (float)(int)(y - floor_y * 65536) * ls->weight_per_frac;
    p.home = ss_line_cell(ls, major, p.minor0 >= 0 ? p.minor0 : 0);
    return p;
}

SS_FN ss_line_sample ss_line_sample_at(const ss_line_set *ls, ss_i64 b16, int major)
{
    return ss_line_sample_y16(ls, major, ss_line_y16(ls, b16, major));
}

#endif
