/* MPI for skysweep's CLI (mpi_share.h): only this file includes mpi.h. */
#include "config.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef HAVE_MPI
#include <mpi.h>
#endif

#include "mpi_share.h"

static int rank_now = 0, size_now = 1;

#ifdef HAVE_MPI
static int joined;

/* Open MPI's and PMIx/PMI launchers set these; a plain start sets none, and
 * then MPI is not initialised at all (no singleton start-up cost). */
static int launched_by_mpi(void)
{
    return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_RANK");
}
#endif

void share_start(int *argc, char ***argv)
{
#ifdef HAVE_MPI
    if (!launched_by_mpi() || MPI_Init(argc, argv) != MPI_SUCCESS)
        return;
    joined = 1;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_now);
    MPI_Comm_size(MPI_COMM_WORLD, &size_now);
    /* Rank 0 alone prints summaries and plans. */
    if (rank_now > 0 && !freopen("/dev/null", "w", stdout))
        fclose(stdout);
#else
    (void)argc, (void)argv;
#endif
}

void share_stop(void)
{
#ifdef HAVE_MPI
    if (joined)
        MPI_Finalize();
    joined = 0;
#endif
}

int share_rank(void)
{
    return rank_now;
}

int share_size(void)
{
    return size_now;
}

int share_first_failure(int failed)
{
    int first = failed ? rank_now : size_now;
#ifdef HAVE_MPI
    if (size_now > 1)
        MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
#endif
    return first < size_now ? first : -1;
}

static int all_min(int v)
{
#ifdef HAVE_MPI
    if (size_now > 1)
        MPI_Allreduce(MPI_IN_PLACE, &v, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
#endif
    return v;
}

int share_band_rows(int rows)
{
    if (size_now < 2)
        return rows;
    int worst = all_min(rows < 0 ? rows : 0);
    if (worst < 0)
        return worst;
    int smallest = all_min(rows > 0 ? rows : INT_MAX);
    return smallest == INT_MAX ? 0 : smallest;
}

ss_status share_band_agree(run_state *run, share_bands *b)
{
    b->made++;
    int failed = share_first_failure(0);
    return failed < 0 ? SS_OK
                      : ss_ctx_error(run->ctx, SS_ERR_INTERNAL, "process %d of %d failed", failed,
                                     size_now);
}

ss_status share_bands_finish(run_state *run, share_bands *b, ss_status st)
{
    if (size_now < 2)
        return st;
    for (; b->made < b->bands; b->made++)
        share_first_failure(st != SS_OK);
    int failed = share_first_failure(st != SS_OK);
    if (failed >= 0 && st == SS_OK)
        st = ss_ctx_error(run->ctx, SS_ERR_INTERNAL, "process %d of %d failed", failed, size_now);
    return st;
}

int share_sum_at_root(float *values, size_t n)
{
#ifdef HAVE_MPI
    const size_t piece = (size_t)1 << 28;
    for (size_t at = 0; size_now > 1 && at < n; at += piece) {
        int count = (int)(n - at < piece ? n - at : piece);
        int rc = rank_now == 0 ? MPI_Reduce(MPI_IN_PLACE, values + at, count, MPI_FLOAT, MPI_SUM,
                                            0, MPI_COMM_WORLD)
                               : MPI_Reduce(values + at, NULL, count, MPI_FLOAT, MPI_SUM, 0,
                                            MPI_COMM_WORLD);
        if (rc != MPI_SUCCESS)
            return 0;
    }
#else
    (void)values, (void)n;
#endif
    return 1;
}

static ss_status reduce_band(void *user, float *sums, size_t n)
{
    share_reducer *r = user;
    ss_status agreed = share_band_agree(r->run, &r->agreed);
    if (agreed != SS_OK)
        return agreed;
    return share_sum_at_root(sums, n) ? SS_OK
                                      : ss_ctx_error(r->run->ctx, SS_ERR_INTERNAL,
                                                     "MPI could not add the processes' sums");
}

ss_share share_of(share_reducer *r, run_state *run, int bands)
{
    r->run = run;
    r->agreed = (share_bands){bands, 0};
    ss_share share = {rank_now, size_now, size_now > 1 ? reduce_band : NULL, r};
    return share;
}

ss_status share_end(share_reducer *r, ss_status st)
{
    return share_bands_finish(r->run, &r->agreed, st);
}
