/* Processes sharing one run: `mpirun -np N skysweep svf ...` starts N
 * copies; each reads the DEM and sweeps every N-th direction (rank r takes
 * r, r + N, ...; insolation deals out its time steps so), their per-cell
 * sums meet at rank 0 (one reduction of a float grid per output: what
 * crosses the network per run), and rank 0 alone writes the output and
 * speaks. Without MPI, or started without a launcher, a run is one process,
 * Open MPI is not even loaded (it is the module skysweep-mpi.so,
 * mpi_module.c), and these calls cost nothing. */
#ifndef SS_CLI_MPI_SHARE_H
#define SS_CLI_MPI_SHARE_H

#include <stddef.h>

#include "run.h"

/* Joins the MPI job when an MPI launcher started this process: 0, or
 * SS_ERR_DEVICE, the reason printed, where the module or MPI_Init fails or
 * the build has no MPI (each process would otherwise run the whole job
 * alone). */
int share_start(int *argc, char ***argv);
void share_stop(void);
int share_rank(void);
int share_size(void);

/* Collective: -1 when no process failed, else the lowest failed rank. */
int share_first_failure(int failed);

/* Collective: one band height for every process from each one's own
 * (ss_band_rows_within's: 0 whole grid, -1 not even one band fits, or
 * rows; -2 for a process that failed before deciding), so that all sweep
 * the same bands in the same order: -2 or -1 if any process says so, else
 * the smallest band any process needs, else 0. */
int share_band_rows(int rows);

/* A banded run under mpirun agrees, before each band's sums are added,
 * that no process has failed; a process that stops early (or finishes)
 * makes up the agreements it has left, so every process makes the same
 * number and none waits for ever. */
typedef struct {
    int bands; /* agreements a run makes: one per band */
    int made;
} share_bands;
/* Before a band's reduction: SS_OK, or an error naming the failed process. */
ss_status share_band_agree(run_state *run, share_bands *b);
/* At the end of the run, whatever st is: the agreements left, then one
 * more on the outcome; returns st, or an error if another process failed. */
ss_status share_bands_finish(run_state *run, share_bands *b, ss_status st);

/* Collective: adds every process's values into rank 0's (others' values
 * are left as they were). Returns 0 if MPI failed. */
int share_sum_at_root(float *values, size_t n);

/* A run shared between the processes through the library's hook
 * (ss_share): before each band's sums are added at rank 0, the processes
 * agree that none has failed. */
typedef struct {
    run_state *run;
    share_bands agreed;
} share_reducer;
/* This process's share of a run of `bands` bands (1: the whole grid):
 * every N-th direction or time step, sums added at rank 0. */
ss_share share_of(share_reducer *r, run_state *run, int bands);
/* Ends a shared run, whatever st is (share_bands_finish). */
ss_status share_end(share_reducer *r, ss_status st);

#endif
