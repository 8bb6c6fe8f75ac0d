/* What every CLI command shares: common options, signals, progress on
 * stderr, reading the DEM, writing an output with its metadata, and turning
 * a status into one line on stderr and an exit code. */
#ifndef SS_CLI_RUN_H
#define SS_CLI_RUN_H

#include "dem_io.h"
#include "frame.h"
#include "skysweep_sun.h"
#include "sun_field.h"
#include "options.h"
#include "skysweep.h"
#include "skysweep_params.h"
#include "skysweep_products.h"

typedef struct {
    /* The library's parameters every sweeping command takes
     * (skysweep_params.h: the "sweep" and "sun" tables). */
    ss_sweep_params sweep;
    ss_sun_params sun; /* commands that take sun_options */
    const char *device;
    int quiet;
    const char *format;
    opt_list creation_options;
    double cell_size_m;
    int heightmap; /* read the input through OpenImageIO (heightmap_input.h) */
    double z_scale; /* --heightmap: metres per pixel value */
    int z_units;    /* index into "auto|m|ft|us-ft": the stored heights' unit */
    int overlap;    /* index into "refuse|first|last|mean": an ss_overlap_rule (dem_io.h) */
    int plan_only, plan_json;
    const char *scene;
    const char *memory;    /* --memory SIZE: bound on the working set; NULL: half the RAM */
    const char *projwin;   /* "ULX,ULY,LRX,LRY": the outputs' window; NULL: the whole DEM */
} common_settings;

/* Marks the optional numbers as not given (NAN); call before parsing. */
void common_settings_init(common_settings *common);

/* The options every sweeping command takes: the library's "sweep" table
 * and the command line's own. Offsets are relative to a common_settings
 * placed at the start of the command's settings struct. */
const opt_spec *common_options(void);
/* The sun's position and the air that refracts it (the library's "sun"
 * table), for shadow, hillshade, insolation and render. */
const opt_spec *sun_options(void);

/* Where a command's time went, seconds since run_begin (run_print_phases). */
typedef struct {
    double open_s;   /* opening the DEM: GDAL, its CRS, the frame's geodesy */
    double read_s;   /* reading its heights, whole or band by band */
    double plan_s;   /* the effects planner (and the set-up of an OpenCL device it picks) */
    double commit_s; /* finishing the outputs: GDAL's flush (compression), checks, renaming */
} run_phases;

typedef struct {
    const char *command;
    ss_ctx *ctx;
    int quiet;
    int plan_only; /* the run plans and writes nothing */
    double started;
    run_phases phases;
    int progress_shown;
    int progress_lines;     /* SKYSWEEP_PROGRESS=lines: one "progress F" line per step */
    double progress_last;   /* the fraction last printed as a line */
    int progress_part, progress_parts; /* a run of several library calls: which one runs */
    char z_unit_source[200]; /* the DEM's height unit and where it came from (metadata) */
    double memory_bound;     /* --memory in bytes (0: none given), for the summary */
    const char *memory_asked; /* --memory as given (NULL: none) */
    ss_memory_plan memory;   /* the memory plan its bands and device buffers follow */
    ss_memory_need memory_need; /* what it was made from (width 0: none was made) */
    char memory_device[128];    /* the device it was made for ("": none opened) */
    double memory_choosing;     /* what --device auto's choosing added to the process, bytes */
    int device_auto;            /* --device auto: the effects plan picks the device */
} run_state;

/* A run made of `parts` library calls, each reporting its progress from 0
 * to 1: the fraction shown goes on from call to call (part 0 of 1: the
 * whole). */
void run_progress_part(run_state *run, int part, int parts);

/* Parses a command's options and positionals; handles --help and
 * --device list. Returns -1 to go on, else the exit code to return. */
int run_parse(const char *command, const opt_spec *const *tables, void *settings, int argc,
              char **argv, const char **pos, int *n_pos, int max_pos, int min_pos,
              const char *usage, const char *summary, const char *const *device_setting);

/* Creates the context, installs the handlers of SIGINT, SIGTERM, SIGHUP and
 * SIGPIPE (each stops the run, stop_guard.h) and progress. */
int run_begin(run_state *run, const char *command, const common_settings *common);
/* Prints "skysweep COMMAND: message" on stderr and returns the exit code:
 * the status, or 128 + signal when interrupted. */
int run_fail(run_state *run, ss_status status);
/* Whether a signal stopped the run (its exit status is then 128 + N). */
int run_interrupted(void);
int run_usage_error(const char *command, const char *message);
void run_end(run_state *run);

/* Reads the DEM and opens its frame (ground cell sizes, true north). */
ss_status run_read_dem(run_state *run, const char *const *paths, int n_paths,
                       const common_settings *common, ss_dem *dem, ss_dem_frame *frame);
/* The line model asked for: SS_LINES_AUTO leaves it to the planner. */
ss_line_model run_lines_asked(const common_settings *common);
/* Bytes per cell of the whole grid that cast shadows by each cell's own
 * ray hold beside a run's bands (the heights, held whole: a ray reads
 * columns anywhere toward the sun): box lines asked for (a banded DEM is
 * not searched for walls, so only --lines box gives them there) without
 * --box-shadows lines; else 0. A grid held whole holds them anyway. */
double run_march_cell_bytes(const common_settings *common);
/* The same for the box model's sky view by each cell's own ray (svf,
 * openness, and the sky terms of hillshade and insolation): --lines box
 * without --box-sky lines; else 0. */
double run_box_sky_cell_bytes(const common_settings *common);
/* The frame's place, for the planner (ss_place). */
ss_place run_place(const common_settings *common, const ss_dem_frame *frame);
/* The sweep options the parameters ask for before a plan decides
 * (ss_sweep_params_options at the frame's place). */
void run_sweep_options(const common_settings *common, const ss_dem_frame *frame,
                       ss_sweep_options *opt);
double run_earth_radius(const common_settings *common, const ss_dem_frame *frame);
/* Refuses (unless the run only plans) an output that cannot be written
 * there (ss_output_check), recording why in the run's context. That no
 * output is an input or another output, run_parse has checked for every
 * file the command names (src/adapt/run_files.h). */
ss_status run_check_output(run_state *run, const char *output);
/* Metadata every output carries: version, device, directions, conventions. */
void run_common_metadata(run_state *run, ss_raster_writer *w, const ss_sweep_options *opt,
                         const ss_dem_frame *frame);
ss_status run_commit(run_state *run, ss_raster_writer *w);
/* Seconds on a monotonic clock. */
double run_now(void);
/* Prints the summary's "phases" line: the command's seconds so far, split
 * into run_phases, the sweeps (the context's counters) and the rest. */
void run_print_phases(const run_state *run);

/* What a banded sweep holds: bytes per cell of a band (halo rows
 * included), and per column and direction besides (hulls handed on are
 * estimated from the directions). */
typedef struct {
    double cell_bytes, column_bytes;
    int directions; /* swept at once; 0: those of --directions */
    /* Held beyond a band's two halo rows on each side (radius walks):
     * metres, and cells. */
    double halo_m, halo_cells;
    /* Held per cell by a whole-grid run's outputs until they are written
     * (horizon's planes of every direction), beyond cell_bytes. */
    double output_bytes;
    int no_sweep; /* sweeps nothing (a plain hillshade): opens no device */
    /* Plans its sweeps only after other work (roofs' shade table): a budget
     * too small is refused at the DEM's opening, under --device auto too. */
    int plans_late;
    /* Held per cell of the whole grid beside the bands (svf's trees). */
    double grid_cell_bytes;
    /* Lines per column whose hulls are handed on between bands; 0: the
     * directions swept at once times the most box lines per cell asked. */
    int hull_lines;
} band_cost;

/* A sweeping command's input side: the output named last, the DEM tiles
 * before it, the DEM with its frame, and the sweep options. */
typedef struct {
    run_state run;
    const char *output;
    const char *const *inputs;
    int n_inputs;
    ss_dem dem;
    ss_dem_frame frame;
    ss_sweep_options opt;
    int have_dem;
    ss_plan plan;
    /* A banded job (job_open_banded): the DEM stays in its files, dem.grid.z
     * is NULL, and the sweep reads band_rows rows at a time. */
    ss_dem_source *source;
    int band_rows;
    band_cost band; /* what a band holds, for its size and the summary */
    unsigned char *rows_counted; /* rows whose nodata cells are counted (bands reread rows) */
    ss_plan_weather weather;          /* insolation from weather records (the plan says so) */
} sweep_job;

/* Starts the run, refuses an output that is an input, reads the DEM and its
 * frame, and builds and checks the sweep options. Returns 0, or the exit
 * code after printing the error (the job is then closed). */
int job_open(sweep_job *job, const char *command, const common_settings *common,
             const char **pos, int n_pos);
/* The same for any banded product, with what its bands hold. */
int job_open_banded(sweep_job *job, const char *command, const common_settings *common,
                    const char **pos, int n_pos, band_cost cost);
/* The sun for the job (job_sun.c): given, or from --time by SPA at the DEM,
 * for one instant; one sun for the DEM or per cell. */
ss_status job_sun(sweep_job *job, const common_settings *common, ss_sun_field *field);
/* Plans the run of a registry product with its own parameters (params:
 * the struct of its table, NULL where it has none) and its time steps
 * (may be none) through the library's one translation
 * (ss_product_prepare), which sets the job's options from the plan;
 * prints the plan unless quiet. Returns -1 to go on, else the exit code
 * (0 after --plan). */
int job_plan(sweep_job *job, const common_settings *common, const ss_product_info *product,
             const void *params, int n_steps, const double *step_unix_s);
/* What the process holds before --device auto's plan opens its device ... */
typedef struct {
    double resident, peak;
} memory_mark;
memory_mark job_memory_mark(void);
/* ... and the job's memory planned again for the device the plan opened
 * (job_plan), what the process grew by since `before` held beside the
 * rest: the DEM was opened and its bands planned on the C twin, before
 * the device was chosen. A banded DEM takes the new band rows; where the
 * device leaves no room within the budget (not one band, or a DEM already
 * held whole that would need bands beside it) the C twin runs, and a line
 * on stderr says so; SS_ERR_MEMORY where even the C twin has no room left
 * beside what choosing loaded, or where the DEM's opening found the budget
 * too small for one band (open_dem_file leaves that to here under auto),
 * naming the least budget with which auto, choosing again, runs. */
ss_status job_memory_replan(sweep_job *job, memory_mark before);
/* Opens the job's output of n_bands bands on rank 0 (the one that writes,
 * alone or under mpirun), before the run so that it fails early; the other
 * ranks leave *w NULL. Every rank learns whether rank 0 failed. */
ss_status job_open_output(sweep_job *job, int n_bands, const common_settings *common,
                          ss_raster_writer **w);
/* The plan as JSON into an output's metadata (PLAN). */
void job_plan_metadata(sweep_job *job, ss_raster_writer *w);
/* The job's DEM for the library's row-wise calls: held whole, or read band
 * by band from its files (stats: the hulls handed on, may be NULL). */
ss_source job_source(sweep_job *job, ss_band_stats *stats);
/* How many bands the job's DEM is swept in (1: held whole). */
int job_bands(const sweep_job *job);
/* Reads rows of a banded job's DEM (NaN at nodata), counting each row's
 * cells without a height once however often the row is read. */
ss_status job_read_rows(sweep_job *job, int row0, int n_rows, float *z);
/* job_read_rows as an ss_rows_read, for callbacks whose user is the job. */
ss_status job_rows_reader(void *job, int row0, int n_rows, float *z);
/* Prints the failure (if st is not SS_OK) and returns the exit code. */
int job_finish(sweep_job *job, ss_status st);
void job_close(sweep_job *job);

/* min, mean and max over valid cells (value != SS_NODATA). */
void run_stats(const float *v, size_t n, double *min, double *mean, double *max);
/* The same added up a band of rows at a time (start from all zeros);
 * empty is what a tally of no valid cell gives. */
typedef struct {
    double lo, hi, sum;
    size_t count;
} run_tally;
void run_tally_add(run_tally *t, const float *v, size_t n);
void run_tally_result(const run_tally *t, double empty, double *min, double *mean, double *max);
void run_print_dem(run_state *run, const ss_dem *dem, const ss_dem_frame *frame);

#endif
