/* A horizon walk (an SS_TERM_HORIZON job of engine.h): on box lines with
 * --box-sky march each cell's own ray (box_sky.h), the box model exactly,
 * on the host whatever the device; else the engine's sweeps. The horizon
 * rasters and insolation's horizon terms and stored horizons take it. */
#include "config.h"

#include <stdlib.h>
#include <string.h>

#include "box_rays_run.h"

/* The job's directions by each cell's own ray, band by band (the source's
 * band rows) from the heights held whole, handed to the consumer as the
 * engine hands a walk's: a visit, each direction's rows in turn, the
 * finish of the band's planes. */
static ss_status horizon_march(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                               const ss_engine_job *job)
{
    ss_box_rays_run run;
    ss_status st = ss_box_rays_begin(ctx, src, 1.0f, &run);
    if (st != SS_OK)
        return st;
    const ss_consumer *consumer = job->consumer;
    int w = src->width, h = src->height;
    size_t n = (size_t)w * run.band_rows;
    int want_cast = (job->walk.want & SS_HORIZON_WANT_CAST) != 0;
    int want_dist = want_cast || (job->walk.want & SS_HORIZON_WANT_DIST);
    float *angle = ss_malloc(n * sizeof(float));
    float *dist = want_dist ? ss_malloc(n * sizeof(float)) : NULL;
    float *cast = want_cast ? ss_malloc(n * sizeof(float)) : NULL;
    float *planes = consumer->planes ? ss_malloc(consumer->planes * n * sizeof(float)) : NULL;
    if (!angle || (want_dist && !dist) || (want_cast && !cast) || (consumer->planes && !planes))
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of horizons");
    double curv_k = ss_curvature_k(opt);
    uint64_t walked = 0, walked_dirs = 0;
    for (int row0 = 0; row0 < h && st == SS_OK; row0 += run.band_rows) {
        ss_band_view band = ss_box_rays_band(&run, row0);
        int n_rows = band.n_rows;
        if (planes)
            memset(planes, 0, consumer->planes * (size_t)n_rows * w * sizeof(float));
        if (consumer->visit)
            st = consumer->visit(job->user, &band);
        for (int d = 0; d < job->n_dirs && st == SS_OK; ++d) {
            const ss_engine_dir *dir = &job->dirs[d];
            ss_dir_rows walk_rows = {angle, dist, cast, 0};
            if (dir->walk) {
                double t0 = ss_seconds_now();
                st = ss_box_horizon_rows(&run.grid, dir->azimuth_deg - opt->grid_north_deg,
                                         run.tops, curv_k, row0, n_rows,
                                         &ctx->cancel_requested, angle, dist, cast)
                         ? ss_check_cancel(ctx, job->what)
                         : ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the horizons' rays");
                ctx->counters.sweep_seconds += ss_seconds_now() - t0;
                walked += (uint64_t)n_rows * w;
                walked_dirs += row0 == 0;
            }
            if (st == SS_OK && consumer->direction)
                st = consumer->direction(job->user, dir->index, &band,
                                         dir->walk ? &walk_rows : NULL, planes);
            if (st == SS_OK)
                st = ss_progress(ctx, (row0 + n_rows * (double)(d + 1) / job->n_dirs) / h,
                                 job->what);
        }
        if (st == SS_OK && consumer->finish)
            st = consumer->finish(job->user, &band, planes);
    }
    ctx->counters.box_sky_directions += walked_dirs;
    ctx->counters.cells_swept += walked;
    free(angle);
    free(dist);
    free(cast);
    free(planes);
    ss_box_rays_end(&run);
    return st;
}

ss_status ss_horizon_walk(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                          const ss_engine_job *job)
{
    /* A radius or negated heights (no horizon walk asks for them) go to the
     * engine, which says what it does with them. */
    int marched = ss_box_sky_marched(opt, job->walk.radius_m) && !job->walk.negate;
    return marched ? horizon_march(ctx, src, opt, job) : ss_engine_run(ctx, src, opt, job);
}
