/* Sky-view factor and openness: a summed walk adds each cell's term of
 * every direction into one grid of sums (never all D horizon grids), then
 * the mean over directions becomes the product (doc/model.md,
 * doc/relief.md). The directions can be shared between processes, whose
 * sums meet before they are finished (ss_share). With a radius, each
 * direction's horizon is the highest terrain within it (the radius scan),
 * as RVT and SAGA compute SVF and openness. Negative openness is positive
 * openness of -z. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "products_internal.h"
#include "ss_terms.h"

ss_status ss_sky_check(ss_ctx *ctx, ss_sky_term term, double radius_m)
{
    ss_call_begin(ctx);
    if ((int)term < (int)SS_SKY_SVF_GEOMETRIC || (int)term > (int)SS_SKY_OPENNESS_NEGATIVE)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown sky product %d", (int)term);
    if (!(radius_m >= 0) || !isfinite(radius_m))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "radius must be >= 0 m (0: unlimited), not %g",
                       radius_m);
    if (radius_m > 0 && term == SS_SKY_SVF_RADIATIVE)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a radius-limited SVF is geometric or horizontal, not radiative (tilted)");
    return SS_OK;
}

ss_status ss_sky_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                      ss_sky_term term, double radius_m, const ss_share *share,
                      ss_rows_sink sink, void *user)
{
    ss_call_begin(ctx);
    ss_status st = ss_sky_check(ctx, term, radius_m);
    if (st == SS_OK)
        st = ss_rows_begin(ctx, src, opt, share);
    return st == SS_OK ? ss_sky_walk(ctx, src, opt, term, radius_m, share, sink, user) : st;
}

static float *the_grid(void *user, int output, int index)
{
    (void)output, (void)index;
    return user;
}

/* The product of every cell of a grid held whole. */
static ss_status sky_product(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                             ss_sky_term term, double radius_m, float *out)
{
    ss_status st = ss_sky_check(ctx, term, radius_m);
    if (st == SS_OK)
        st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK)
        st = ss_grid_check(ctx, grid, NULL);
    if (st != SS_OK)
        return st;
    ss_source src = ss_source_of_grid(grid);
    ss_grid_sink sink = {the_grid, out, grid->width};
    return ss_sky_walk(ctx, &src, opt, term, radius_m, NULL, ss_grid_sink_rows, &sink);
}

ss_status ss_svf(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                 ss_svf_definition definition, float *out)
{
    ss_call_begin(ctx);
    return ss_svf_within(ctx, grid, opt, definition, 0.0, out);
}

ss_status ss_svf_within(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                        ss_svf_definition definition, double radius_m, float *out)
{
    ss_call_begin(ctx);
    if (definition != SS_SVF_DEF_GEOMETRIC && definition != SS_SVF_DEF_HORIZONTAL &&
        definition != SS_SVF_DEF_RADIATIVE)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown SVF definition %d", (int)definition);
    return sky_product(ctx, grid, opt, (ss_sky_term)definition, radius_m, out);
}

ss_status ss_openness(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                      int negative, double radius_m, float *out)
{
    ss_call_begin(ctx);
    return sky_product(ctx, grid, opt,
                       negative ? SS_SKY_OPENNESS_NEGATIVE : SS_SKY_OPENNESS_POSITIVE, radius_m,
                       out);
}
