/* What every banded sweep shares (banded.c for sums over directions,
 * banded_horizon.c for one grid per direction): a band of rows held with
 * halo rows, the two passes that walk the bands in their lines' order, the
 * share of a line's steps that a band walks, and the hulls handed on
 * between bands. banded.c's comment explains the rules. */
#ifndef SS_BAND_WALK_H
#define SS_BAND_WALK_H

#include "ctx_internal.h"
#include "ss_passes.h"

#define SS_BAND_HALO 2 /* rows held above and below a band */

typedef struct {
    ss_hull_point *points; /* the hull handed on, slots 0..count-1 */
    int count, capacity;
} ss_carried_hull;

/* A band's heights and hull stack slots: (band_rows + 2 HALO) x width,
 * from the band's row0 - HALO; rows outside the grid are NaN. */
typedef struct {
    ss_ctx *ctx;
    ss_rows_read read;
    void *user;
    int width, height, band_rows;
    int negate; /* heights read as -z (negative openness) */
    float *z;
    int *stack;
} ss_band_grid;

/* Sums of what the bands handed on, merged into ss_band_stats. */
typedef struct {
    size_t hull_sum, hull_max, handoffs;
} ss_band_tally;

/* Allocates the band's buffers; SS_ERR_MEMORY (with a message) if not. */
ss_status ss_band_grid_alloc(ss_band_grid *b);
void ss_band_grid_free(ss_band_grid *b);
size_t ss_band_held_cells(const ss_band_grid *b);
/* Reads rows [row0, row0 + rows) and their halo rows. */
ss_status ss_band_read(ss_band_grid *b, int row0, int rows);

/* Order in which a line set's owner rows are walked: +1 down, -1 up. */
int ss_band_pass_of(const ss_line_set *ls);
/* The whole-grid line set re-based to the band buffers of row0. */
ss_line_set ss_band_lines(const ss_line_set *whole, int row0);

/* Begins line `line` (of ls from ss_band_lines) in the band [row0, row1):
 * sets [*s_lo, *s_hi) to the steps whose owner rows lie in the band and
 * resumes the walker with the hull handed on. Returns 0 when the band
 * holds none of the line's steps. *count gets the line's step count. */
int ss_band_line_begin(const ss_line_set *ls, int line, const ss_carried_hull *hull, int row0,
                       int row1, int pass, int height, ss_walker *wk, int *s_lo, int *s_hi,
                       int *count);
/* After the band's steps: frees the hull of a line that is done, else
 * hands the walker's hull on (counted in tally). Returns 0, or -1 when out
 * of memory. */
int ss_band_line_end(ss_carried_hull *hull, ss_walker *wk, const ss_line_set *ls,
                     const ss_band_grid *b, int s_hi, int count, ss_band_tally *tally);
void ss_carried_hulls_free(ss_carried_hull *hulls, int n);
void ss_band_stats_add(ss_band_stats *stats, const ss_band_tally *t);

#endif
