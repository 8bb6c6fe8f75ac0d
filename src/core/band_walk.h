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

/* What a product does with a line's steps [s_lo, s_hi) in a band: walk
 * them (ss_walker_step with flags) and add what they feed into its sums.
 * Called from OpenMP threads, lines of one round at once. */
typedef void (*ss_band_steps_fn)(void *user, ss_walker *wk, const ss_line_set *ls, int s_lo,
                                 int s_hi, int flags);

/* Walks one direction (its whole-grid line set and one carried hull per
 * line) through the band [row0, row1) in the pass's order: every line's
 * steps owned by the band's rows, resumed from its carried hull, handed to
 * steps, and the hull handed on (counted in stats) or freed when the line
 * is done. SS_ERR_MEMORY (with a message) if a hull cannot be kept. */
ss_status ss_band_walk(const ss_band_grid *b, const ss_line_set *whole, ss_carried_hull *hulls,
                       int row0, int row1, int pass, float curv_k, ss_band_steps_fn steps,
                       void *user, ss_band_stats *stats);
void ss_carried_hulls_free(ss_carried_hull *hulls, int n);

#endif
