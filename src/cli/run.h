/* What every CLI command shares: common options, signals, progress on
 * stderr, reading the DEM, writing an output with its metadata, and turning
 * a status into one line on stderr and an exit code. */
#ifndef SS_CLI_RUN_H
#define SS_CLI_RUN_H

#include "dem_io.h"
#include "options.h"
#include "skysweep.h"

typedef struct {
    int directions;
    double offset_deg;
    const char *device;
    int quiet;
    const char *format;
    opt_list creation_options;
    double cell_size_m;
    int curvature; /* 0 off, 1 on */
    double refraction_k;
    double earth_radius_m;
    int lines; /* index into "interpolated|digital" */
} common_settings;

/* The options every sweeping command takes; offsets are relative to a
 * common_settings placed at the start of the command's settings struct. */
extern const opt_spec common_options[];

typedef struct {
    const char *command;
    ss_ctx *ctx;
    int quiet;
    double started;
    int progress_shown;
} run_state;

/* Creates the context, installs SIGINT/SIGTERM handlers and progress. */
int run_begin(run_state *run, const char *command, const common_settings *common);
/* Prints "skysweep COMMAND: message" on stderr and returns the exit code:
 * the status, or 128 + signal when interrupted. */
int run_fail(run_state *run, ss_status status);
int run_usage_error(const char *command, const char *message);
void run_end(run_state *run);

ss_status run_read_dem(run_state *run, const char *const *paths, int n_paths,
                       const common_settings *common, ss_dem *dem);
void run_sweep_options(const common_settings *common, ss_sweep_options *opt);
/* Refuses an output that is also an input. */
ss_status run_check_output(run_state *run, const char *output, const char *const *inputs,
                           int n_inputs);
/* Metadata every output carries: version, device, directions, conventions. */
void run_common_metadata(run_state *run, ss_raster_writer *w, const ss_sweep_options *opt);
ss_status run_commit(run_state *run, ss_raster_writer *w);

/* min, mean and max over valid cells (value != SS_NODATA). */
void run_stats(const float *v, size_t n, double *min, double *mean, double *max);
void run_print_dem(run_state *run, const ss_dem *dem);

#endif
