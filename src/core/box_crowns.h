/* Box-model crowns crossed by each cell's own ray (doc/vegetation.md,
 * "Crowns by each cell's own ray").
 *
 * On a city DSM every crown is a column over its cell's square, from its
 * trunk to its top (ss_canopy). The ray from a cell's centre toward a sun
 * at elevation e crosses the square of cell j from distance t_in to t_out
 * (metres, horizontal), at heights z0 + t tan(e); it passes inside j's
 * crown iff that span meets the open interval (z_j + trunk_j, z_j +
 * top_j). The crowns' box lines (vegetation.c) answer that for the nearest
 * of their lines; here each cell's own ray is followed, with the bound of
 * box_shadow.c over the crowns' tops:
 *
 *   - One line per cell across walks the grid from the sun's side,
 *     keeping the running maximum of the three cells' highest crown top
 *     around the line, lifted by tan(e) times the distance to the column's
 *     near edge. A cell whose ray that bound lets pass above every crown
 *     upstream crosses none; the rest are marched square by square until
 *     a crown is met, the ray leaves the grid, or the bound shows nothing
 *     farther can be met.
 *
 * The earth is flat here, as in ss_canopy_crossed. */
#ifndef SS_BOX_CROWNS_H
#define SS_BOX_CROWNS_H

#include <signal.h>

#include "box_ray.h"

/* For the cells c of rows [row0, row0 + n_rows) (a band's; the whole
 * grid's heights and crowns are read): crossed[c] = 1 where the box-model
 * ray from cell c's centre toward the sun at grid azimuth
 * grid_azimuth_deg and elevation elevation_deg (0 < elevation < 90)
 * passes strictly inside a crown of a cell ahead (its own not counted),
 * else 0; 0 at nodata. crossed is indexed over the whole grid, its other
 * rows untouched; any rows give the whole grid's answer on them. Cells
 * whose solid horizon (solid_angle, over those rows alone from row0;
 * NULL: none given) is at least solid_el_hi are left 0 unasked: the solid
 * columns shade them from every sun up to that, so no crown can change
 * their light. Lines not yet walked are left once *cancel (NULL: never)
 * is set, for the caller to report. Returns 0 when out of memory for the
 * lines' work space. */
int ss_box_crowns_crossed(const ss_grid *grid, const ss_canopy *canopy,
                          double grid_azimuth_deg, double elevation_deg, int row0, int n_rows,
                          const float *solid_angle, double solid_el_hi,
                          const volatile sig_atomic_t *cancel, unsigned char *crossed,
                          ss_box_ray_counts *counts);

#endif
