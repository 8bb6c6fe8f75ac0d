/* One sun's rays over a grid, and the lines that walk it (box_ray.h). */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "box_ray.h"
#include "ctx_internal.h" /* ss_malloc */

int box_first_past(const box_frame *f, int line, int its_end)
{
    /* The minor index is monotonic along a line: a binary search. */
    int rising = f->shift_rising;
    int lo = 0, hi = f->major_len;
    while (lo < hi) {
        int mid = lo + (hi - lo) / 2;
        int minor = line + f->shift[box_walk_position(f, mid)];
        int past = rising ? (its_end ? minor > f->minor_len : minor >= -1)
                          : (its_end ? minor < -1 : minor <= f->minor_len);
        if (past)
            hi = mid;
        else
            lo = mid + 1;
    }
    return lo;
}

int box_frame_init(box_frame *f, const ss_grid *g, double grid_azimuth_deg)
{
    double az = grid_azimuth_deg * (M_PI / 180.0);
    f->width = g->width;
    f->height = g->height;
    f->col_per_m = sin(az) / g->cell_x_m;
    f->row_per_m = -cos(az) / g->cell_y_m; /* rows run south */
    int major_is_col = fabs(f->col_per_m) >= fabs(f->row_per_m);
    f->major_is_col = major_is_col;
    double major_per_m = major_is_col ? f->col_per_m : f->row_per_m;
    f->major_len = major_is_col ? g->width : g->height;
    f->minor_len = major_is_col ? g->height : g->width;
    f->stride_major = major_is_col ? 1 : g->width;
    f->stride_minor = major_is_col ? g->width : 1;
    f->sun_at_high_major = major_per_m > 0.0;
    f->step_m = 1.0 / fabs(major_per_m);
    double slope = major_is_col ? f->row_per_m / f->col_per_m : f->col_per_m / f->row_per_m;
    f->shift = ss_malloc(sizeof(int) * (size_t)f->major_len);
    if (!f->shift)
        return 0;
    int lowest = 0, highest = 0;
    for (int m = 0; m < f->major_len; ++m) {
        f->shift[m] = (int)floor(slope * m + 0.5);
        lowest = f->shift[m] < lowest ? f->shift[m] : lowest;
        highest = f->shift[m] > highest ? f->shift[m] : highest;
    }
    f->shift_rising =
        f->shift[box_walk_position(f, f->major_len - 1)] >= f->shift[box_walk_position(f, 0)];
    /* Every cell of a major index m lies on line minor - shift[m]. */
    f->first_line = -highest;
    f->last_line = f->minor_len - 1 - lowest;
    return 1;
}

void box_frame_free(box_frame *f)
{
    free(f->shift);
    f->shift = NULL;
}

int box_frame_walk_lines(const box_frame *f, box_line_walk walk, const void *job,
                         const volatile sig_atomic_t *cancel, ss_box_ray_counts *counts)
{
    int failed = 0;
    uint64_t cells = 0, marched = 0;
#pragma omp parallel reduction(+ : cells, marched, failed)
    {
        double *bound_before = ss_malloc(sizeof(double) * ((size_t)f->major_len + 1));
        ss_box_ray_counts mine = {0, 0};
        failed += !bound_before;
#pragma omp for schedule(dynamic, 16)
        for (int line = f->first_line; line <= f->last_line; ++line)
            if (bound_before && !(cancel && *cancel))
                walk(job, line, bound_before, &mine);
        cells += mine.cells;
        marched += mine.marched;
        free(bound_before);
    }
    counts->cells = cells;
    counts->marched = marched;
    return !failed;
}
