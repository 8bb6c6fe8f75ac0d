/* What the products share: curvature, line sets, finishing a sum, shares
 * of a run, and the sink of the whole-grid calls. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "box_shadow.h"
#include "lines.h"
#include "products_internal.h"
#include "ss_terms.h"

/* The public enum and the kernels' constants must agree. */
_Static_assert((int)SS_LINES_INTERPOLATED == SS_LINE_MODEL_INTERPOLATED, "line model values");
_Static_assert((int)SS_LINES_DIGITAL == SS_LINE_MODEL_DIGITAL, "line model values");
_Static_assert((int)SS_LINES_BOX == SS_LINE_MODEL_BOX, "line model values");

float ss_curvature_k(const ss_sweep_options *opt)
{
    if (opt->earth_radius_m <= 0.0)
        return 0.0f;
    double r_eff = opt->earth_radius_m / (1.0 - opt->refraction_k);
    return (float)(0.5 / r_eff);
}

int ss_box_shadows_marched(const ss_sweep_options *opt)
{
    return opt->lines == SS_LINES_BOX && opt->box_shadows == SS_BOX_SHADOWS_MARCH;
}

ss_status ss_box_shadow_march(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                              double azimuth_deg, double el_lo_deg, double el_hi_deg,
                              ss_status (*direction)(void *, int, const ss_band_view *,
                                                     const ss_dir_rows *, float *),
                              void *user)
{
    float *owned;
    const float *z;
    ss_status st = ss_source_heights(ctx, src, &owned, &z);
    if (st != SS_OK)
        return st;
    /* The march only reads the heights. */
    ss_grid grid = {src->width, src->height, src->cell_x_m, src->cell_y_m, 0.0, (float *)z};
    int rows = ss_source_band_rows(src);
    float *angle = ss_malloc((size_t)src->width * rows * sizeof(float));
    if (!angle)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the box shadows");
    /* A band's rows at a time, each handed on as the engine's bands are,
     * with every row held (the heights are whole). */
    for (int row0 = 0; row0 < src->height && st == SS_OK; row0 += rows) {
        int n_rows = src->height - row0 < rows ? src->height - row0 : rows;
        ss_box_ray_counts counts;
        st = ss_box_shadow_horizons(&grid, azimuth_deg - opt->grid_north_deg, el_lo_deg,
                                    el_hi_deg, ss_curvature_k(opt), row0, n_rows,
                                    &ctx->cancel_requested, angle, &counts)
                 ? ss_check_cancel(ctx, "the box shadows")
                 : ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the box shadows");
        if (st != SS_OK)
            break;
        ctx->counters.box_march_cells += counts.cells;
        ctx->counters.box_march_marched += counts.marched;
        ss_band_view band = {.row0 = row0,
                             .n_rows = n_rows,
                             .lo = 0,
                             .held_rows = src->height,
                             .width = src->width,
                             .height = src->height,
                             .z = z,
                             .own_z = z + (size_t)row0 * src->width};
        ss_dir_rows dir_rows = {angle, NULL, NULL, 0};
        st = direction(user, 0, &band, &dir_rows, NULL);
        if (st == SS_OK)
            st = ss_progress(ctx, (double)(row0 + n_rows) / src->height, "the box shadows");
    }
    if (st == SS_OK)
        ctx->counters.box_march_steps++;
    free(angle);
    free(owned);
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
    if (opt->lines == SS_LINES_BOX)
        ls->families = opt->box_lines;
    return grid_az_deg * (M_PI / 180.0);
}

double ss_product_lines(const ss_grid *grid, const ss_sweep_options *opt, int i,
                        ss_line_set *ls)
{
    return ss_product_lines_at(grid, opt, ss_direction_azimuth(opt, i), ls);
}

ss_status ss_share_check(ss_ctx *ctx, const ss_share *share)
{
    if (share && (share->stride < 0 || share->first < 0 ||
                  (share->stride > 1 && share->first >= share->stride) ||
                  (share->stride <= 1 && share->first != 0)))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a share of a run needs 0 <= first < stride (first %d, stride %d)",
                       share->first, share->stride);
    return SS_OK;
}

ss_status ss_rows_begin(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                        const ss_share *share)
{
    ss_status st = ss_share_check(ctx, share);
    if (st == SS_OK)
        st = ss_source_check(ctx, src);
    if (st == SS_OK)
        st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK && src->stats)
        *src->stats = (ss_band_stats){0};
    return st;
}

int ss_share_has(const ss_share *share, int k)
{
    return !share || share->stride <= 1 || k % share->stride == share->first;
}

ss_status ss_share_reduce(const ss_share *share, float *sums, size_t n)
{
    return share && share->reduce ? share->reduce(share->user, sums, n) : SS_OK;
}

ss_status ss_grid_sink_rows(void *sink, int output, int index, int row0, int n_rows,
                            const float *values)
{
    ss_grid_sink *g = sink;
    float *grid = g->grid_of(g->user, output, index);
    float *dest = grid ? grid + (size_t)row0 * (size_t)g->width : NULL;
    if (dest && dest != values)
        memcpy(dest, values, sizeof(float) * (size_t)n_rows * (size_t)g->width);
    return SS_OK;
}

ss_grid ss_band_grid(const ss_band_view *band, const ss_source *src)
{
    ss_grid g = {band->width,           band->held_rows, src->cell_x_m, src->cell_y_m,
                 ss_source_origin(src), (float *)band->z};
    return g;
}
