/* Shared CLI runtime (see run.h). */
#include "config.h"

#include <float.h>
#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>
#include <time.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

#include "commands.h"
#include "heightmap_input.h"
#include "mpi_share.h"
#include "run.h"
#include "run_files.h"
#include "scene.h"
#include "stop_guard.h"
#include "thread_room.h"

#define COMMON(field) offsetof(common_settings, field)
/* The indices of --z-units' choices (common_settings.z_units). */
enum { Z_UNITS_AUTO, Z_UNITS_M, Z_UNITS_FT, Z_UNITS_US_FT };

/* The command line's own options; the model's come from the library's
 * "sweep" table. */
static const opt_spec cli_options[] = {
    {"device", OPT_STRING, COMMON(device), "NAME", NULL, 0, 0, NULL,
     "'auto' (the plan picks the fastest for the job from a cost model, doc/devices.md), "
     "'reference' (the C twin), an OpenCL device ('P:D' or part of its name), or 'list'; "
     "default $SKYSWEEP_DEVICE, else auto"},
    {"q", OPT_FLAG, COMMON(quiet), NULL, NULL, 0, 0, NULL, "quiet: no progress, no summary"},
    {"of", OPT_STRING, COMMON(format), "FORMAT", "GTiff", 0, 0, NULL, "GDAL output format"},
    {"co", OPT_LIST, COMMON(creation_options), "KEY=VALUE", NULL, 0, 0, NULL,
     "GDAL creation option (repeatable); defaults: TILED=YES COMPRESS=DEFLATE ZLEVEL=1 "
     "PREDICTOR=3 NUM_THREADS=ALL_CPUS"},
    {"cell-size", OPT_DOUBLE, COMMON(cell_size_m), "METRES", NULL, 1e-6, 1e7, NULL,
     "treat an input without georeferencing as a heightmap with this cell size"},
    {"heightmap", OPT_FLAG, COMMON(heightmap), NULL, NULL, 0, 0, NULL,
     "read the input as a plain image through OpenImageIO (16-bit PNG, EXR, TIFF): heights "
     "= pixel x --z-scale on --cell-size cells, no CRS"},
    {"z-scale", OPT_DOUBLE, COMMON(z_scale), "FACTOR", "1", -1e6, 1e6, NULL,
     "with --heightmap: metres per pixel value (e.g. 0.1 for decimetres)"},
    {"z-units", OPT_CHOICE, COMMON(z_units), NULL, "auto", 0, 0, "auto|m|ft|us-ft",
     "unit of the stored heights (ft: international foot, us-ft: US survey foot); auto: the "
     "band's unit type, else the CRS's vertical axis, else metres"},
    {"overlap", OPT_CHOICE, COMMON(overlap), NULL, "refuse", 0, 0, "refuse|first|last|mean",
     "where tiles given together overlap and disagree (by more than 1 cm, or half an integer "
     "tile's step): refuse them, or take the first or last tile's height, or their mean"},
    {"scene", OPT_INPUT, COMMON(scene), "FILE", NULL, 0, 0, NULL,
     "read the job from a scene file (doc/scenes.md); options given here override it"},
    {"projwin", OPT_STRING, COMMON(projwin), "ULX ULY LRX LRY", NULL, 0, 0, NULL,
     "write the outputs for this window only (the DEM's CRS, as gdal_translate -projwin; "
     "also ULX,ULY,LRX,LRY); horizons still come from the whole DEM"},
    {"memory", OPT_STRING, COMMON(memory), "SIZE", NULL, 0, 0, NULL,
     "bound on the process's peak resident memory (the program, GDAL and a CPU device's "
     "buffers included), e.g. 512M or 4G; a larger DEM is swept in bands of rows "
     "(exact, doc/scale.md; render alone refuses it) (default: half the RAM)"},
    {"plan", OPT_FLAG, COMMON(plan_only), NULL, NULL, 0, 0, NULL,
     "print the plan (effects on/off, why, the error allowed, cost) and stop"},
    {"plan-format", OPT_CHOICE, COMMON(plan_json), NULL, "text", 0, 0, "text|json",
     "format of the plan"},
    OPT_END};

const opt_spec *common_options(void)
{
    static opt_spec table[48];
    if (!table[0].name) {
        int n = opt_from_params("sweep", COMMON(sweep), table, 32);
        memcpy(table + n, cli_options, sizeof cli_options);
    }
    return table;
}

const opt_spec *sun_options(void)
{
    static opt_spec table[16];
    if (!table[0].name)
        opt_from_params("sun", COMMON(sun), table, 16);
    return table;
}

void common_settings_init(common_settings *common)
{
    ss_sun_params_init(&common->sun);
}

double run_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The signals that stop a run (stop_guard.c blocks the same in its thread). */
static const int stop_signals[] = {SIGINT, SIGTERM, SIGHUP, SIGPIPE};

/* The context of the command running, so that a signal stops its sweep
 * between lines (ss_ctx_cancel only sets a flag). */
static ss_ctx *signal_ctx = NULL;

static void on_signal(int sig)
{
    stop_guard_signal(sig);
    if (signal_ctx)
        ss_ctx_cancel(signal_ctx);
}

/* For a program that follows the run (the QGIS provider): the fraction done
 * as a line "progress 0.1234" on stdout each time it moves by 0.1 %, from
 * the start, so a bar can move per direction or step. */
static int progress_line(run_state *run, double complete)
{
    if (complete < 1.0 && complete - run->progress_last < 0.001)
        return 1;
    run->progress_last = complete;
    printf("progress %.4f\n", complete);
    fflush(stdout);
    return 1;
}

/* GDAL's term progress, shown only once a run has lasted a second, and the
 * place where a pending stop signal cancels the run. */
static int progress(double complete, const char *message, void *user)
{
    (void)message;
    run_state *run = user;
    if (stop_guard_signalled())
        return 0;
    if (run->quiet)
        return 1;
    if (run->progress_parts > 1)
        complete = (run->progress_part + complete) / run->progress_parts;
    if (run->progress_lines)
        return progress_line(run, complete);
    if (!run->progress_shown && run_now() - run->started < 1.0)
        return 1;
    run->progress_shown = 1;
    stop_guard_line_open(complete < 1.0);
    return ss_gdal_term_progress(complete);
}

void run_progress_part(run_state *run, int part, int parts)
{
    run->progress_part = part;
    run->progress_parts = parts;
}

/* Whether an address-space limit (ulimit -v) below the machine's memory
 * bounds the run: threads started late (GDAL's compression pool at the
 * first write, PoCL's with the device) may then find no room left for
 * their stacks, once the run's memory is taken. */
static int address_space_tight(void)
{
    struct rlimit limit;
    double memory = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
    return getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY &&
           (double)limit.rlim_cur < memory;
}

/* Sizes the run's thread pools to the threads this process can start
 * (thread_room.h) and starts OpenMP's team while there is room for it:
 * OpenMP's team and GDAL's compression pool share what there is, and a
 * run the plan would give to an OpenCL device goes to the C twin, since no
 * option sizes PoCL's threads. Under a tight address space GDAL compresses
 * in the run's thread. *device is the device asked for, "reference" once
 * the run takes the C twin. 0, or the exit code after its line. */
static int fit_threads(const char *command, const char **device)
{
    int cores = (int)sysconf(_SC_NPROCESSORS_ONLN);
#ifdef _OPENMP
    if (omp_get_max_threads() > cores)
        cores = omp_get_max_threads();
#endif
    if (cores < 1)
        cores = 1;
    /* OpenMP's team beside the run's thread, GDAL's pool (NUM_THREADS=ALL_CPUS),
     * PoCL's threads, the stop guard's and the kernel build's. */
    int want = 3 * cores + 1;
    int room = thread_room_probe(want), tight = address_space_tight();
    if ((room < want || tight) && strcasecmp(*device, "auto") == 0)
        *device = "reference";
    if (room < want && strcasecmp(*device, "reference") != 0) {
        fprintf(stderr, "skysweep %s: this process can start only %d more threads (ulimit -u "
                        "or -v), too few for an OpenCL device: use --device reference\n",
                command, room);
        return SS_ERR_DEVICE;
    }
    /* A team of n takes n - 1 threads, a pool of n > 1 takes n, the guard one. */
    int share = room >= want ? cores : room / 2 > 1 ? room / 2 : 1;
    char text[16];
    snprintf(text, sizeof text, "%d", tight ? 1 : share);
    if (room < want || tight)
        setenv("GDAL_NUM_THREADS", text, 1); /* the raster writer's NUM_THREADS */
#ifdef _OPENMP
    if (room < want)
        omp_set_num_threads(share);
    /* libgomp keeps the team it starts for the regions to come: started
     * now, it cannot fail later for want of room (libgomp would exit 1). */
#pragma omp parallel
    {
    }
#endif
    return 0;
}

int run_begin(run_state *run, const char *command, const common_settings *common)
{
    memset(run, 0, sizeof *run);
    run->command = command;
    /* Under mpirun only rank 0 speaks (mpi_share.h). */
    run->quiet = (common ? common->quiet : 0) || share_rank() > 0;
    run->plan_only = common ? common->plan_only : 0;
    run->started = run_now();
    const char *lines = getenv("SKYSWEEP_PROGRESS");
    run->progress_lines = lines && strcmp(lines, "lines") == 0;
    /* The device follows the job unless one is named here or in the
     * environment (SKYSWEEP_DEVICE, read by the library). */
    const char *env = getenv("SKYSWEEP_DEVICE");
    const char *device = common && common->device ? common->device : env && env[0] ? env : "auto";
    int rc = fit_threads(command, &device);
    if (rc)
        return rc;
    run->ctx = ss_ctx_new();
    if (!run->ctx) {
        fprintf(stderr, "skysweep %s: out of memory\n", command);
        return SS_ERR_MEMORY;
    }
    signal_ctx = run->ctx;
    stop_guard_arm(command, share_rank() == 0);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    /* A closed terminal (SIGHUP) and a reader that has gone (SIGPIPE, as
     * `skysweep ... | head -1` gives once the progress is written) stop a
     * run as Ctrl-C does: one line on standard error, no temporary left. */
    for (size_t i = 0; i < sizeof stop_signals / sizeof stop_signals[0]; ++i)
        sigaction(stop_signals[i], &sa, NULL);
    ss_ctx_set_progress(run->ctx, progress, run);
    ss_ctx_use_device(run->ctx, device);
    run->device_auto = strcasecmp(device, "auto") == 0;
    return 0;
}

int run_interrupted(void)
{
    return stop_guard_signalled() != 0;
}

int run_fail(run_state *run, ss_status status)
{
    if (stop_guard_signalled()) {
        stop_guard_report();
        return 128 + stop_guard_signalled();
    }
    if (share_rank() > 0)
        return (int)status; /* rank 0 reports, naming this process if it failed alone */
    if (run->progress_shown)
        fputc('\n', stderr);
    fprintf(stderr, "skysweep %s: %s\n", run->command, ss_ctx_message(run->ctx));
    return (int)status;
}

int run_usage_error(const char *command, const char *message)
{
    fprintf(stderr, "skysweep %s: %s (see skysweep %s --help)\n", command, message, command);
    return SS_ERR_ARGUMENT;
}

void run_end(run_state *run)
{
    if (signal_ctx == run->ctx)
        signal_ctx = NULL;
    ss_ctx_free(run->ctx);
    run->ctx = NULL;
}

/* --memory's SIZE: bytes, with an optional k, M, G or T (powers of 1024). */
static int parse_size(const char *text, double *bytes)
{
    char *end;
    double v = strtod(text, &end);
    const char *units = "kMGT";
    const char *u = *end ? strchr(units, *end) : NULL;
    if (*end && (!u || end[1] != '\0'))
        return -1;
    if (u)
        v *= pow(1024.0, (double)(u - units + 1));
    if (!(v > 0) || !isfinite(v))
        return -1;
    *bytes = v;
    return 0;
}

/* Opens the DEM; reads it whole unless the command can band (cost is not
 * NULL) and the whole-grid sweep does not fit. */
static ss_status open_dem_file(run_state *run, const char *const *paths, int n_paths,
                               const common_settings *common, const band_cost *cost,
                               ss_dem *dem, ss_dem_source **source, int *band_rows);

/* Opens the DEM (open_dem_file) and keeps its height unit for the outputs'
 * metadata. */
static ss_status open_dem(run_state *run, const char *const *paths, int n_paths,
                          const common_settings *common, const band_cost *cost, ss_dem *dem,
                          ss_dem_source **source, int *band_rows)
{
    ss_status st = open_dem_file(run, paths, n_paths, common, cost, dem, source, band_rows);
    if (st == SS_OK)
        snprintf(run->z_unit_source, sizeof run->z_unit_source, "%s", dem->z_unit_source);
    return st;
}

/* The process's resident memory now (/proc/self/statm), bytes; 0 where
 * the system does not say. */
static double resident_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long size = 0, resident = 0;
    int got = f && fscanf(f, "%lu %lu", &size, &resident) == 2;
    if (f)
        fclose(f);
    return got ? (double)resident * (double)sysconf(_SC_PAGESIZE) : 0.0;
}

/* The process's peak resident memory so far (getrusage), bytes. */
static double peak_bytes(void)
{
    struct rusage ru;
    return getrusage(RUSAGE_SELF, &ru) == 0 ? (double)ru.ru_maxrss * 1024.0 : 0.0;
}

/* GDAL's block cache, capped under a budget, whole or in bands, and counted
 * by the memory plan: else an output written whole keeps its dirty blocks
 * up to GDAL's default (5 % of the RAM); horizon's 32 bands of angles,
 * distances and casting heights of a 2048^2 DEM peaked at 1419 MiB under
 * --memory 300M. */
#define GDAL_CACHE_BYTES (16 * 1048576)

/* Band rows for the budget from the memory planner (memory_plan.c): the
 * device is opened first (a sweeping command's), so that what the process
 * then holds, libraries, GDAL, the DEM's dataset and the device with its
 * kernels, is measured and counted, and a CPU device's buffers are too. */
static int plan_memory(run_state *run, const ss_dem *dem, const band_cost *cost, double budget,
                       double device_memory, double cell_bytes, int hull_directions, int halo)
{
    if (!cost->no_sweep)
        ss_ctx_device_name(run->ctx);
    ss_memory_need need = {.budget_bytes = budget,
                           .baseline_bytes = resident_bytes(),
                           .peak_bytes = peak_bytes(),
                           .width = dem->grid.width,
                           .height = dem->grid.height,
                           .cell_bytes = cell_bytes,
                           .whole_cell_bytes = cell_bytes + cost->output_bytes,
                           .column_bytes = cost->column_bytes,
                           .hull_lines = hull_directions,
                           .halo_rows = halo,
                           .cache_bytes = GDAL_CACHE_BYTES,
                           .grid_cell_bytes = cost->grid_cell_bytes,
                           .device_memory_bytes = device_memory};
    ss_memory_plan_make(run->ctx, &need, &run->memory);
    run->memory_need = need;
    snprintf(run->memory_device, sizeof run->memory_device, "%s",
             cost->no_sweep ? "" : ss_ctx_device_name(run->ctx));
    return run->memory.band_rows;
}

memory_mark job_memory_mark(void)
{
    return (memory_mark){resident_bytes(), peak_bytes()};
}

/* Whether the plan just made lets the job's DEM be swept as it was opened:
 * in bands (any band rows; the grid would fit whole too), or whole. */
static int plan_keeps_dem(const sweep_job *job)
{
    int rows = job->run.memory.band_rows;
    return job->source ? rows >= 0 : rows == 0;
}

/* The budget a refusal names for a least of least bytes: whole MiB, and
 * 1 MiB more, because what the process holds varies by a few hundred KiB
 * from run to run (its heap, GDAL's and the threads' pages), and a least
 * named to the MiB was refused on the next run now and then. */
static double named_budget(double least)
{
    return (ceil(least / 1048576.0) + 1.0) * 1048576.0;
}

/* Refuses a budget too small for one band, naming a budget that would do
 * (named_budget) and what the process holds (of it, what --device auto
 * loaded to choose a device: 0 where it loaded nothing). */
static ss_status refuse_budget(const run_state *run, double least, double held,
                               double loaded_by_auto, int width)
{
    char loaded[96] = "";
    if (loaded_by_auto >= 1048576.0)
        snprintf(loaded, sizeof loaded, ", %.0f MiB of it loaded by --device auto to choose a device",
                 loaded_by_auto / 1048576.0);
    return ss_ctx_error(run->ctx, SS_ERR_MEMORY,
                        "the memory budget (%s) is too small for this DEM and command: it "
                        "needs at least --memory %.0fM (the process's %.0f MiB%s, one band of "
                        "%d cells with the hulls handed on, GDAL's cache and the device's "
                        "buffers; doc/scale.md)",
                        run->memory_asked ? run->memory_asked : "half this machine's memory",
                        named_budget(least) / 1048576.0, held / 1048576.0, loaded, width);
}

/* The least budget with which a plan for need on the context's device
 * sweeps the grid whole (the peak already reached included), DBL_MAX
 * where the device holds no whole grid. The context keeps that plan: make
 * the run's after it. */
static double whole_least(ss_ctx *ctx, ss_memory_need need)
{
    ss_memory_plan p;
    need.budget_bytes = DBL_MAX;
    ss_memory_plan_make(ctx, &need, &p);
    return p.band_rows == 0 ? fmax(p.planned_bytes, need.peak_bytes) : DBL_MAX;
}

/* The least budget --device auto accepts, choosing again as it did, on
 * the devices tried (least_bands: the least of their plans' least budgets,
 * least_whole: of their whole grids'): with a budget that the C twin's
 * plan at the DEM's opening (first, made before choosing, on heights the
 * effects plan reads) sweeps whole, the DEM is read whole before the
 * device is chosen, and then only a whole grid keeps it: a least whose
 * named budget (named_budget) comes within 1 MiB of the first plan's whole
 * grid, which moves with the process's size from run to run too, is taken
 * whole. */
static double auto_least(run_state *run, const ss_memory_need *first, double least_bands,
                         double least_whole)
{
    double whole_first = whole_least(run->ctx, *first);
    return named_budget(least_bands) + 1048576.0 < whole_first ? least_bands
                                                                : fmax(whole_first, least_whole);
}

ss_status job_memory_replan(sweep_job *job, memory_mark before)
{
    run_state *run = &job->run;
    /* Processes sharing a run sweep the same bands, agreed at the DEM's
     * opening (share_band_rows): they keep them. */
    if (!run->device_auto || run->memory_need.width == 0 || !run->memory_device[0] ||
        share_size() > 1)
        return SS_OK;
    /* Looking for OpenCL devices loads their platforms even where the C
     * twin stays: that is counted as well. */
    ss_memory_need need = run->memory_need;
    need.baseline_bytes += fmax(resident_bytes() - before.resident, 0.0);
    need.peak_bytes += fmax(peak_bytes() - before.peak, 0.0);
    char chosen[sizeof run->memory_device];
    snprintf(chosen, sizeof chosen, "%s", ss_ctx_device_name(run->ctx));
    double least_whole = whole_least(run->ctx, need);
    ss_memory_plan_make(run->ctx, &need, &run->memory);
    double least_bands = run->memory.least_budget;
    const char *fell_back = NULL;
    char picked[sizeof chosen];
    snprintf(picked, sizeof picked, "%s", chosen);
    if (!plan_keeps_dem(job) && strcmp(chosen, run->memory_device) != 0) {
        fell_back = job->source ? "one band" : "the DEM held whole";
        ss_ctx_use_device(run->ctx, "reference");
        snprintf(job->plan.device, sizeof job->plan.device, "reference");
        snprintf(chosen, sizeof chosen, "%s", ss_ctx_device_name(run->ctx));
        least_whole = fmin(least_whole, whole_least(run->ctx, need));
        ss_memory_plan_make(run->ctx, &need, &run->memory);
        least_bands = fmin(least_bands, run->memory.least_budget);
    }
    /* The context is on the C twin here, as at the DEM's opening. */
    if (!plan_keeps_dem(job))
        return refuse_budget(run, auto_least(run, &run->memory_need, least_bands, least_whole),
                             need.baseline_bytes,
                             need.baseline_bytes - run->memory_need.baseline_bytes,
                             job->dem.grid.width);
    if (fell_back && !run->quiet)
        fprintf(stderr,
                "skysweep %s: warning: --device auto chose %s, whose buffers leave no room "
                "for %s within the memory budget: the C twin runs\n",
                run->command, picked, fell_back);
    if (job->source && run->memory.band_rows > 0)
        job->band_rows = run->memory.band_rows;
    run->memory_choosing = need.baseline_bytes - run->memory_need.baseline_bytes;
    run->memory_need = need;
    snprintf(run->memory_device, sizeof run->memory_device, "%s", chosen);
    return SS_OK;
}

/* Whether a budget too small for one band on the C twin is refused once
 * --device auto has chosen its device (job_memory_replan) rather than now:
 * choosing may load the OpenCL platforms and a device's kernels, and the
 * least budget named must be one that auto, choosing again, accepts. Not
 * for processes sharing a run (their bands are agreed now), nor for a
 * command that plans only after other work (roofs). */
static int refused_after_choosing(const run_state *run, const band_cost *cost, int rows,
                                  double budget)
{
    return rows < 0 && cost && !cost->no_sweep && !cost->plans_late && run->device_auto &&
           share_size() == 1 && run->memory.least_budget > budget;
}

static ss_status open_dem_file(run_state *run, const char *const *paths, int n_paths,
                               const common_settings *common, const band_cost *cost,
                               ss_dem *dem, ss_dem_source **source, int *band_rows)
{
    int may_band = cost != NULL;
    /* A halo is a radius walk's (svf and openness within a radius, the VAT
     * blend). */
    int radius_walk = may_band && (cost->halo_m > 0 || cost->halo_cells > 0);
    double cell_bytes =
        may_band ? cost->cell_bytes + ss_lines_extra_cell_bytes(run_lines_asked(common)) : 0.0;
    /* Hulls are handed on per line: box lines have box_lines times as many
     * (the plan's count is not known yet: the most it can take). */
    int hull_directions =
        may_band && cost->hull_lines > 0
            ? cost->hull_lines
            : (may_band && cost->directions ? cost->directions : common->sweep.directions) *
                  (run_lines_asked(common) == SS_LINES_BOX
                       ? ss_sweep_params_box_lines_most(&common->sweep)
                       : 1);
    *source = NULL;
    *band_rows = 0;
    if (common->heightmap)
        return heightmap_read(run, paths, n_paths, common, dem);
    if (common->z_scale != 1.0)
        return ss_ctx_error(run->ctx, SS_ERR_ARGUMENT,
                            "--z-scale applies to --heightmap inputs; a DEM's heights are scaled "
                            "by its own unit (or --z-units)");
    double budget = 0;
    if (common->memory && parse_size(common->memory, &budget) != 0)
        return ss_ctx_error(run->ctx, SS_ERR_ARGUMENT,
                            "--memory expects a size such as 512M or 4G, not '%s'",
                            common->memory);
    /* A test hook (doc/scale.md): plans the device's buffers as if it had
     * this much memory of its own, a GPU's smaller, PoCL's or the C twin's
     * as a GPU's would be. */
    const char *device_memory_env = getenv("SKYSWEEP_TEST_DEVICE_MEMORY");
    double device_memory = 0;
    if (device_memory_env && *device_memory_env &&
        parse_size(device_memory_env, &device_memory) != 0)
        return ss_ctx_error(run->ctx, SS_ERR_ARGUMENT,
                            "SKYSWEEP_TEST_DEVICE_MEMORY expects a size such as 512M, not '%s'",
                            device_memory_env);
    static const double metres_per_unit[] = {[Z_UNITS_AUTO] = 0.0,
                                             [Z_UNITS_M] = 1.0,
                                             [Z_UNITS_FT] = 0.3048,
                                             [Z_UNITS_US_FT] = 1200.0 / 3937.0};
    ss_dem_read_options ro = {.heightmap_cell_m = common->cell_size_m,
                              .z_unit_m = metres_per_unit[common->z_units],
                              .overlap = (ss_overlap_rule)common->overlap};
    if (!common->memory && !may_band)
        return ss_dem_read(run->ctx, paths, n_paths, &ro, dem);
    if (!common->memory)
        budget = 0.5 * (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
    else
        run->memory_bound = budget;
    run->memory_asked = common->memory;
    ss_dem_source *src;
    ss_status st = ss_dem_open(run->ctx, paths, n_paths, &ro, dem, &src);
    /* The engine indexes a run's cells with ints (engine.c): no budget
     * sweeps more, so say that rather than size bands for it. */
    if (st == SS_OK && (double)dem->grid.width * dem->grid.height > 2147483647.0) {
        st = ss_ctx_error(run->ctx, SS_ERR_INPUT,
                          "'%s' has %d x %d cells, beyond the 2^31 cells one run sweeps: cut it "
                          "into tiles (gdal_translate -srcwin) and run each with a margin",
                          paths[0], dem->grid.width, dem->grid.height);
        ss_dem_source_close(src);
        ss_dem_free(dem);
        return st;
    }
    /* Its stack slots, where the radius takes hulls: the VAT blend's radius
     * in cells taken at the larger cell size, which it never exceeds. */
    if (st == SS_OK && radius_walk) {
        double cx = dem->grid.cell_x_m, cy = dem->grid.cell_y_m;
        cell_bytes += ss_radius_extra_cell_bytes(cost->halo_m + cost->halo_cells * fmax(cx, cy),
                                                 cx, cy);
    }
    int halo = 0;
    if (st == SS_OK && radius_walk) {
        /* A radius walk holds the rows within its radius beside each band
         * (a geographic grid's rows, whose sizes come with its frame,
         * counted at their smallest: a degree of latitude is 110.574 km or
         * more); more rows than the grid's height cannot be held either way. */
        double cell_y = isfinite(dem->grid.cell_y_m) ? dem->grid.cell_y_m
                                                     : fabs(dem->geotransform[5]) * 110574.0;
        halo = (int)fmin(ceil(cost->halo_m / cell_y + cost->halo_cells), dem->grid.height);
    }
    int rows = -2;
    if (st == SS_OK && may_band)
        rows = plan_memory(run, dem, cost, budget, device_memory, cell_bytes, hull_directions,
                           halo);
    else if (st == SS_OK)
        rows = ss_band_rows_for(dem->grid.width, dem->grid.height, common->sweep.directions,
                                budget);
    /* Processes sharing a run sweep the same bands (their machines' memory
     * may differ); a process that could not open the DEM stops them all. */
    if (may_band)
        rows = share_band_rows(rows);
    if (st != SS_OK)
        return st;
    if (rows == -2) {
        ss_dem_source_close(src);
        ss_dem_free(dem);
        return ss_ctx_error(run->ctx, SS_ERR_INPUT, "another process could not open '%s'",
                            paths[0]);
    }
    if (st == SS_OK && refused_after_choosing(run, cost, rows, budget))
        rows = 1; /* until job_memory_replan refuses */
    if (rows != 0 && (!may_band || rows < 0)) {
        double need = ss_whole_sweep_bytes(dem->grid.width, dem->grid.height);
        const ss_memory_plan *m = &run->memory;
        if (may_band && m->least_budget <= budget && m->device_least > m->device_memory)
            st = ss_ctx_error(run->ctx, SS_ERR_MEMORY,
                              "the device's memory (%.0f MiB) is too small for one band of %d "
                              "cells of this DEM and command: it needs a device of at least "
                              "%.0f MiB (its driver's share kept), or --device reference "
                              "(doc/scale.md)",
                              m->device_memory / 1048576.0, dem->grid.width,
                              ceil(m->device_least / 1048576.0));
        else if (may_band)
            st = refuse_budget(run, m->least_budget, resident_bytes(), 0, dem->grid.width);
        else
            st = ss_ctx_error(run->ctx, SS_ERR_MEMORY,
                              "'%s' needs about %.0f MiB for a whole-grid sweep, more than "
                              "%s allows; svf, openness, horizon, shadow, insolation and a "
                              "plain hillshade work in bands",
                              paths[0], need / 1048576.0,
                              common->memory ? "--memory" : "half this machine's memory");
    }
    if (st == SS_OK)
        ss_gdal_limit_cache(GDAL_CACHE_BYTES);
    if (st == SS_OK && rows == 0) {
        /* It fits: read it whole, as ss_dem_read would. */
        ss_grid *g = &dem->grid;
        int w = g->width, h = g->height;
        double cx = g->cell_x_m, cy = g->cell_y_m;
        st = ss_grid_alloc(run->ctx, g, w, h, cx, cy);
        if (st == SS_ERR_ARGUMENT)
            st = SS_ERR_INPUT;
        double t = run_now();
        if (st == SS_OK)
            st = ss_dem_source_read(run->ctx, src, dem, 0, h, g->z);
        run->phases.read_s += run_now() - t;
    }
    if (st == SS_OK && rows > 0) {
        *source = src;
        *band_rows = rows;
        return SS_OK;
    }
    ss_dem_source_close(src);
    if (st != SS_OK)
        ss_dem_free(dem);
    return st;
}

ss_status run_read_dem(run_state *run, const char *const *paths, int n_paths,
                       const common_settings *common, ss_dem *dem, ss_dem_frame *frame)
{
    ss_dem_source *source;
    int band_rows;
    ss_status st = open_dem(run, paths, n_paths, common, NULL, dem, &source, &band_rows);
    if (st == SS_OK) {
        st = ss_dem_frame_open(run->ctx, dem, frame);
        if (st != SS_OK)
            ss_dem_free(dem);
    }
    if (st == SS_OK && dem->rejected_cells && !run->quiet)
        fprintf(stderr,
                "skysweep %s: warning: %zu heights beyond +-1e7 m were taken as nodata\n",
                run->command, dem->rejected_cells);
    return st;
}

double run_earth_radius(const common_settings *common, const ss_dem_frame *frame)
{
    return common->sweep.earth_radius_m > 0 ? common->sweep.earth_radius_m : frame->earth_radius_m;
}

ss_line_model run_lines_asked(const common_settings *common)
{
    return ss_sweep_params_lines(&common->sweep);
}

double run_march_cell_bytes(const common_settings *common)
{
    int marched = run_lines_asked(common) == SS_LINES_BOX &&
                  common->sweep.box_shadows == SS_BOX_SHADOWS_MARCH;
    return marched ? (double)sizeof(float) : 0.0;
}

double run_box_sky_cell_bytes(const common_settings *common)
{
    int marched = run_lines_asked(common) == SS_LINES_BOX &&
                  common->sweep.box_sky == SS_BOX_SKY_MARCH;
    return marched ? (double)sizeof(float) : 0.0;
}

ss_place run_place(const common_settings *common, const ss_dem_frame *f)
{
    return (ss_place){f->georeferenced,      f->geographic,         f->centre_lon_deg,
                      f->centre_lat_deg,     f->grid_north_deg,     f->grid_north_min_deg,
                      f->grid_north_max_deg, f->cell_variation,     f->diagonal_m,
                      run_earth_radius(common, f)};
}

void run_sweep_options(const common_settings *common, const ss_dem_frame *frame,
                       ss_sweep_options *opt)
{
    /* Provisional: job_plan sets directions, curvature and north from the plan. */
    ss_place place = run_place(common, frame);
    ss_sweep_params_options(&common->sweep, &place, opt);
}

ss_status run_check_output(run_state *run, const char *output)
{
    return run->plan_only ? SS_OK : ss_output_check(run->ctx, output);
}

void run_common_metadata(run_state *run, ss_raster_writer *w, const ss_sweep_options *opt,
                         const ss_dem_frame *frame)
{
    char buf[768];
    ss_writer_metadata(w, "SKYSWEEP_VERSION", ss_version());
    ss_writer_metadata(w, "SKYSWEEP_COMMAND", run->command);
    snprintf(buf, sizeof buf, "%d", opt->directions);
    ss_writer_metadata(w, "DIRECTIONS", buf);
    if (run->z_unit_source[0])
        ss_writer_metadata(w, "INPUT_HEIGHT_UNIT", run->z_unit_source);
    snprintf(buf, sizeof buf, "%.17g", opt->offset_deg);
    ss_writer_metadata(w, "DIRECTION_OFFSET_DEG", buf);
    if (frame->georeferenced && opt->grid_north_deg == 0.0 && frame->grid_north_deg != 0.0)
        snprintf(buf, sizeof buf,
                 "degrees clockwise from grid north (up the grid's columns; grid north is "
                 "%.6f deg true at the centre)",
                 frame->grid_north_deg);
    else if (frame->georeferenced)
        snprintf(buf, sizeof buf,
                 "degrees clockwise from true north (grid north is %.6f deg true at the centre, "
                 "%.6f to %.6f over the grid; lines are straight in the grid)",
                 frame->grid_north_deg, frame->grid_north_min_deg, frame->grid_north_max_deg);
    else
        snprintf(buf, sizeof buf, "degrees clockwise from the grid's north (no CRS)");
    ss_writer_metadata(w, "AZIMUTH_CONVENTION", buf);
    snprintf(buf, sizeof buf,
             "%.6f x %.6f m at the centre (%s), varying by up to %.2g relative over the grid",
             frame->cell_x_m, frame->cell_y_m,
             !frame->georeferenced ? "given" : frame->geographic ? "geodesic" : "projected / scale",
             frame->cell_variation);
    ss_writer_metadata(w, "CELL_SIZE_USED", buf);
    /* What the box model took, as the run did it: the rays where they ran,
     * the lines where anything was swept on them (the sky view's own count
     * where the plan gave it one), the exact shadows' rays where any step
     * or sun was marched. */
    ss_counters done = ss_ctx_counters(run->ctx);
    if (opt->lines == SS_LINES_BOX) {
        int sky = opt->sky_box_lines > 0 ? opt->sky_box_lines : opt->box_lines;
        int shadow_lines = opt->box_shadows == SS_BOX_SHADOWS_LINES;
        char lines[256] = "";
        if (done.sweeps > 0 && shadow_lines && sky != opt->box_lines)
            snprintf(lines, sizeof lines,
                     "; the lines swept give each cell the horizon of the nearest: %d per cell "
                     "for the sky view (at most %.3g cell beside its centre), %d for cast "
                     "shadows where the run casts any (%.3g)",
                     sky, 0.5 / sky, opt->box_lines, 0.5 / opt->box_lines);
        else if (done.sweeps > 0)
            snprintf(lines, sizeof lines,
                     "; the lines swept, %d per cell, give each cell the horizon of the nearest "
                     "(at most %.3g cell beside its centre)%s",
                     sky, 0.5 / sky,
                     shadow_lines ? ", cast shadows too where the run casts any" : "");
        snprintf(buf, sizeof buf, "box: cells as flat-topped columns%s%s%s",
                 done.box_sky_directions > 0
                     ? "; the sky view and horizons (SVF, openness, horizon rasters, sky terms, "
                       "Perez's band, stored horizons) by each cell's own ray (the box model "
                       "exactly), on every device and in bands"
                     : "",
                 lines,
                 done.box_march_steps > 0
                     ? "; exact cast shadows by each cell's own ray (proven bounds, else a "
                       "march), on every device and in bands"
                     : "");
    }
    ss_writer_metadata(w, "LINE_MODEL",
                       opt->lines == SS_LINES_DIGITAL
                           ? "digital: lines through cell centres, distance projected on the "
                             "azimuth"
                       : opt->lines == SS_LINES_BOX
                           ? buf
                           : "interpolated: samples on exact lines, heights and horizons "
                             "interpolated linearly across lines");
    if (opt->earth_radius_m > 0)
        snprintf(buf, sizeof buf, "on: R = %.0f m, refraction k = %.3f", opt->earth_radius_m,
                 opt->refraction_k);
    else
        snprintf(buf, sizeof buf, "off");
    ss_writer_metadata(w, "EARTH_CURVATURE", buf);
    /* Asking for the device's name opens it (OpenCL set-up, ~0.2 s on
     * PoCL): a run that swept nothing (plain hillshade) names none. */
    ss_writer_metadata(w, "DEVICE", done.sweeps > 0 ? ss_ctx_device_name(run->ctx)
                                    : done.box_sky_directions > 0 || done.box_march_steps > 0
                                        ? "the host: the box model by each cell's own ray (sky "
                                          "view, horizons or shadows)"
                                        : "none: no sweep was needed");
}

ss_status run_commit(run_state *run, ss_raster_writer *w)
{
    double t = run_now();
    ss_status st = ss_writer_commit(w, progress, run);
    run->phases.commit_s += run_now() - t;
    return st;
}

void run_print_phases(const run_state *run)
{
    if (run->quiet)
        return;
    const run_phases *p = &run->phases;
    double total = run_now() - run->started;
    ss_counters c = ss_ctx_counters(run->ctx);
    double rest = total - p->open_s - p->read_s - p->plan_s - c.build_seconds - c.sweep_seconds -
                  p->commit_s;
    /* The parts are disjoint intervals of the total: only rounding may take
     * the rest below 0, and a double count must show. */
    if (rest < 0.0 && rest > -1e-6)
        rest = 0.0;
    printf("phases  %.3f s since the command began: DEM opened %.3f s, heights read %.3f s, "
           "plan %.3f s, kernel build %.3f s, sweeps %.3f s, outputs finished %.3f s, the rest "
           "%.3f s (doc/performance.md)\n",
           total, p->open_s, p->read_s, p->plan_s, c.build_seconds, c.sweep_seconds, p->commit_s,
           rest);
}

void run_tally_add(run_tally *t, const float *v, size_t n)
{
    for (size_t i = 0; i < n; ++i) {
        if (v[i] == SS_NODATA)
            continue;
        t->lo = t->count && t->lo <= v[i] ? t->lo : v[i];
        t->hi = t->count && t->hi >= v[i] ? t->hi : v[i];
        t->sum += v[i];
        t->count++;
    }
}

void run_tally_result(const run_tally *t, double empty, double *min, double *mean, double *max)
{
    *min = t->count ? t->lo : empty;
    *max = t->count ? t->hi : empty;
    *mean = t->count ? t->sum / (double)t->count : empty;
}

void run_stats(const float *v, size_t n, double *min, double *mean, double *max)
{
    run_tally t = {0, 0, 0, 0};
    run_tally_add(&t, v, n);
    run_tally_result(&t, 0.0, min, mean, max);
}

void run_print_dem(run_state *run, const ss_dem *dem, const ss_dem_frame *frame)
{
    if (run->quiet)
        return;
    const ss_grid *g = &dem->grid;
    printf("input   %s: %d x %d cells of %.6g x %.6g m, %zu nodata\n", dem->description,
           g->width, g->height, g->cell_x_m, g->cell_y_m, dem->nodata_cells + dem->rejected_cells);
    if (dem->z_unit_m != 1.0 || strstr(dem->z_unit_source, "feet"))
        printf("heights %s, read as metres\n", dem->z_unit_source);
    static const char *const overlap_took[] = {"", "the first tile's height",
                                               "the last tile's height", "the tiles' mean"};
    if (dem->overlap_cells)
        printf("overlap %zu cells where tiles disagree took %s (--overlap)\n",
               dem->overlap_cells, overlap_took[dem->overlap_rule]);
    if (frame->georeferenced)
        printf("place   %.5f, %.5f (lon, lat); grid north %+.4f deg true; cell sizes vary by "
               "%.2g over the grid\n",
               frame->centre_lon_deg, frame->centre_lat_deg, frame->grid_north_deg,
               frame->cell_variation);
}

/* GDAL's "-projwin ULX ULY LRX LRY" takes four words; the option table
 * takes one: the four numbers are joined into "ULX,ULY,LRX,LRY" in place. */
static void join_projwin(int *argc, char **argv)
{
    static char joined[4 * 32];
    for (int i = 1; i + 4 < *argc; ++i) {
        if (strcmp(argv[i], "-projwin") != 0 && strcmp(argv[i], "--projwin") != 0)
            continue;
        int numbers = 1;
        for (int k = 1; k <= 4; ++k) {
            char *end;
            strtod(argv[i + k], &end);
            numbers &= end != argv[i + k] && *end == '\0';
        }
        if (!numbers || snprintf(joined, sizeof joined, "%s,%s,%s,%s", argv[i + 1], argv[i + 2],
                                 argv[i + 3], argv[i + 4]) >= (int)sizeof joined)
            return;
        argv[i + 1] = joined;
        for (int k = i + 2; k + 3 <= *argc; ++k)
            argv[k] = argv[k + 3];
        *argc -= 3;
        return;
    }
}

/* The files the command names (run_files.h): its file options by their
 * type, the scene, and its positionals, of which the last of two or more
 * is the output ("-": standard output). Kept until the next command. */
static ss_run_files named_files;

static int register_files(const opt_spec *const *tables, const void *settings,
                          const char *scene, const char **pos, int n_pos)
{
    int bad = scene ? ss_run_files_add(&named_files, scene, "--scene", 0) : 0;
    for (int t = 0; tables[t]; ++t)
        for (const opt_spec *s = tables[t]; s->name; ++s) {
            const char *path = (s->type == OPT_INPUT || s->type == OPT_OUTPUT)
                                   ? *(const char *const *)((const char *)settings + s->offset)
                                   : NULL;
            char label[40];
            snprintf(label, sizeof label, "%s%s", opt_dash(s->name), s->name);
            if (path && strcmp(path, "-") != 0)
                bad |= ss_run_files_add(&named_files, path, label, s->type == OPT_OUTPUT);
        }
    for (int i = 0; i < n_pos; ++i) {
        int output = n_pos > 1 && i == n_pos - 1;
        if (strcmp(pos[i], "-") != 0)
            bad |= ss_run_files_add(&named_files, pos[i], output ? "OUTPUT" : "input", output);
    }
    return bad;
}

/* Refuses, before any work, an output that is an input or another output. */
static int check_named_files(const char *command, const opt_spec *const *tables,
                             const void *settings, const char *scene, const char **pos, int n_pos)
{
    ss_run_files_clear(&named_files);
    if (register_files(tables, settings, scene, pos, n_pos) != 0) {
        fprintf(stderr, "skysweep %s: out of memory\n", command);
        return SS_ERR_MEMORY;
    }
    ss_ctx *ctx = ss_ctx_new();
    if (!ctx) {
        fprintf(stderr, "skysweep %s: out of memory\n", command);
        return SS_ERR_MEMORY;
    }
    ss_status st = ss_run_files_check(ctx, &named_files);
    if (st != SS_OK)
        fprintf(stderr, "skysweep %s: %s\n", command, ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st == SS_OK ? -1 : (int)st;
}

int run_parse(const char *command, const opt_spec *const *tables, void *settings, int argc,
              char **argv, const char **pos, int *n_pos, int max_pos, int min_pos,
              const char *usage, const char *summary, const char *const *device_setting)
{
    join_projwin(&argc, argv);
    if (opt_print_reference(tables, argc, argv, command, usage, summary, ss_version()))
        return 0;
    char err[512];
    char **scene_argv = NULL;
    int scene_argc, scene_at = scene_arg(argc, argv);
    const char *scene = scene_at >= 0 ? argv[scene_at + 1] : NULL;
    if (scene_expand(tables, argc, argv, &scene_argc, &scene_argv, err, sizeof err) != 0)
        return run_usage_error(command, err);
    if (scene_argv) { /* lives as long as the run: settings point into it */
        argc = scene_argc;
        argv = scene_argv;
    }
    int r = opt_parse(tables, settings, argc, argv, pos, n_pos, max_pos, err, sizeof err);
    if (r < 0)
        return run_usage_error(command, err);
    if (r > 0) {
        opt_print_help(tables, usage, summary);
        return 0;
    }
    /* Read after parsing: --device list prints the devices and stops. */
    if (device_setting && *device_setting && strcmp(*device_setting, "list") == 0)
        return command_list_devices();
    if (*n_pos < min_pos) {
        snprintf(err, sizeof err, "needs %s", min_pos > 1 ? "an input DEM and an output file"
                                                         : "an input");
        return run_usage_error(command, err);
    }
    return check_named_files(command, tables, settings, scene, pos, *n_pos);
}

static int open_job(sweep_job *job, const char *command, const common_settings *common,
                    const char **pos, int n_pos, const band_cost *cost)
{
    memset(job, 0, sizeof *job);
    int rc = run_begin(&job->run, command, common);
    if (rc)
        return rc;
    job->output = pos[n_pos - 1];
    job->inputs = pos;
    job->n_inputs = n_pos - 1;
    ss_status st = run_check_output(&job->run, job->output);
    if (st != SS_OK) {
        rc = run_fail(&job->run, st);
        run_end(&job->run);
        return rc;
    }
    if (cost)
        job->band = *cost;
    st = open_dem(&job->run, pos, job->n_inputs, common, cost, &job->dem, &job->source,
                  &job->band_rows);
    if (st == SS_OK) {
        st = ss_dem_frame_open(job->run.ctx, &job->dem, &job->frame);
        if (st != SS_OK) {
            ss_dem_source_close(job->source);
            job->source = NULL;
            ss_dem_free(&job->dem);
        } else {
            job->have_dem = 1; /* from here on job_close frees DEM, frame and source */
        }
        /* The memory plan opens the device, whose kernel build, counted
         * on its own, may fall in the opening. */
        job->run.phases.open_s = run_now() - job->run.started - job->run.phases.read_s -
                                 ss_ctx_counters(job->run.ctx).build_seconds;
    }
    if (st == SS_OK && common->projwin) {
        double w[4];
        char tail;
        if (sscanf(common->projwin, "%lf,%lf,%lf,%lf%c", &w[0], &w[1], &w[2], &w[3], &tail) != 4)
            st = ss_ctx_error(job->run.ctx, SS_ERR_ARGUMENT,
                              "-projwin expects ULX ULY LRX LRY, not '%s'", common->projwin);
        else
            st = ss_dem_set_window(job->run.ctx, &job->dem, w);
    }
    if (st == SS_OK && job->dem.rejected_cells && !job->run.quiet)
        fprintf(stderr,
                "skysweep %s: warning: %zu heights beyond +-1e7 m were taken as nodata\n",
                command, job->dem.rejected_cells);
    if (st == SS_OK) {
        run_sweep_options(common, &job->frame, &job->opt);
        st = ss_sweep_options_check(job->run.ctx, &job->opt);
    }
    if (st != SS_OK) {
        rc = job_finish(job, st);
        job_close(job);
        return rc;
    }
    return 0;
}

int job_open(sweep_job *job, const char *command, const common_settings *common,
             const char **pos, int n_pos)
{
    return open_job(job, command, common, pos, n_pos, NULL);
}

int job_open_banded(sweep_job *job, const char *command, const common_settings *common,
                    const char **pos, int n_pos, band_cost cost)
{
    return open_job(job, command, common, pos, n_pos, &cost);
}

ss_status job_open_output(sweep_job *job, int n_bands, const common_settings *common,
                          ss_raster_writer **w)
{
    *w = NULL;
    ss_status st = share_rank() == 0 ? ss_writer_open(job->run.ctx, job->output, &job->dem, n_bands,
                                                      common->format,
                                                      common->creation_options.items, w)
                                     : SS_OK;
    if (share_first_failure(st != SS_OK) >= 0 && st == SS_OK)
        st = ss_ctx_error(job->run.ctx, SS_ERR_OUTPUT, "rank 0 could not open the output");
    return st;
}

ss_status job_rows_reader(void *job, int row0, int n_rows, float *z)
{
    return job_read_rows(job, row0, n_rows, z);
}

int job_bands(const sweep_job *job)
{
    int h = job->dem.grid.height;
    return job->source ? (h + job->band_rows - 1) / job->band_rows : 1;
}

ss_source job_source(sweep_job *job, ss_band_stats *stats)
{
    const ss_grid *g = &job->dem.grid;
    ss_source src = {.width = g->width,
                     .height = g->height,
                     .cell_x_m = g->cell_x_m,
                     .cell_y_m = g->cell_y_m,
                     .z_origin_m = &g->z_origin_m,
                     .z = job->source ? NULL : g->z,
                     .read = job->source ? job_rows_reader : NULL,
                     .read_user = job,
                     .band_rows = job->source ? job->band_rows : 0,
                     .stats = stats};
    return src;
}

ss_status job_read_rows(sweep_job *job, int row0, int n_rows, float *z)
{
    ss_dem *dem = &job->dem;
    if (!job->rows_counted && !(job->rows_counted = calloc((size_t)dem->grid.height, 1)))
        return ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for a band");
    size_t nodata = dem->nodata_cells, rejected = dem->rejected_cells;
    double t = run_now();
    ss_status st = ss_dem_source_read(job->run.ctx, job->source, dem, row0, n_rows, z);
    job->run.phases.read_s += run_now() - t;
    /* Each row's cells without a height are counted once, all as nodata. */
    dem->nodata_cells = nodata;
    dem->rejected_cells = rejected;
    for (int r = 0; st == SS_OK && r < n_rows; ++r) {
        if (job->rows_counted[row0 + r])
            continue;
        job->rows_counted[row0 + r] = 1;
        for (int c = 0; c < dem->grid.width; ++c)
            dem->nodata_cells += !isfinite(z[(size_t)r * dem->grid.width + c]);
    }
    return st;
}

int job_finish(sweep_job *job, ss_status st)
{
    return st == SS_OK ? 0 : run_fail(&job->run, st);
}

void job_close(sweep_job *job)
{
    if (job->have_dem) {
        ss_dem_frame_close(&job->frame);
        ss_dem_source_close(job->source);
        job->source = NULL;
        ss_dem_free(&job->dem);
        job->have_dem = 0;
    }
    free(job->rows_counted);
    job->rows_counted = NULL;
    run_end(&job->run);
}
