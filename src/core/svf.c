/* Sky-view factor and openness: one sweep per direction adds each cell's
 * term into one accumulator grid (never all D horizon grids), then the
 * mean over directions becomes the product (doc/model.md, doc/relief.md).
 * The sums can be taken over a share of the directions (every stride-th
 * from first), so that processes sharing the work add their sums before
 * finishing (src/cli/mpi_share.c). With a radius, each direction's horizon
 * is the highest terrain within it (the radius scan), as RVT and SAGA
 * compute SVF and openness. Negative openness is positive openness of -z. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "products_internal.h"
#include "ss_terms.h"

/* The kernels' term for a sky product. */
static int kernel_term(ss_sky_term term)
{
    return term <= SS_SKY_SVF_TILTED ? (int)term : SS_TERM_ELEVATION;
}

float ss_sky_value(ss_sky_term term, float sum, int directions)
{
    return ss_product_finish(kernel_term(term), sum, directions);
}

ss_status ss_sky_check(ss_ctx *ctx, ss_sky_term term, double radius_m, int first, int stride,
                       int directions)
{
    if ((int)term < (int)SS_SKY_SVF_GEOMETRIC || (int)term > (int)SS_SKY_OPENNESS_NEGATIVE)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown sky product %d", (int)term);
    if (!(radius_m >= 0) || !isfinite(radius_m))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "radius must be >= 0 m (0: unlimited), not %g",
                       radius_m);
    if (radius_m > 0 && term == SS_SKY_SVF_TILTED)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a radius-limited SVF is geometric or horizontal, not radiative (tilted)");
    if (stride < 1 || first < 0 || first >= stride || directions < 1)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a share of directions needs 0 <= first < stride (got first %d, stride "
                       "%d; %d directions)",
                       first, stride, directions);
    return SS_OK;
}

ss_status ss_sky_sums(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                      ss_sky_term term, double radius_m, int first, int stride, float *sums)
{
    ss_status st = ss_sky_check(ctx, term, radius_m, first, stride, opt->directions);
    if (st != SS_OK)
        return st;
    size_t n = (size_t)grid->width * grid->height;
    ss_grid inverted = *grid;
    if (term == SS_SKY_OPENNESS_NEGATIVE) {
        inverted.z = ss_alloc_grid(n * sizeof(float));
        if (!inverted.z)
            return ss_fail(ctx, SS_ERR_MEMORY, "out of memory inverting the DEM");
        for (size_t c = 0; c < n; ++c)
            inverted.z[c] = -grid->z[c];
    }
    const ss_grid *g = term == SS_SKY_OPENNESS_NEGATIVE ? &inverted : grid;
    int k = kernel_term(term);
    ss_session *s;
    st = ss_product_begin(ctx, g, opt, 1, &s);
    if (st == SS_OK) {
        float curv_k = ss_curvature_k(opt);
        double t0 = ss_seconds_now();
        for (int i = first; i < opt->directions && st == SS_OK; i += stride) {
            ss_line_set ls;
            double az = ss_product_lines(g, opt, i, &ls);
            st = radius_m > 0 ? ss_session_radius_terms(s, &ls, k, (float)radius_m, curv_k)
                              : ss_session_svf(s, &ls, k, curv_k, az);
            if (st == SS_OK)
                st = ss_progress(ctx, (double)(i + 1) / opt->directions,
                                 term >= SS_SKY_OPENNESS_POSITIVE ? "openness"
                                                                  : "sky-view factor");
        }
        float *acc = NULL;
        if (st == SS_OK)
            st = ss_session_view(s, 0, &acc);
        ctx->counters.sweep_seconds += ss_seconds_now() - t0;
        if (st == SS_OK)
            memcpy(sums, acc, n * sizeof(float));
        ss_session_close(s);
    }
    if (term == SS_SKY_OPENNESS_NEGATIVE)
        free(inverted.z);
    return st;
}

/* The product of every cell from all directions' sums. */
static ss_status sky_product(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                             ss_sky_term term, double radius_m, float *out)
{
    ss_status st = ss_sky_sums(ctx, grid, opt, term, radius_m, 0, 1, out);
    size_t n = (size_t)grid->width * (size_t)grid->height;
    for (size_t c = 0; st == SS_OK && c < n; ++c)
        out[c] = isfinite(grid->z[c]) ? ss_sky_value(term, out[c], opt->directions) : SS_NODATA;
    return st;
}

ss_status ss_svf(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                 ss_svf_definition definition, float *out)
{
    return ss_svf_within(ctx, grid, opt, definition, 0.0, out);
}

ss_status ss_svf_within(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                        ss_svf_definition definition, double radius_m, float *out)
{
    if (definition != SS_SVF_DEF_GEOMETRIC && definition != SS_SVF_DEF_HORIZONTAL &&
        definition != SS_SVF_DEF_TILTED)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown SVF definition %d", (int)definition);
    return sky_product(ctx, grid, opt, (ss_sky_term)definition, radius_m, out);
}

ss_status ss_openness(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                      int negative, double radius_m, float *out)
{
    return sky_product(ctx, grid, opt,
                       negative ? SS_SKY_OPENNESS_NEGATIVE : SS_SKY_OPENNESS_POSITIVE, radius_m,
                       out);
}
