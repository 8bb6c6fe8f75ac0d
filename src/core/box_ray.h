/* The frame that box-model work by each cell's own ray shares
 * (box_shadow.c for solid columns, box_crowns.c for crowns): one sun's
 * rays over a grid, the lines one cell across that walk it from the sun's
 * side, and the cell traversal of one ray (Amanatides & Woo 1987).
 *
 * The major axis is the one the ray crosses more columns of per metre.
 * Line `line` holds the cell of minor index line + shift[major] at each
 * major index; a cell's ray runs beside its line by less than half a cell,
 * so in every column it crosses it stays within the three cells around the
 * line there. That is what lets a running maximum along the line bound
 * what every ray of the line meets (doc/model.md, "Cast shadows: each
 * cell's own ray"). */
#ifndef SS_BOX_RAY_H
#define SS_BOX_RAY_H

#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdint.h>

#include "skysweep.h"

/* What a walk by each cell's own ray did. */
typedef struct {
    uint64_t cells;   /* cells with a height */
    uint64_t marched; /* of them, those the bounds left to the march */
} ss_box_ray_counts;

typedef struct {
    int width, height;
    int major_is_col; /* the major axis is the columns (a grid one cell wide may have
                         stride_major 1 either way) */
    int major_len, minor_len;
    ptrdiff_t stride_major, stride_minor;
    int sun_at_high_major;       /* the sun lies toward increasing major index */
    double step_m;               /* metres along the ray per major column */
    int *shift;                  /* per major index: floor(slope * major + 1/2), in minor cells */
    int shift_rising;            /* shift never falls along the walk */
    double col_per_m, row_per_m; /* the ray toward the sun, in cells per metre */
    int first_line, last_line;   /* the lines whose cells or neighbours lie in the grid */
} box_frame;

/* The frame of a sun toward grid azimuth grid_azimuth_deg (clockwise from
 * the grid's north) over grid. Returns 0 when out of memory. */
int box_frame_init(box_frame *f, const ss_grid *grid, double grid_azimuth_deg);
void box_frame_free(box_frame *f);

/* Position along the walk: columns from the sun's side. The same map
 * takes a position back to its major index. */
static inline int box_walk_position(const box_frame *f, int major)
{
    return f->sun_at_high_major ? f->major_len - 1 - major : major;
}

/* The row of line `line`'s cell at walk position p (beyond the grid's
 * rows where the line is). Rows are monotonic along a line. */
static inline int box_line_row(const box_frame *f, int line, int p)
{
    int major = box_walk_position(f, p);
    return f->major_is_col ? line + f->shift[major] : major;
}

/* Work over rows [row0, row1) alone (a band's): whether line `line`'s
 * positions [first, end) meet those rows, and *rows_fall, whether its rows
 * fall along the walk; box_past_rows then says where the walk may end, for
 * a ray runs toward the sun, to earlier positions. */
static inline int box_line_meets_rows(const box_frame *f, int line, int first, int end,
                                      int row0, int row1, int *rows_fall)
{
    if (first >= end)
        return 0;
    int row_a = box_line_row(f, line, first), row_b = box_line_row(f, line, end - 1);
    *rows_fall = row_b < row_a;
    int lo = row_a < row_b ? row_a : row_b, hi = row_a < row_b ? row_b : row_a;
    return hi >= row0 && lo < row1;
}

static inline int box_past_rows(int row, int rows_fall, int row0, int row1)
{
    return rows_fall ? row < row0 : row >= row1;
}

/* The column and row of the cell at (major, minor). */
static inline void box_cell_at(const box_frame *f, int major, int minor, int *col, int *row)
{
    *col = f->major_is_col ? major : minor;
    *row = f->major_is_col ? minor : major;
}

/* One line's walk (box_shadow.c's, box_crowns.c's): job is the walker's
 * own state, bound_before a work space of major_len + 1 values, counts
 * what the line's cells add. */
typedef void (*box_line_walk)(const void *job, int line, double *bound_before,
                              ss_box_ray_counts *counts);

/* Walks every line of f with walk on OpenMP's threads, each thread with
 * its own work space, the counts summed into *counts; lines not begun when
 * *cancel (NULL: none) is set are skipped. Each cell belongs to exactly
 * one line, so walkers write their cells without locks. Returns 0 when out
 * of memory. */
int box_frame_walk_lines(const box_frame *f, box_line_walk walk, const void *job,
                         const volatile sig_atomic_t *cancel, ss_box_ray_counts *counts);

/* The first walk position whose cell of line `line` lies past its span's
 * start (its_end 0) or past its end (its_end 1): the span being where the
 * line or a cell beside it lies in the grid, its minor index from -1 to
 * minor_len. */
int box_first_past(const box_frame *f, int line, int its_end);

/* A margin for rounding: what the bounds compare differs from what the
 * march compares by a few ulps of the larger side. */
static inline double box_rounding_margin(double threshold)
{
    return 1e-6 + 1e-9 * fabs(threshold);
}

/* One ray from a cell's centre toward the sun, square after square. */
typedef struct {
    int col, row;
    int position;       /* the walk position of the square it is in */
    double t_in, t_out; /* metres from the centre where it enters and leaves it */
    double tx, ty, step_x, step_y;
    int sx, sy;
} box_ray;

static inline box_ray box_ray_from(const box_frame *f, int col, int row)
{
    box_ray r;
    r.col = col;
    r.row = row;
    r.step_x = f->col_per_m != 0.0 ? 1.0 / fabs(f->col_per_m) : INFINITY;
    r.step_y = f->row_per_m != 0.0 ? 1.0 / fabs(f->row_per_m) : INFINITY;
    r.tx = 0.5 * r.step_x;
    r.ty = 0.5 * r.step_y;
    r.sx = f->col_per_m > 0.0 ? 1 : -1;
    r.sy = f->row_per_m > 0.0 ? 1 : -1;
    r.position = -1;
    r.t_in = r.t_out = 0.0;
    return r;
}

/* Into the next square the ray crosses: 0 where it leaves the grid. */
static inline int box_ray_next(const box_frame *f, box_ray *r)
{
    if (r->tx < r->ty) {
        r->t_in = r->tx;
        r->col += r->sx;
        r->tx += r->step_x;
    } else {
        r->t_in = r->ty;
        r->row += r->sy;
        r->ty += r->step_y;
    }
    if (r->col < 0 || r->row < 0 || r->col >= f->width || r->row >= f->height)
        return 0;
    r->t_out = r->tx < r->ty ? r->tx : r->ty;
    r->position = box_walk_position(f, f->major_is_col ? r->col : r->row);
    return 1;
}

#endif
