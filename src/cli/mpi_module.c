/* Open MPI at run time: the module skysweep-mpi.so, the only code that
 * includes mpi.h. Linking Open MPI into the program loads seven shared
 * libraries (libmpi, its runtime, hwloc, libevent) at every start, about
 * 2.6 ms, where only a run under mpirun uses them; mpi_share.c loads this
 * module then (modules.h) and calls the four functions below. */
#include "config.h"

#include <dlfcn.h>
#include <mpi.h>

/* Declared here for the module's users, which look them up by name. */
int ss_mpi_join(int *argc, char ***argv, int *rank, int *size);
void ss_mpi_leave(void);
int ss_mpi_min_int(int *value);
int ss_mpi_sum_at_root(float *values, int count, int rank);

/* Joins the job mpirun started: 1 with this process's rank and the size,
 * or 0. */
int ss_mpi_join(int *argc, char ***argv, int *rank, int *size)
{
    /* The module came with RTLD_LOCAL, and so did libmpi with it; Open MPI
     * loads its components later, which look its symbols up globally (as
     * mpi4py does, libmpi is made global first). */
    Dl_info where;
    if (dladdr((void *)MPI_Init, &where) && where.dli_fname)
        dlopen(where.dli_fname, RTLD_NOW | RTLD_GLOBAL | RTLD_NOLOAD);
    if (MPI_Init(argc, argv) != MPI_SUCCESS)
        return 0;
    MPI_Comm_rank(MPI_COMM_WORLD, rank);
    MPI_Comm_size(MPI_COMM_WORLD, size);
    return 1;
}

void ss_mpi_leave(void)
{
    MPI_Finalize();
}

/* Collective: *value becomes the smallest over the processes. */
int ss_mpi_min_int(int *value)
{
    return MPI_Allreduce(MPI_IN_PLACE, value, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD) == MPI_SUCCESS;
}

/* Collective: rank 0's values become the sums over the processes. */
int ss_mpi_sum_at_root(float *values, int count, int rank)
{
    int rc = rank == 0 ? MPI_Reduce(MPI_IN_PLACE, values, count, MPI_FLOAT, MPI_SUM, 0,
                                    MPI_COMM_WORLD)
                       : MPI_Reduce(values, NULL, count, MPI_FLOAT, MPI_SUM, 0, MPI_COMM_WORLD);
    return rc == MPI_SUCCESS;
}
