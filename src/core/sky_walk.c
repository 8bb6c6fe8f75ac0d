/* The sky's summed walk (ss_sky_walk): each cell's term of every direction
 * added into one grid of sums, finished into SVF or openness as each band
 * is done. Sky-view factor and openness run it (svf.c), and so do the
 * products that need the sky's view on the way: hillshade's sky layers and
 * insolation's diffuse light. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "box_rays_run.h"
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

int ss_box_sky_marched(const ss_sweep_options *opt, double radius_m)
{
    return opt->lines == SS_LINES_BOX && opt->box_sky == SS_BOX_SKY_MARCH && radius_m == 0.0;
}

/* Directions of the sky view's rays between progress reports. */
#define SKY_RAYS_AT_ONCE 8

/* The job's directions by each cell's own ray (box_sky.h), band by band
 * (the source's band rows) from the heights held whole, each band's sums
 * finished as the engine's are. */
static ss_status sky_march(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                           const ss_engine_job *job)
{
    float sign = job->walk.negate ? -1.0f : 1.0f;
    ss_box_rays_run run;
    ss_status st = ss_box_rays_begin(ctx, src, sign, &run);
    if (st != SS_OK)
        return st;
    int w = src->width, h = src->height, rows = run.band_rows;
    int tilted = job->walk.term == SS_SVF_TILTED;
    const float *z = run.grid.z;
    double curv_k = ss_curvature_k(opt);
    float *sums = ss_malloc((size_t)w * rows * sizeof(float));
    double *azimuths = ss_malloc(sizeof(double) * (size_t)(job->n_dirs > 0 ? job->n_dirs : 1));
    /* A band's gradients with a row either side, as the engine's held rows give them. */
    float *grad = tilted ? ss_malloc(2 * (size_t)w * ((size_t)rows + 2) * sizeof(float)) : NULL;
    if (!sums || !azimuths || (tilted && !grad))
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of the sky view");
    for (int d = 0; azimuths && d < job->n_dirs; ++d)
        azimuths[d] = job->dirs[d].azimuth_deg - opt->grid_north_deg;
    for (int row0 = 0; row0 < h && st == SS_OK; row0 += rows) {
        ss_band_view band = ss_box_rays_band(&run, row0);
        int n_rows = band.n_rows;
        memset(sums, 0, (size_t)w * n_rows * sizeof(float));
        const float *own_grad = NULL;
        if (tilted) {
            int lo = row0 > 0 ? row0 - 1 : 0, hi = row0 + n_rows < h ? row0 + n_rows + 1 : h;
            ss_grid held = {w, hi - lo, src->cell_x_m, src->cell_y_m, 0.0,
                            (float *)z + (size_t)lo * w};
            ss_gradient_grid(&held, grad);
            own_grad = grad + 2 * (size_t)(row0 - lo) * w;
        }
        /* A few directions at a time, for the progress reports: each cell
         * adds its terms in the directions' order all the same. */
        for (int d0 = 0; d0 < job->n_dirs && st == SS_OK; d0 += SKY_RAYS_AT_ONCE) {
            int n = job->n_dirs - d0 < SKY_RAYS_AT_ONCE ? job->n_dirs - d0 : SKY_RAYS_AT_ONCE;
            double t0 = ss_seconds_now();
            st = ss_box_sky_add(&run.grid, n, azimuths + d0, job->walk.term, sign, run.tops,
                                curv_k, row0, n_rows, own_grad, &ctx->cancel_requested, sums)
                     ? ss_check_cancel(ctx, job->what)
                     : ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the sky view's rays");
            ctx->counters.sweep_seconds += ss_seconds_now() - t0;
            if (st == SS_OK)
                st = ss_progress(ctx, (row0 + n_rows * (double)(d0 + n) / job->n_dirs) / h,
                                 job->what);
        }
        if (st == SS_OK)
            st = job->consumer->finish(job->user, &band, sums);
    }
    if (st == SS_OK) {
        ctx->counters.box_sky_directions += (uint64_t)job->n_dirs;
        ctx->counters.cells_swept += (uint64_t)job->n_dirs * (uint64_t)w * (uint64_t)h;
    }
    free(azimuths);
    free(grad);
    free(sums);
    ss_box_rays_end(&run);
    return st;
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
    ss_status st = ss_box_sky_marched(opt, radius_m) ? sky_march(ctx, src, opt, &job)
                                                     : ss_engine_run(ctx, src, opt, &job);
    free(dirs);
    return st;
}
