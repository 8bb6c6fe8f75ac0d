/* Helpers shared by the commands. */
#include "config.h"

#include <stdio.h>
#include <stdlib.h>

#include "commands.h"
#include "mpi_share.h"
#include "skysweep.h"

int command_list_devices(void)
{
    ss_ctx *ctx = ss_ctx_new();
    char buf[8192];
    int n = ctx ? ss_list_devices(ctx, buf, sizeof buf) : 0;
    if (n == 0)
        printf("no OpenCL devices found (install pocl-opencl-icd); --device reference runs the "
               "C reference\n");
    else
        fputs(buf, stdout);
    printf("reference C reference (host, OpenMP)\n");
    ss_ctx_free(ctx);
    return 0;
}

void command_print_sweep(run_state *run, const ss_sweep_options *opt, int width, int height)
{
    ss_counters c = ss_ctx_counters(run->ctx);
    double rate = c.sweep_seconds > 0 ? (double)c.cells_swept / c.sweep_seconds / 1e6 : 0;
    printf("sweep   %llu sweeps (%s lines), curvature %s, %s\n",
           (unsigned long long)c.sweeps,
           opt->lines == SS_LINES_DIGITAL ? "digital" : "interpolated",
           opt->earth_radius_m > 0 ? "on" : "off", ss_ctx_device_name(run->ctx));
    printf("time    sweep %.3f s (%.0f M cell-directions/s over %d x %d cells), kernel build "
           "%.3f s\n",
           c.sweep_seconds, rate, width, height, c.build_seconds);
    if (share_size() > 1)
        printf("share   %d MPI processes, directions dealt round-robin (this one swept %llu), "
               "sums added at rank 0\n",
               share_size(), (unsigned long long)c.sweeps);
}

ss_status command_out_of_memory(run_state *run)
{
    (void)run;
    fprintf(stderr, "skysweep %s: out of memory\n", run->command);
    return SS_ERR_MEMORY;
}
