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

/* The kernels' term for a sky product. */
static int kernel_term(ss_sky_term term)
{
    return term <= SS_SKY_SVF_TILTED ? (int)term : SS_TERM_ELEVATION;
}

float ss_sky_value(ss_sky_term term, float sum, int directions)
{
    return ss_product_finish(kernel_term(term), sum, directions);
}

ss_status ss_sky_check(ss_ctx *ctx, ss_sky_term term, double radius_m)
{
    ss_call_begin(ctx);
    if ((int)term < (int)SS_SKY_SVF_GEOMETRIC || (int)term > (int)SS_SKY_OPENNESS_NEGATIVE)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown sky product %d", (int)term);
    if (!(radius_m >= 0) || !isfinite(radius_m))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "radius must be >= 0 m (0: unlimited), not %g",
                       radius_m);
    if (radius_m > 0 && term == SS_SKY_SVF_TILTED)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a radius-limited SVF is geometric or horizontal, not radiative (tilted)");
    return SS_OK;
}

typedef struct {
    ss_sky_term term;
    int directions;
    const ss_share *share;
    ss_rows_sink sink;
    void *user;
} sky_run;

/* A band's sums, added over the processes that share the run, become the
 * product. */
static ss_status sky_finish(void *user, const ss_band_view *band, float *sums)
{
    sky_run *k = user;
    size_t n = (size_t)band->n_rows * (size_t)band->width;
    ss_status st = ss_share_reduce(k->share, sums, n);
    if (st != SS_OK)
        return st;
    for (size_t c = 0; c < n; ++c)
        sums[c] = isfinite(band->own_z[c]) ? ss_sky_value(k->term, sums[c], k->directions)
                                            : SS_NODATA;
    return k->sink(k->user, SS_OUT_SKY, 0, band->row0, band->n_rows, sums);
}

ss_status ss_sky_walk(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                      ss_sky_term term, double radius_m, const ss_share *share,
                      ss_rows_sink sink, void *user)
{
    ss_engine_dir *dirs = ss_malloc(sizeof *dirs * (size_t)opt->directions);
    if (!dirs)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory for %d directions", opt->directions);
    int n = 0;
    for (int i = 0; i < opt->directions; ++i)
        if (ss_share_has(share, i))
            dirs[n++] = (ss_engine_dir){ss_direction_azimuth(opt, i), 1, i, -1};
    sky_run k = {term, opt->directions, share, sink, user};
    ss_consumer consumer = {.planes = 1, .finish = sky_finish};
    ss_engine_job job = {
        .walk = {.term = kernel_term(term),
                 .radius_m = radius_m,
                 .negate = term == SS_SKY_OPENNESS_NEGATIVE},
        .dirs = dirs,
        .n_dirs = n,
        .consumer = &consumer,
        .user = &k,
        .what = term >= SS_SKY_OPENNESS_POSITIVE ? "openness" : "sky-view factor"};
    ss_status st = ss_engine_run(ctx, src, opt, &job);
    free(dirs);
    return st;
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
        definition != SS_SVF_DEF_TILTED)
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
