/* Sky products of a job. A banded job (job_open_bands) reads the DEM band
 * by band from its files, its finished rows go straight into the output,
 * and under mpirun each band's sums meet at rank 0 before it finishes them. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "sky_job.h"
#include "mpi_share.h"

typedef struct {
    sweep_job *job;
    ss_sky_term term;
    ss_raster_writer *w; /* rank 0's */
    float *rows;         /* a band of sums, to add across processes */
    share_bands agreed;  /* before each band's sums are added */
    run_tally tally;     /* of the finished rows */
} band_state;

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    band_state *b = user;
    return job_read_rows(b->job, row0, n_rows, z);
}

static ss_status write_rows(void *user, int row0, int n_rows, const float *values)
{
    band_state *b = user;
    size_t n = (size_t)n_rows * (size_t)b->job->dem.grid.width;
    if (share_size() > 1) {
        /* Sums (NaN at nodata) from every process; rank 0 finishes them. */
        ss_status agreed = share_band_agree(&b->job->run, &b->agreed);
        if (agreed != SS_OK)
            return agreed;
        memcpy(b->rows, values, n * sizeof(float));
        if (!share_sum_at_root(b->rows, n))
            return ss_ctx_error(b->job->run.ctx, SS_ERR_INTERNAL,
                                "MPI could not add the processes' sums");
        if (share_rank() > 0)
            return SS_OK;
        for (size_t c = 0; c < n; ++c)
            b->rows[c] = isnan(b->rows[c])
                             ? SS_NODATA
                             : ss_sky_value(b->term, b->rows[c], b->job->opt.directions);
        values = b->rows;
    }
    run_tally_add(&b->tally, values, n);
    return ss_writer_rows(b->w, 1, row0, n_rows, values);
}

static ss_status sky_banded(sweep_job *job, ss_sky_term term, ss_raster_writer *w,
                            ss_band_stats *stats, double *min, double *mean, double *max)
{
    int bands = (job->dem.grid.height + job->band_rows - 1) / job->band_rows;
    band_state b = {job, term, w, NULL, {bands, 0}, {0, 0, 0, 0}};
    int shared = share_size() > 1;
    if (shared)
        b.rows = malloc(sizeof(float) * (size_t)job->band_rows * (size_t)job->dem.grid.width);
    if (shared && !b.rows)
        return share_bands_finish(
            &job->run, &b.agreed,
            ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for a band"));
    const ss_grid *g = &job->dem.grid;
    ss_band_io io = {g->width, g->height, g->cell_x_m, g->cell_y_m, job->band_rows,
                     read_rows, write_rows, &b, share_rank(), share_size(), shared, stats};
    ss_status st = ss_sky_banded(job->run.ctx, &io, &job->opt, term);
    st = share_bands_finish(&job->run, &b.agreed, st);
    free(b.rows);
    run_tally_result(&b.tally, NAN, min, mean, max);
    return st;
}

ss_status job_sky_product(sweep_job *job, ss_sky_term term, double radius_m,
                          ss_raster_writer *w, ss_band_stats *stats, double *min, double *mean,
                          double *max)
{
    if (job->source) {
        if (radius_m > 0)
            return ss_ctx_error(job->run.ctx, SS_ERR_MEMORY,
                                "the DEM is swept in bands (it does not fit in --memory), "
                                "and a radius-limited product needs the whole grid");
        return sky_banded(job, term, w, stats, min, mean, max);
    }
    const ss_grid *g = &job->dem.grid;
    size_t n = (size_t)g->width * (size_t)g->height;
    float *out = malloc(n * sizeof *out);
    if (!out)
        return ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for the product");
    ss_status st = share_sky_product(&job->run, g, &job->opt, term, radius_m, out);
    if (st == SS_OK && w) {
        run_stats(out, n, min, mean, max);
        st = ss_writer_rows(w, 1, 0, g->height, out);
    }
    free(out);
    return st;
}
