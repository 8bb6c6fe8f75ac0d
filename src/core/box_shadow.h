/* Box-model shadows by proven bounds and a march (doc/model.md, "Cast
 * shadows: each cell's own ray"; measured in doc/box_lines.md).
 *
 * A cell of a city DSM is a flat-topped column. Whether the sun at
 * elevation e in one azimuth lights a cell's centre is then exact: no
 * column top that the ray from the centre toward the sun crosses rises
 * above it, seen from the centre at the distance where the ray enters the
 * column. Box lines (ss_box.h) approximate that ray by the nearest of
 * their lines, with a cost per line family; here each cell gets the exact
 * answer instead, at about one digital walk's cost:
 *
 *   - One line per cell across walks the grid toward the sun's far side.
 *     A cell's ray runs beside its line by less than half a cell, so in
 *     every column it crosses it stays within the three cells around the
 *     line there. Keeping, along the line, the running maximum of the
 *     three cells' tallest top lifted by the sun's slope over the
 *     distance to the column's near edge bounds from above what any ray of
 *     the line can meet; the running maximum of their lowest top at the
 *     column's centre, curvature taken at the line's full length, bounds
 *     it from below. A cell the upper bound lets the sun clear is lit; one
 *     the lower bound shades is in shadow.
 *   - Every other cell is marched: its ray, column by column, until it
 *     meets a top the sun does not clear, leaves the grid, or passes the
 *     last column whose bound could still shade it.
 *
 * The result does not depend on the bounds, only its cost does: the
 * bounds decide only what the march would decide. */
#ifndef SS_BOX_SHADOW_H
#define SS_BOX_SHADOW_H

#include <signal.h>

#include "box_ray.h"

/* Each cell's horizon of rows [row0, row0 + n_rows) toward grid azimuth
 * grid_azimuth_deg (clockwise from the grid's north) as far as a sun
 * between el_lo_deg and el_hi_deg (apparent elevations) can tell it, in
 * angle (degrees, width * n_rows; the heights are the whole grid's, for a
 * ray reads columns anywhere toward the sun, and any rows give the whole
 * grid's answer on them, bit for bit):
 * for every sun elevation e in that range, e > angle[c] exactly where the
 * box model lights cell c. The box horizon is never below 0 degrees (a
 * column's own top reaches its edge); 90 marks cells no sun in the range
 * lights. curv_k: 1 / (2 R_eff), 0 for none. Nodata cells neither cast
 * nor receive (their angle is 0); the ray ends at the grid's edge.
 * Lines not yet walked are left once *cancel (NULL: never) is set, for the
 * caller to report. Returns 0 when out of memory for the lines' work
 * space. */
int ss_box_shadow_horizons(const ss_grid *grid, double grid_azimuth_deg, double el_lo_deg,
                           double el_hi_deg, double curv_k, int row0, int n_rows,
                           const volatile sig_atomic_t *cancel, float *angle,
                           ss_box_ray_counts *counts);

#endif
