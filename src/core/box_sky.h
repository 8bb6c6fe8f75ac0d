/* The box model's sky view by each cell's own ray (doc/model.md, "The sky
 * view: each cell's own ray").
 *
 * A cell of a city DSM is a flat-topped column. Its box horizon toward an
 * azimuth is the largest elevation, seen from its centre, of the column
 * tops its ray crosses, its own top (0 degrees) included: a top above the
 * eye shows at the distance where the ray enters its square (as
 * kernels/ss_box.h's points are); one below never rises above 0. Box
 * lines approximate each ray by the nearest of their lines; here every
 * cell gets its own, so the result is the box model exactly:
 *
 *   - Every ray of one azimuth crosses the same squares, as offsets from
 *     its cell, at the same distances from its centre: the traversal
 *     (Amanatides & Woo 1987, box_ray.h's, which lists them) does not
 *     depend on where it starts. So each direction's squares are listed
 *     once, ties between a column and a row boundary settled once, and
 *     each cell walks the list with no stepping arithmetic.
 *   - A walk ends where the ray leaves the grid, or where even the grid's
 *     highest top could not rise above the best angle found so far; on
 *     the way it passes over every block of 32 x 32 cells whose highest
 *     top could not rise above that angle where the ray enters the block
 *     (on terrain, every block downhill).
 *   - Where the CPU has AVX2, four cells side by side walk together, one
 *     load of four heights a square (box_sky_lanes.c), with the same
 *     answer bit for bit.
 *
 * Each cell's answer depends on the heights alone, not on which rows are
 * asked, so any band height gives the whole grid's answer bit for bit. */
#ifndef SS_BOX_SKY_H
#define SS_BOX_SKY_H

#include <signal.h>

#include "skysweep.h"

/* The tops a walk can stop by: the highest of sign * height (sign 1, or
 * -1 for negative openness) over the grid, and over each block. */
typedef struct ss_box_sky_tops ss_box_sky_tops;

/* The tops of the grid's heights times sign; NULL when out of memory. */
ss_box_sky_tops *ss_box_sky_tops_new(const ss_grid *grid, float sign);
void ss_box_sky_tops_free(ss_box_sky_tops *tops);

/* Adds, for each cell of rows [row0, row0 + n_rows) with a height, its
 * terms (ss_sky_walk_term's definition: SS_SVF_* or SS_TERM_ELEVATION)
 * toward the n_dirs grid azimuths grid_azimuth_deg (clockwise from the
 * grid's north), in their order, into sums (width * n_rows, from row0).
 * The heights are the whole grid's, multiplied by sign (1, or -1 for
 * negative openness) and lowered by curv_k t^2 at distance t (curv_k = 1 /
 * (2 R_eff), 0 for none); tops are theirs (ss_box_sky_tops_new). grad: the
 * rows' surface gradients (2 floats a cell from row0, ss_gradient_grid's)
 * for SS_SVF_TILTED, else NULL. Cells not yet begun are left once *cancel
 * (NULL: never) is set, for the caller to report. Returns 0 when out of
 * memory for the directions' lists. */
int ss_box_sky_add(const ss_grid *grid, int n_dirs, const double *grid_azimuth_deg,
                   int definition, float sign, const ss_box_sky_tops *tops, double curv_k,
                   int row0, int n_rows, const float *grad, const volatile sig_atomic_t *cancel,
                   float *sums);

/* Each cell's box horizon toward grid azimuth grid_azimuth_deg (clockwise
 * from the grid's north) for rows [row0, row0 + n_rows) of the whole grid's
 * heights lowered by curv_k t^2 (tops: ss_box_sky_tops_new's, sign 1),
 * into width * n_rows floats from row0 each: angle, degrees above the
 * horizontal (never below 0: the cell's own top reaches its edge; NaN
 * without a height); where not NULL, dist, the metres from the cell's
 * centre to where the ray enters the nearest square whose top sets it
 * (the cell's own edge for its own top), and cast, that top's height.
 * Cells not yet begun are left once *cancel (NULL: never) is set. Returns
 * 0 when out of memory for the direction's list. */
int ss_box_horizon_rows(const ss_grid *grid, double grid_azimuth_deg,
                        const ss_box_sky_tops *tops, double curv_k, int row0, int n_rows,
                        const volatile sig_atomic_t *cancel, float *angle, float *dist,
                        float *cast);

#endif
