/* The sky's summed walk (ss_sky_walk): each cell's term of every direction
 * added into one grid of sums, finished into SVF or openness as each band
 * is done. Sky-view factor and openness run it (svf.c), and so do the
 * products that need the sky's view on the way: hillshade's sky layers and
 * insolation's diffuse light. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "products_internal.h"
#include "ss_terms.h"

/* The kernels' term for a sky product. */
static int kernel_term(ss_sky_term term)
{
    return term <= SS_SKY_SVF_RADIATIVE ? (int)term : SS_TERM_ELEVATION;
}

float ss_sky_value(ss_sky_term term, float sum, int directions)
{
    return ss_product_finish(kernel_term(term), sum, directions);
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
