/* Processes sharing one run: `mpirun -np N skysweep svf ...` starts N
 * copies; each reads the DEM and sweeps every N-th direction (rank r takes
 * r, r + N, ...; insolation deals out its time steps so), their per-cell
 * sums meet at rank 0 (one reduction of a float grid per output: what
 * crosses the network per run), and rank 0 alone writes the output and
 * speaks. Without MPI, or started without a launcher, a
 * run is one process and these calls cost nothing. */
#ifndef SS_CLI_MPI_SHARE_H
#define SS_CLI_MPI_SHARE_H

#include <stddef.h>

#include "run.h"

/* Joins the MPI job when an MPI launcher started this process. */
void share_start(int *argc, char ***argv);
void share_stop(void);
int share_rank(void);
int share_size(void);

/* Collective: -1 when no process failed, else the lowest failed rank. */
int share_first_failure(int failed);

/* Collective: adds every process's values into rank 0's (others' values
 * are left as they were). Returns 0 if MPI failed. */
int share_sum_at_root(float *values, size_t n);

/* The sky product (SVF definitions, openness) of every cell into out on
 * rank 0 (other ranks' out is scratch), directions shared between the
 * processes. Collective; on failure every rank returns an error and rank
 * 0's context says which process failed. */
ss_status share_sky_product(run_state *run, const ss_grid *grid, const ss_sweep_options *opt,
                            ss_sky_term term, double radius_m, float *out);

#endif
