/* Host side of the line models (kernels/ss_lines.h). */
#ifndef SS_LINES_HOST_H
#define SS_LINES_HOST_H

#include <stddef.h>

#include "ss_lines.h"

/* The family of parallel lines that sweeps a width x height grid for a
 * direction looking toward azimuth_deg (clockwise from the grid's north),
 * with model SS_LINE_MODEL_*. Box lines get one family (one line per cell
 * across): the caller sets `families`. */
void ss_line_set_for_azimuth(ss_line_set *ls, int width, int height, double cell_x_m,
                             double cell_y_m, double azimuth_deg, int model);

/* Whether box lines take cells of this shape: at most twice as long as
 * wide, so that a cell's centre projects inside its own cell, behind the
 * boundary with the previous column (kernels/ss_box.h). */
int ss_box_lines_take_cells(double cell_x_m, double cell_y_m);

/* The cells of one digital line in the order the engine walks them (the
 * sign of ls->step), each with the distance walked to it along the
 * azimuth in metres, as the engine's walks measure it:
 *     ss_line_cursor c = ss_line_cursor_start(ls, line);
 *     while (ss_line_cursor_next(&c)) ... c.cell, c.walked_m ...
 * Positions of the line outside the grid are passed over. */
typedef struct {
    const ss_line_set *ls;
    ss_i64 b16;
    int k;
    size_t cell;
    double walked_m;
} ss_line_cursor;

ss_line_cursor ss_line_cursor_start(const ss_line_set *ls, int line);
int ss_line_cursor_next(ss_line_cursor *c);

#endif
