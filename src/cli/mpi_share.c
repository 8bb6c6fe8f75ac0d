/* Processes sharing one run (mpi_share.h). Open MPI is a module loaded
 * only under a launcher (mpi_module.c); a plain start loads nothing. */
#include "config.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "modules.h"
#include "mpi_share.h"

static int rank_now = 0, size_now = 1;

/* What MPI launchers (Open MPI's, PMI's, PMIx's) put in their processes'
 * environments, a plain start none: sizes, and ranks (PMIx states no
 * size). A value of at least `several` says there are other processes. */
static const struct {
    const char *name;
    int several;
} launcher_vars[] = {{"OMPI_COMM_WORLD_SIZE", 2}, {"PMI_SIZE", 2},
                     {"OMPI_COMM_WORLD_RANK", 1}, {"PMIX_RANK", 1}, {"PMI_RANK", 1}};
enum { N_LAUNCHER_VARS = sizeof launcher_vars / sizeof launcher_vars[0] };

#ifdef HAVE_MPI
static void *module;
static union {
    void *symbols[4];
    struct {
        int (*join)(int *, char ***, int *, int *);
        void (*leave)(void);
        int (*min_int)(int *);
        int (*sum_at_root)(float *, int, int);
    } fn;
} mpi;

/* Whether a launcher started this process; if not, MPI is not loaded at all. */
static int launched_by_mpi(void)
{
    for (int i = 0; i < N_LAUNCHER_VARS; ++i)
        if (getenv(launcher_vars[i].name))
            return 1;
    return 0;
}
#else
/* The launcher's variable that says this process is one of several, or
 * NULL: one process under a launcher (mpirun -np 1, srun -n1) runs as a
 * plain start. A program started by a rank inherits its variables; the
 * message names the one to unset. */
static const char *one_of_several(void)
{
    for (int i = 0; i < N_LAUNCHER_VARS; ++i) {
        const char *value = getenv(launcher_vars[i].name);
        if (value && atoi(value) >= launcher_vars[i].several)
            return launcher_vars[i].name;
    }
    return NULL;
}
#endif

int share_start(int *argc, char ***argv)
{
#ifdef HAVE_MPI
    if (!launched_by_mpi())
        return 0;
    static const char *const names[4] = {"ss_mpi_join", "ss_mpi_leave", "ss_mpi_min_int",
                                         "ss_mpi_sum_at_root"};
    ss_ctx *ctx = ss_ctx_new();
    ss_status st = ctx ? cli_module_load(ctx, "skysweep-mpi.so", "Open MPI", names, 4,
                                         mpi.symbols, &module)
                       : SS_ERR_MEMORY;
    if (st != SS_OK) {
        /* Each process would run the whole job and write the same output. */
        fprintf(stderr, "skysweep: started by an MPI launcher, but %s\n",
                ctx ? ss_ctx_message(ctx) : "out of memory");
        ss_ctx_free(ctx);
        return SS_ERR_DEVICE;
    }
    ss_ctx_free(ctx);
    if (!mpi.fn.join(argc, argv, &rank_now, &size_now)) {
        fprintf(stderr, "skysweep: started by an MPI launcher, but MPI_Init failed\n");
        return SS_ERR_DEVICE;
    }
    /* Rank 0 alone prints summaries and plans. */
    if (rank_now > 0 && !freopen("/dev/null", "w", stdout))
        fclose(stdout);
#else
    (void)argc, (void)argv;
    const char *several = one_of_several();
    if (several) {
        /* Each process would run the whole job and write the same output. */
        fprintf(stderr,
                "skysweep: %s=%s says an MPI launcher started several processes, but this "
                "skysweep was built without MPI (configure found no Open MPI, or was given "
                "--without-mpi): unset it to run one process, or use a build with MPI\n",
                several, getenv(several));
        return SS_ERR_DEVICE;
    }
#endif
    return 0;
}

void share_stop(void)
{
#ifdef HAVE_MPI
    if (module)
        mpi.fn.leave();
    module = NULL; /* kept loaded: Open MPI's threads may still run its code */
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
        mpi.fn.min_int(&first);
#endif
    return first < size_now ? first : -1;
}

static int all_min(int v)
{
#ifdef HAVE_MPI
    if (size_now > 1)
        mpi.fn.min_int(&v);
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
    for (size_t at = 0; size_now > 1 && at < n; at += piece)
        if (!mpi.fn.sum_at_root(values + at, (int)(n - at < piece ? n - at : piece), rank_now))
            return 0;
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
