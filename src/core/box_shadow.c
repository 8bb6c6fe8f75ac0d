/* Box-model shadows by proven bounds and a march (box_shadow.h). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "box_shadow.h"
#include "ctx_internal.h" /* ss_malloc */

/* Suns steeper than this are not bounded from below (their tangent would
 * swamp the heights' precision); their cells are marched instead. */
#define STEEPEST_BOUNDED_DEG 89.0

/* One sun over the grid, in the frame of its walk: the major axis is the
 * one the ray crosses more columns of per metre. */
typedef struct {
    const float *z;
    int width, height;
    int major_len, minor_len;
    ptrdiff_t stride_major, stride_minor;
    int sun_at_high_major; /* the sun lies toward increasing major index */
    double step_m;         /* metres along the ray per major column */
    const int *shift;      /* per major index: floor(slope * major + 1/2), in minor cells */
    int shift_rising;      /* shift never falls along the walk */
    double col_per_m, row_per_m; /* the ray toward the sun, in cells per metre */
    double tan_lit;   /* the lowest sun's slope (clamped to 0..STEEPEST_BOUNDED_DEG) */
    double tan_shade; /* the highest sun's slope; INFINITY: no lower bound */
    double curv_k, curv_margin_m;
} box_sun;

/* Position along the walk: columns from the sun's side. */
static inline int walk_position(const box_sun *b, int major)
{
    return b->sun_at_high_major ? b->major_len - 1 - major : major;
}

/* A margin for rounding: what the bounds compare differs from what the
 * march compares by a few ulps of the larger side. */
static inline double rounding_margin(double threshold)
{
    return 1e-6 + 1e-9 * fabs(threshold);
}

/* The first walk position whose cell of line `line` lies past its span's
 * start (its_end 0) or past its end (its_end 1): the span being where the
 * line or a cell beside it lies in the grid, its minor index from -1 to
 * minor_len. The minor index is monotonic along a line. */
static int first_past(const box_sun *b, int line, int its_end)
{
    int rising = b->shift_rising;
    int lo = 0, hi = b->major_len;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        int minor = line + b->shift[walk_position(b, mid)];
        int past = rising ? (its_end ? minor > b->minor_len : minor >= -1)
                          : (its_end ? minor < -1 : minor <= b->minor_len);
        if (past)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

/* The ray from the centre of cell (col, row), column boundary after column
 * boundary (as tests/box_march.c): the largest slope of a column top above
 * the centre at the distance where the ray enters it, stopping where that
 * reaches tan_shade, where the ray leaves the grid, or before a column
 * whose line's upper bound (bound_before[p + 1 - first]: every column of
 * the line's span up to walk position p) the lowest sun clears from this
 * cell (lit_threshold). */
static double march_slope(const box_sun *b, int col, int row, double z0,
                          const double *bound_before, int first, double lit_threshold)
{
    double step_x = b->col_per_m != 0.0 ? 1.0 / fabs(b->col_per_m) : INFINITY;
    double step_y = b->row_per_m != 0.0 ? 1.0 / fabs(b->row_per_m) : INFINITY;
    double tx = 0.5 * step_x, ty = 0.5 * step_y;
    int sx = b->col_per_m > 0.0 ? 1 : -1, sy = b->row_per_m > 0.0 ? 1 : -1;
    int major_is_col = b->stride_major == 1;
    int last_position = -1;
    double best = 0.0, margin = rounding_margin(lit_threshold);
    for (;;) {
        double t;
        if (tx < ty) {
            t = tx;
            col += sx;
            tx += step_x;
        } else {
            t = ty;
            row += sy;
            ty += step_y;
        }
        if (col < 0 || row < 0 || col >= b->width || row >= b->height)
            return best;
        int position = walk_position(b, major_is_col ? col : row);
        if (position != last_position) {
            last_position = position;
            if (bound_before[position + 1 - first] < lit_threshold - margin)
                return best;
        }
        float h = b->z[(size_t)row * b->width + col];
        if (isfinite(h) && h > z0) {
            double slope = (h - z0 - b->curv_k * t * t) / t;
            if (slope > best) {
                best = slope;
                if (best >= b->tan_shade)
                    return best;
            }
        }
    }
}

/* The tallest top of the three cells around a line at (major, minor), and
 * the lowest (-INFINITY where one is outside the grid or nodata: a ray may
 * cross it). */
static inline void window_tops(const box_sun *b, int major, int minor, double *top, double *low)
{
    double hi = -INFINITY, lo = INFINITY;
    for (int m = minor - 1; m <= minor + 1; ++m) {
        float h = m >= 0 && m < b->minor_len
                      ? b->z[major * b->stride_major + m * b->stride_minor]
                      : NAN;
        if (isfinite(h)) {
            hi = h > hi ? h : hi;
            lo = h < lo ? h : lo;
        } else {
            lo = -INFINITY;
        }
    }
    *top = hi;
    *low = lo;
}

/* Line `line`'s cells (minor index line + shift[major]), walked from the
 * sun's side; bound_before is its work space (major_len + 1 values). */
static void walk_line(const box_sun *b, int line, double *bound_before, float *angle,
                      ss_box_shadow_counts *counts)
{
    double upper = -INFINITY, lower = -INFINITY;
    int first = first_past(b, line, 0), end = first_past(b, line, 1);
    bound_before[0] = -INFINITY;
    for (int p = first; p < end; ++p) {
        int major = walk_position(b, p); /* the same map both ways */
        int minor = line + b->shift[major];
        double along = p * b->step_m;
        if (minor >= 0 && minor < b->minor_len) {
            ptrdiff_t cell = major * b->stride_major + minor * b->stride_minor;
            float z0 = b->z[cell];
            if (!isfinite(z0)) {
                angle[cell] = 0.0f;
            } else {
                counts->cells++;
                double lit_threshold = z0 + b->tan_lit * along;
                double shade_threshold = z0 + b->tan_shade * along + b->curv_margin_m;
                if (upper < lit_threshold - rounding_margin(lit_threshold)) {
                    angle[cell] = 0.0f;
                } else if (lower > shade_threshold + rounding_margin(shade_threshold)) {
                    angle[cell] = 90.0f;
                } else {
                    counts->marched++;
                    int col = b->stride_major == 1 ? major : minor;
                    int row = b->stride_major == 1 ? minor : major;
                    double slope =
                        march_slope(b, col, row, z0, bound_before, first, lit_threshold);
                    angle[cell] = (float)(atan(slope) * (180.0 / M_PI));
                }
            }
        }
        {
            double top, low;
            window_tops(b, major, minor, &top, &low);
            /* A ray enters this column half a column nearer than its centre. */
            double up = top + b->tan_lit * (along + 0.5 * b->step_m);
            double down = low + b->tan_shade * along;
            upper = up > upper ? up : upper;
            lower = down > lower ? down : lower;
        }
        bound_before[p + 1 - first] = upper;
    }
}

/* The walk's frame for a sun toward grid azimuth az_rad. */
static void frame_of(box_sun *b, const ss_grid *g, double az_rad)
{
    b->col_per_m = sin(az_rad) / g->cell_x_m;
    b->row_per_m = -cos(az_rad) / g->cell_y_m; /* rows run south */
    int major_is_col = fabs(b->col_per_m) >= fabs(b->row_per_m);
    double major_per_m = major_is_col ? b->col_per_m : b->row_per_m;
    b->major_len = major_is_col ? g->width : g->height;
    b->minor_len = major_is_col ? g->height : g->width;
    b->stride_major = major_is_col ? 1 : g->width;
    b->stride_minor = major_is_col ? g->width : 1;
    b->sun_at_high_major = major_per_m > 0.0;
    b->step_m = 1.0 / fabs(major_per_m);
}

int ss_box_shadow_horizons(const ss_grid *grid, double grid_azimuth_deg, double el_lo_deg,
                           double el_hi_deg, double curv_k,
                           const volatile sig_atomic_t *cancel, float *angle,
                           ss_box_shadow_counts *counts)
{
    size_t n = (size_t)grid->width * grid->height;
    *counts = (ss_box_shadow_counts){0, 0};
    if (!(el_hi_deg > 0.0)) {
        /* Below the horizontal every column's own top shades its centre. */
        for (size_t c = 0; c < n; ++c)
            angle[c] = 0.0f;
        return 1;
    }
    box_sun b = {.z = grid->z, .width = grid->width, .height = grid->height, .curv_k = curv_k};
    frame_of(&b, grid, grid_azimuth_deg * (M_PI / 180.0));
    double slope = b.stride_major == 1 ? b.row_per_m / b.col_per_m : b.col_per_m / b.row_per_m;
    int *shift = ss_malloc(sizeof(int) * (size_t)b.major_len);
    if (!shift)
        return 0;
    int lowest = 0, highest = 0;
    for (int m = 0; m < b.major_len; ++m) {
        shift[m] = (int)floor(slope * m + 0.5);
        lowest = shift[m] < lowest ? shift[m] : lowest;
        highest = shift[m] > highest ? shift[m] : highest;
    }
    b.shift = shift;
    b.shift_rising = shift[walk_position(&b, b.major_len - 1)] >= shift[walk_position(&b, 0)];
    double lo = fmin(fmax(el_lo_deg, 0.0), STEEPEST_BOUNDED_DEG);
    b.tan_lit = tan(lo * (M_PI / 180.0));
    b.tan_shade = el_hi_deg < STEEPEST_BOUNDED_DEG ? tan(el_hi_deg * (M_PI / 180.0)) : INFINITY;
    double length_m = b.major_len * b.step_m;
    b.curv_margin_m = curv_k * length_m * length_m;
    /* Every cell of a major index m lies on line minor - shift[m]. */
    int first_line = -highest, last_line = b.minor_len - 1 - lowest;
    int failed = 0;
    uint64_t cells = 0, marched = 0;
#pragma omp parallel reduction(+ : cells, marched, failed)
    {
        double *bound_before = ss_malloc(sizeof(double) * ((size_t)b.major_len + 1));
        ss_box_shadow_counts mine = {0, 0};
        failed += !bound_before;
#pragma omp for schedule(dynamic, 16)
        for (int line = first_line; line <= last_line; ++line)
            if (bound_before && !(cancel && *cancel))
                walk_line(&b, line, bound_before, angle, &mine);
        cells += mine.cells;
        marched += mine.marched;
        free(bound_before);
    }
    free(shift);
    counts->cells = cells;
    counts->marched = marched;
    return !failed;
}
