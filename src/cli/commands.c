/* Helpers shared by the commands. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <sys/resource.h>
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
           ss_line_model_name(opt->lines),
           opt->earth_radius_m > 0 ? "on" : "off", ss_ctx_device_name(run->ctx));
    printf("time    sweep %.3f s (%.0f M cell-directions/s over %d x %d cells), kernel build "
           "%.3f s\n",
           c.sweep_seconds, rate, width, height, c.build_seconds);
    if (c.box_sky_directions)
        printf("sky     %llu directions of the box model's sky view or horizons from each cell's "
               "own ray (exact), on the host\n",
               (unsigned long long)c.box_sky_directions);
    if (share_size() > 1)
        printf("share   %d MPI processes, directions dealt round-robin (this one swept %llu), "
               "sums added at rank 0\n",
               share_size(), (unsigned long long)c.sweeps);
}

void command_print_box_march(run_state *run, const char *label)
{
    ss_counters c = ss_ctx_counters(run->ctx);
    if (c.box_march_steps)
        printf("%s box shadows from each cell's own ray: %llu of %llu cells (%.1f %%) marched, "
               "the rest settled by proven bounds\n",
               label, (unsigned long long)c.box_march_marched,
               (unsigned long long)c.box_march_cells,
               100.0 * (double)c.box_march_marched / (double)c.box_march_cells);
}

/* Peak resident memory of the process so far (getrusage), MiB. */
static double peak_resident_mib(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? ru.ru_maxrss / 1024.0 : NAN;
}

/* bytes as MiB, or GiB to three figures from 1 GiB up. */
static void print_bytes(double bytes)
{
    double mib = bytes / 1048576.0;
    if (mib >= 1024.0)
        printf("%.3g GiB", mib / 1024.0);
    else
        printf("%.0f MiB", mib);
}

void command_print_memory(const sweep_job *job, const char *how)
{
    const run_state *run = &job->run;
    const ss_memory_plan *m = &run->memory;
    printf("memory  peak resident %.0f MiB (%s)", peak_resident_mib(), how);
    if (run->memory_bound > 0)
        printf(", bound --memory %.0f MiB", run->memory_bound / 1048576.0);
    /* What --device auto loaded to choose the device (job_memory_replan):
     * the OpenCL platforms, and the device with its kernels. */
    if (run->memory_bound > 0 && run->memory_choosing >= 1048576.0)
        printf(", choosing the device loaded %.0f MiB", run->memory_choosing / 1048576.0);
    if (run->memory_bound > 0)
        printf(", planned %.0f MiB", m->planned_bytes / 1048576.0);
    /* The device the plan was made for: under --device auto the one it
     * picked (job_memory_replan). */
    if (run->memory_device[0])
        printf("%s for %s", run->memory_bound > 0 ? "" : ", planned", run->memory_device);
    /* A device's own memory is planned apart from the process's. */
    if (m->device_memory > 0) {
        printf(", device ");
        print_bytes(m->device_planned);
        printf(" of ");
        print_bytes(m->device_memory);
        printf(" planned");
    }
    printf("\n");
}

void command_print_job_sweep(sweep_job *job, const ss_band_stats *bands)
{
    const ss_grid *g = &job->dem.grid;
    if (!job->source) {
        command_print_sweep(&job->run, &job->opt, g->width, g->height);
        command_print_memory(job, "whole grid");
        run_print_phases(&job->run);
        return;
    }
    ss_counters c = ss_ctx_counters(job->run.ctx);
    printf("sweep   %llu sweeps (%s lines), curvature %s, %s, in bands\n",
           (unsigned long long)c.sweeps,
           ss_line_model_name(job->opt.lines),
           job->opt.earth_radius_m > 0 ? "on" : "off", ss_ctx_device_name(job->run.ctx));
    printf("time    sweep %.3f s (%.0f M cell-directions/s over %d x %d cells), DEM read in "
           "bands\n",
           c.sweep_seconds,
           c.sweep_seconds > 0 ? (double)c.cells_swept / c.sweep_seconds / 1e6 : 0.0, g->width,
           g->height);
    printf("bands   %d rows of %d cells at a time (%.0f MiB); hulls handed on between bands: "
           "%zu, mean %.1f points, largest %zu (%.0f MiB allowed for)\n",
           job->band_rows, job->dem.grid.width,
           /* the band's rows and its 4 halo rows */
           job->band.cell_bytes * (job->band_rows + 4.0) * job->dem.grid.width / 1048576.0,
           bands->handoffs,
           bands->handoffs ? (double)bands->hull_points_handed_on / (double)bands->handoffs : 0.0,
           bands->max_hull_points, job->run.memory.hull_bytes / 1048576.0);
    command_print_memory(job, "bands");
    run_print_phases(&job->run);
}

ss_status command_out_of_memory(run_state *run)
{
    return ss_ctx_error(run->ctx, SS_ERR_MEMORY, "out of memory");
}
