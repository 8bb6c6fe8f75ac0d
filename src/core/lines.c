/* Chooses, for one azimuth, the major axis, walk order and fixed-point slope
 * of the lines, and how far each index step walks along the azimuth. */
#include "config.h"

#include <math.h>

#include "lines.h"

/* The kernels take the line set by value: no padding may differ. */
_Static_assert(sizeof(ss_line_set) == 80, "ss_line_set layout");

void ss_line_set_for_azimuth(ss_line_set *ls, int width, int height, double cell_x_m,
                             double cell_y_m, double azimuth_deg, int model)
{
    double az = azimuth_deg * (M_PI / 180.0);
    /* Lines are walked away from the azimuth: toward -sin(az) east and
     * +cos(az) south (rows grow southward). Index speeds per metre walked: */
    double walk_east = -sin(az), walk_south = cos(az);
    double col_speed = walk_east / cell_x_m, row_speed = walk_south / cell_y_m;
    /* Distance walked per +1 column and per +1 row (projection on the walk). */
    double along_per_col = walk_east * cell_x_m, along_per_row = walk_south * cell_y_m;

    ls->width = width;
    ls->model = model;
    ls->base_major = ls->base_minor = 0;
    ls->families = 1;
    int interpolated = model == SS_LINE_MODEL_INTERPOLATED;
    ls->weight_per_frac = interpolated ? 1.0f / 65536.0f : 0.0f;
    ls->round_fx = interpolated ? 0 : ((ss_i64)1 << 31);
    double slope, along_major, along_minor;
    if (fabs(col_speed) >= fabs(row_speed)) {
        ls->major_is_row = 0;
        ls->stride_major = 1;
        ls->stride_minor = width;
        ls->major_len = width;
        ls->minor_len = height;
        ls->step = col_speed >= 0 ? 1 : -1;
        slope = row_speed / col_speed;
        along_major = along_per_col;
        along_minor = along_per_row;
    } else {
        ls->major_is_row = 1;
        ls->stride_major = width;
        ls->stride_minor = 1;
        ls->major_len = height;
        ls->minor_len = width;
        ls->step = row_speed >= 0 ? 1 : -1;
        slope = col_speed / row_speed;
        along_major = along_per_row;
        along_minor = along_per_col;
    }
    /* |slope| <= 1 by the choice of major axis. The slope is rounded to 16
     * fractional bits (a direction error below 8e-6 rad) so that samples,
     * placed with 16-bit fractions, lie exactly on the line they assume. */
    double fx = nearbyint(slope * 65536.0) * 65536.0;
    if (fx > 4294967296.0)
        fx = 4294967296.0;
    if (fx < -4294967296.0)
        fx = -4294967296.0;
    ls->slope_fx = (ss_i64)fx;
    if (model == SS_LINE_MODEL_DIGITAL) {
        /* Cell centres sit beside the exact line: both index steps count. */
        ls->along_per_step_m = (float)(ls->step * along_major);
        ls->along_per_minor_m = (float)along_minor;
    } else {
        /* Samples (box lines: column boundaries) lie on the exact line, with
         * the fixed-point slope; a box line's cell centres sit beside it. */
        double m = fx / 4294967296.0;
        ls->along_per_step_m = (float)(ls->step * (along_major + m * along_minor));
        ls->along_per_minor_m = model == SS_LINE_MODEL_BOX ? (float)along_minor : 0.0f;
    }

    /* Intercepts b that reach the grid: the position b + major * slope
     * moves by f_end over the major axis. Lines that turn out empty at the
     * ends cost one extent search each. */
    ls->line_min = 0;
    ls->n_lines = 1; /* line 0 is intercept 0 */
    int f_end = ss_line_minor(ls, 0, ls->major_len - 1);
    int f_max = f_end > 0 ? f_end : 0, f_min = f_end < 0 ? f_end : 0;
    /* Interpolated samples reach one cell further; box families sit up to
     * a cell above the digital lines. */
    int spare = model == SS_LINE_MODEL_DIGITAL ? 0 : 1;
    ls->line_min = -f_max - spare;
    ls->n_lines = (ls->minor_len - 1 - f_min + spare) - ls->line_min + 1;
}

ss_line_cursor ss_line_cursor_start(const ss_line_set *ls, int line)
{
    return (ss_line_cursor){ls, ss_line_intercept16(ls, line), 0, 0, 0.0};
}

int ss_line_cursor_next(ss_line_cursor *c)
{
    const ss_line_set *ls = c->ls;
    while (c->k < ls->major_len) {
        int k = c->k++;
        int major = ls->step > 0 ? k : ls->major_len - 1 - k;
        int minor = ss_line_minor(ls, c->b16, major);
        if (minor < 0 || minor >= ls->minor_len)
            continue;
        c->cell = (size_t)major * (size_t)ls->stride_major + (size_t)minor * (size_t)ls->stride_minor;
        c->walked_m = major * ((double)ls->along_per_step_m * ls->step) +
                      minor * (double)ls->along_per_minor_m;
        return 1;
    }
    return 0;
}

int ss_box_lines_take_cells(double cell_x_m, double cell_y_m)
{
    return cell_x_m <= 2.0 * cell_y_m && cell_y_m <= 2.0 * cell_x_m;
}
