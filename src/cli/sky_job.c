/* Sky products of a job: the DEM held whole or read band by band, the
 * finished rows straight into the output; under mpirun each band's sums
 * meet at rank 0 before it finishes them. */
#include "config.h"

#include <math.h>

#include "mpi_share.h"
#include "sky_job.h"

typedef struct {
    ss_raster_writer *w; /* rank 0's */
    int width;
    run_tally tally;     /* of the finished rows */
} sky_rows;

static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)output, (void)index;
    sky_rows *k = user;
    if (!k->w) /* another process's rows: rank 0 writes */
        return SS_OK;
    run_tally_add(&k->tally, values, (size_t)n_rows * (size_t)k->width);
    return ss_writer_rows(k->w, 1, row0, n_rows, values);
}

ss_status job_sky_product(sweep_job *job, ss_sky_term term, double radius_m,
                          ss_raster_writer *w, ss_band_stats *stats, double *min, double *mean,
                          double *max)
{
    sky_rows k = {w, job->dem.grid.width, {0, 0, 0, 0}};
    ss_source src = job_source(job, stats);
    share_reducer reducer;
    ss_share share = share_of(&reducer, &job->run, job_bands(job));
    ss_status st =
        ss_sky_rows(job->run.ctx, &src, &job->opt, term, radius_m, &share, write_rows, &k);
    st = share_end(&reducer, st);
    run_tally_result(&k.tally, NAN, min, mean, max);
    return st;
}
