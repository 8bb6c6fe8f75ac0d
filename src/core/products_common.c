/* What every sweep product does before its first direction. */
#include "config.h"

#include <math.h>

#include "lines.h"
#include "products_internal.h"
#include "ss_terms.h"

/* The public enum and the kernels' constants must agree. */
_Static_assert((int)SS_LINES_INTERPOLATED == SS_LINE_MODEL_INTERPOLATED, "line model values");
_Static_assert((int)SS_LINES_DIGITAL == SS_LINE_MODEL_DIGITAL, "line model values");

float ss_curvature_k(const ss_sweep_options *opt)
{
    if (opt->earth_radius_m <= 0.0)
        return 0.0f;
    double r_eff = opt->earth_radius_m / (1.0 - opt->refraction_k);
    return (float)(0.5 / r_eff);
}

ss_status ss_product_begin(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                           int n_outputs, ss_session **session)
{
    ss_status st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK)
        st = ss_grid_check(ctx, grid, NULL);
    if (st == SS_OK)
        st = ss_session_open(ctx, grid, n_outputs, session);
    return st;
}

float ss_product_finish(int term, float sum, int directions)
{
    float mean = sum / (float)directions;
    if (term == SS_TERM_ELEVATION)
        return 90.0f - mean;
    float v = term == SS_SVF_GEOMETRIC ? 1.0f - mean : mean;
    return v < 0.0f ? 0.0f : (v > 1.0f ? 1.0f : v);
}

double ss_product_lines_at(const ss_grid *grid, const ss_sweep_options *opt,
                           double azimuth_deg, ss_line_set *ls)
{
    double grid_az_deg = azimuth_deg - opt->grid_north_deg;
    ss_line_set_for_azimuth(ls, grid->width, grid->height, grid->cell_x_m, grid->cell_y_m,
                            grid_az_deg, (int)opt->lines);
    return grid_az_deg * (M_PI / 180.0);
}

double ss_product_lines(const ss_grid *grid, const ss_sweep_options *opt, int i,
                        ss_line_set *ls)
{
    return ss_product_lines_at(grid, opt, ss_direction_azimuth(opt, i), ls);
}
