/* Sky products (SVF, openness) of a job: the whole grid in memory, or
 * the DEM read in bands (job_open_banded), alone or shared between MPI
 * processes (mpi_share.h). */
#ifndef SS_CLI_SKY_JOB_H
#define SS_CLI_SKY_JOB_H

#include "run.h"

/* Computes the product into band 1 of w (rank 0's writer; NULL on other
 * MPI ranks). stats (may be NULL) gets the hulls handed on between bands;
 * min, mean and max the product's (rank 0). */
ss_status job_sky_product(sweep_job *job, ss_sky_term term, double radius_m,
                          ss_raster_writer *w, ss_band_stats *stats, double *min, double *mean,
                          double *max);

#endif
