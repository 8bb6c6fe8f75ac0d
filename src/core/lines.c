/* Chooses, for one azimuth, the major axis, walk order and fixed-point slope
 * of the digital lines, and how far each index step walks along the azimuth. */
#include "config.h"

#include <math.h>

#include "lines.h"

void ss_line_set_for_azimuth(ss_line_set *ls, int width, int height, double cell_x_m,
                             double cell_y_m, double azimuth_deg)
{
    double az = azimuth_deg * (M_PI / 180.0);
    /* Lines are walked away from the azimuth: toward -sin(az) east and
     * +cos(az) south (rows grow southward). Index speeds per metre walked: */
    double walk_east = -sin(az), walk_south = cos(az);
    double col_speed = walk_east / cell_x_m, row_speed = walk_south / cell_y_m;
    /* Distance walked per +1 column and per +1 row (projection on the walk). */
    double along_per_col = walk_east * cell_x_m, along_per_row = walk_south * cell_y_m;

    ls->width = width;
    ls->reserved = 0;
    double slope, along_major, along_minor;
    if (fabs(col_speed) >= fabs(row_speed)) {
        ls->major_is_row = 0;
        ls->major_len = width;
        ls->minor_len = height;
        ls->step = col_speed >= 0 ? 1 : -1;
        slope = row_speed / col_speed;
        along_major = along_per_col;
        along_minor = along_per_row;
    } else {
        ls->major_is_row = 1;
        ls->major_len = height;
        ls->minor_len = width;
        ls->step = row_speed >= 0 ? 1 : -1;
        slope = col_speed / row_speed;
        along_major = along_per_row;
        along_minor = along_per_col;
    }
    /* |slope| <= 1 by the choice of major axis; clamp the rounding edge. */
    double fx = nearbyint(slope * 4294967296.0);
    if (fx > 4294967296.0)
        fx = 4294967296.0;
    if (fx < -4294967296.0)
        fx = -4294967296.0;
    ls->slope_fx = (ss_i64)fx;
    ls->along_per_step_m = (float)(ls->step * along_major);
    ls->along_per_minor_m = (float)along_minor;

    /* Intercepts b = minor - f(major) over the grid; f(0) = 0 and f is
     * monotone, so its extremes are at the two ends of the major axis. */
    int f_end = ss_line_minor(ls, 0, ls->major_len - 1);
    int f_max = f_end > 0 ? f_end : 0, f_min = f_end < 0 ? f_end : 0;
    ls->line_min = -f_max;
    ls->n_lines = (ls->minor_len - 1 - f_min) - ls->line_min + 1;
}
