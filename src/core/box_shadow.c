/* Box-model shadows by proven bounds and a march (box_shadow.h). */
#include "config.h"

#include <math.h>
#include <stddef.h>

#include "box_ray.h"
#include "box_shadow.h"

/* Suns steeper than this are not bounded from below (their tangent would
 * swamp the heights' precision); their cells are marched instead. */
#define STEEPEST_BOUNDED_DEG 89.0

/* One sun over the grid: its frame (box_ray.h) and what the bounds take. */
typedef struct {
    box_frame f;
    const float *z;
    double tan_lit;   /* the lowest sun's slope (clamped to 0..STEEPEST_BOUNDED_DEG) */
    double tan_shade; /* the highest sun's slope; INFINITY: no lower bound */
    double curv_k, curv_margin_m;
    int row0, row1;    /* the rows answered */
    float *angle;      /* the answer per cell of those rows */
} box_sun;

/* The ray from the centre of cell (col, row), column boundary after column
 * boundary (as tests/box_march.c): the largest slope of a column top above
 * the centre at the distance where the ray enters it, stopping where that
 * reaches tan_shade, where the ray leaves the grid, or before a column
 * whose line's upper bound (bound_before[p + 1 - first]: every column of
 * the line's span up to walk position p) the lowest sun clears from this
 * cell (lit_threshold). */
static double march_slope(const box_sun *b, int col, int row, double z0, const double *bound_before,
                          int first, double lit_threshold)
{
    box_ray ray = box_ray_from(&b->f, col, row);
    int last_position = -1;
    double best = 0.0, margin = box_rounding_margin(lit_threshold);
    while (box_ray_next(&b->f, &ray)) {
        if (ray.position != last_position) {
            last_position = ray.position;
            if (bound_before[ray.position + 1 - first] < lit_threshold - margin)
                return best;
        }
        float h = b->z[(size_t)ray.row * b->f.width + ray.col];
        double t = ray.t_in;
        if (isfinite(h) && h > z0) {
            double slope = (h - z0 - b->curv_k * t * t) / t;
            if (slope > best) {
                best = slope;
                if (best >= b->tan_shade)
                    return best;
            }
        }
    }
    return best;
}

/* The tallest top of the three cells around a line at (major, minor), and
 * the lowest (-INFINITY where one is outside the grid or nodata: a ray may
 * cross it). */
static inline void window_tops(const box_sun *b, int major, int minor, double *top, double *low)
{
    const box_frame *f = &b->f;
    double hi = -INFINITY, lo = INFINITY;
    for (int m = minor - 1; m <= minor + 1; ++m) {
        float h =
            m >= 0 && m < f->minor_len ? b->z[major * f->stride_major + m * f->stride_minor] : NAN;
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
 * sun's side; bound_before is its work space (major_len + 1 values). Its
 * cells outside the rows answered only feed the bounds, and the walk ends
 * past those rows: a ray runs toward the sun, to earlier positions. */
static void walk_line(const void *job, int line, double *bound_before, ss_box_ray_counts *counts)
{
    const box_sun *b = job;
    const box_frame *f = &b->f;
    double upper = -INFINITY, lower = -INFINITY;
    int first = box_first_past(f, line, 0), end = box_first_past(f, line, 1), rows_fall;
    if (!box_line_meets_rows(f, line, first, end, b->row0, b->row1, &rows_fall))
        return;
    bound_before[0] = -INFINITY;
    for (int p = first; p < end; ++p) {
        int major = box_walk_position(f, p); /* the same map both ways */
        int minor = line + f->shift[major];
        int row_here = box_line_row(f, line, p);
        if (box_past_rows(row_here, rows_fall, b->row0, b->row1))
            break;
        double along = p * f->step_m;
        /* A ray through a corner may step first into its own column,
         * whose bound is made after it: there nothing stops its march. */
        bound_before[p + 1 - first] = INFINITY;
        if (minor >= 0 && minor < f->minor_len && row_here >= b->row0 && row_here < b->row1) {
            ptrdiff_t cell = major * f->stride_major + minor * f->stride_minor;
            float z0 = b->z[cell];
            float *angle = b->angle + (cell - (ptrdiff_t)b->row0 * f->width);
            if (!isfinite(z0)) {
                *angle = 0.0f;
            } else {
                counts->cells++;
                double lit_threshold = z0 + b->tan_lit * along;
                double shade_threshold = z0 + b->tan_shade * along + b->curv_margin_m;
                if (upper < lit_threshold - box_rounding_margin(lit_threshold)) {
                    *angle = 0.0f;
                } else if (lower > shade_threshold + box_rounding_margin(shade_threshold)) {
                    *angle = 90.0f;
                } else {
                    counts->marched++;
                    int col, row;
                    box_cell_at(f, major, minor, &col, &row);
                    double slope = march_slope(b, col, row, z0, bound_before, first, lit_threshold);
                    *angle = (float)(atan(slope) * (180.0 / M_PI));
                }
            }
        }
        {
            double top, low;
            window_tops(b, major, minor, &top, &low);
            /* A ray enters this column half a column nearer than its centre. */
            double up = top + b->tan_lit * (along + 0.5 * f->step_m);
            double down = low + b->tan_shade * along;
            upper = up > upper ? up : upper;
            lower = down > lower ? down : lower;
        }
        bound_before[p + 1 - first] = upper;
    }
}

int ss_box_shadow_horizons(const ss_grid *grid, double grid_azimuth_deg, double el_lo_deg,
                           double el_hi_deg, double curv_k, int row0, int n_rows,
                           const volatile sig_atomic_t *cancel, float *angle,
                           ss_box_ray_counts *counts)
{
    size_t n = (size_t)grid->width * n_rows;
    *counts = (ss_box_ray_counts){0, 0};
    if (!(el_hi_deg > 0.0)) {
        /* Below the horizontal every column's own top shades its centre. */
        for (size_t c = 0; c < n; ++c)
            angle[c] = 0.0f;
        return 1;
    }
    box_sun b = {.z = grid->z,
                 .curv_k = curv_k,
                 .row0 = row0,
                 .row1 = row0 + n_rows,
                 .angle = angle};
    if (!box_frame_init(&b.f, grid, grid_azimuth_deg))
        return 0;
    double lo = fmin(fmax(el_lo_deg, 0.0), STEEPEST_BOUNDED_DEG);
    b.tan_lit = tan(lo * (M_PI / 180.0));
    b.tan_shade = el_hi_deg < STEEPEST_BOUNDED_DEG ? tan(el_hi_deg * (M_PI / 180.0)) : INFINITY;
    double length_m = b.f.major_len * b.f.step_m;
    b.curv_margin_m = curv_k * length_m * length_m;
    int done = box_frame_walk_lines(&b.f, walk_line, &b, cancel, counts);
    box_frame_free(&b.f);
    return done;
}
