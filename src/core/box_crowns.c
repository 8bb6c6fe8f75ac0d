/* Box-model crowns crossed by each cell's own ray (box_crowns.h). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "box_crowns.h"
#include "crown_union.h" /* trunk_of */

/* The bound's slope is clamped here, which keeps it a bound (a lower slope
 * lifts the tops less) and keeps steep suns' tangents from swamping the
 * heights' precision. */
#define STEEPEST_BOUNDED_DEG 89.0

typedef struct {
    box_frame f;
    const float *z;
    const ss_canopy *canopy;
    const float *solid_angle; /* of the rows answered; cells at or above solid_el_hi are not asked */
    double solid_el_hi;
    double tan_e;           /* the sun's slope */
    double tan_bound;       /* the bound's (tan_e, clamped) */
    int row0, row1;         /* the rows answered */
    unsigned char *crossed; /* the answer per cell of the grid (those rows' alone written) */
} box_crowns;

/* Cell i's crown as heights (*bottom, *top): 0 where it has none. */
static inline int crown_of(const box_crowns *b, size_t i, double *bottom, double *top)
{
    float z = b->z[i];
    double height = b->canopy->height_m[i], trunk = trunk_of(b->canopy, i);
    if (!isfinite(z) || !(height > trunk))
        return 0;
    *bottom = z + trunk;
    *top = z + height;
    return 1;
}

/* The ray from the centre of cell (col, row) at height z0, square after
 * square: 1 at the first crown whose open interval its span of heights
 * over the square meets; 0 where it leaves the grid, or before a column
 * whose line's bound (bound_before[p + 1 - first]) it passes above
 * (threshold: z0 + tan_bound times the cell's distance along the walk). */
static int march_crossed(const box_crowns *b, int col, int row, double z0,
                         const double *bound_before, int first, double threshold)
{
    box_ray ray = box_ray_from(&b->f, col, row);
    int last_position = -1;
    double margin = box_rounding_margin(threshold);
    while (box_ray_next(&b->f, &ray)) {
        if (ray.position != last_position) {
            last_position = ray.position;
            if (bound_before[ray.position + 1 - first] < threshold - margin)
                return 0;
        }
        double bottom, top;
        if (crown_of(b, (size_t)ray.row * b->f.width + ray.col, &bottom, &top) &&
            z0 + b->tan_e * ray.t_in < top && z0 + b->tan_e * ray.t_out > bottom)
            return 1;
    }
    return 0;
}

/* The highest crown top of the three cells around a line at (major,
 * minor); -INFINITY where none has a crown. */
static inline double window_top(const box_crowns *b, int major, int minor)
{
    const box_frame *f = &b->f;
    double hi = -INFINITY, bottom, top;
    for (int m = minor - 1; m <= minor + 1; ++m)
        if (m >= 0 && m < f->minor_len &&
            crown_of(b, (size_t)(major * f->stride_major + m * f->stride_minor), &bottom, &top))
            hi = top > hi ? top : hi;
    return hi;
}

/* Line `line`'s cells, walked from the sun's side; bound_before is its
 * work space (major_len + 1 values). Its cells outside the rows answered
 * only feed the bound (box_line_meets_rows). */
static void walk_line(const void *job, int line, double *bound_before, ss_box_ray_counts *counts)
{
    const box_crowns *b = job;
    const box_frame *f = &b->f;
    double upper = -INFINITY;
    int first = box_first_past(f, line, 0), end = box_first_past(f, line, 1), rows_fall;
    if (!box_line_meets_rows(f, line, first, end, b->row0, b->row1, &rows_fall))
        return;
    bound_before[0] = -INFINITY;
    for (int p = first; p < end; ++p) {
        int major = box_walk_position(f, p);
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
            double threshold = z0 + b->tan_bound * along;
            ptrdiff_t own = cell - (ptrdiff_t)b->row0 * f->width;
            if (isfinite(z0) && !(b->solid_angle && b->solid_angle[own] >= b->solid_el_hi)) {
                counts->cells++;
                if (!(upper < threshold - box_rounding_margin(threshold))) {
                    counts->marched++;
                    int col, row;
                    box_cell_at(f, major, minor, &col, &row);
                    b->crossed[cell] = (unsigned char)march_crossed(b, col, row, z0, bound_before,
                                                                    first, threshold);
                }
            }
        }
        /* A ray enters this column half a column nearer than its centre. */
        double up = window_top(b, major, minor) + b->tan_bound * (along + 0.5 * f->step_m);
        upper = up > upper ? up : upper;
        bound_before[p + 1 - first] = upper;
    }
}

int ss_box_crowns_crossed(const ss_grid *grid, const ss_canopy *canopy, double grid_azimuth_deg,
                          double elevation_deg, int row0, int n_rows, const float *solid_angle,
                          double solid_el_hi, const volatile sig_atomic_t *cancel,
                          unsigned char *crossed, ss_box_ray_counts *counts)
{
    *counts = (ss_box_ray_counts){0, 0};
    memset(crossed + (size_t)row0 * grid->width, 0, (size_t)grid->width * n_rows);
    box_crowns b = {.z = grid->z,
                    .canopy = canopy,
                    .solid_angle = solid_angle,
                    .solid_el_hi = solid_el_hi,
                    .row0 = row0,
                    .row1 = row0 + n_rows,
                    .crossed = crossed};
    if (!box_frame_init(&b.f, grid, grid_azimuth_deg))
        return 0;
    b.tan_e = tan(elevation_deg * (M_PI / 180.0));
    b.tan_bound = tan(fmin(elevation_deg, STEEPEST_BOUNDED_DEG) * (M_PI / 180.0));
    int done = box_frame_walk_lines(&b.f, walk_line, &b, cancel, counts);
    box_frame_free(&b.f);
    return done;
}
