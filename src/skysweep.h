/* skysweep: exact terrain horizons, sky-view factor and their products.
 *
 * The library does the work and never prints or exits: every call returns an
 * ss_status, and the one-line message of the last failure is kept in the
 * context the caller owns (ss_ctx_message). Conventions used throughout:
 *   - rows run north to south, columns west to east, cell (0,0) is north-west;
 *   - azimuths are degrees clockwise from north (0 = N, 90 = E): true north
 *     when the caller gives grid_north_deg (ss_sweep_options), else grid
 *     north (up the grid's columns);
 *   - horizon elevation angles are degrees above the local horizontal and may
 *     be negative; -90 means no terrain lies ahead inside the grid;
 *   - distances are metres along the azimuth;
 *   - outputs hold SS_NODATA where the input is nodata, and never NaN or Inf.
 * The sun's position is in skysweep_sun.h, site horizons in skysweep_sites.h.
 */
#ifndef SKYSWEEP_H
#define SKYSWEEP_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* What the library exports: it is built with -fvisibility=hidden, so that
 * only these calls are its interface. */
#if defined(__GNUC__) && !defined(SS_API)
#define SS_API __attribute__((visibility("default")))
#elif !defined(SS_API)
#define SS_API
#endif

#define SS_NODATA (-9999.0f)
/* The earth's mean radius (IUGG R1), metres: curvature where a DEM gives no place. */
#define SS_EARTH_RADIUS_MEAN_M 6371008.8

/* Status codes double as the CLI's exit codes (doc/cli.md). */
typedef enum {
    SS_OK = 0,
    SS_ERR_ARGUMENT = 2,  /* an option or parameter is out of range */
    SS_ERR_INPUT = 3,     /* the input cannot be read or is not a usable DEM */
    SS_ERR_OUTPUT = 4,    /* an output cannot be written */
    SS_ERR_DEVICE = 5,    /* no usable OpenCL device, or the kernels failed to build */
    SS_ERR_MEMORY = 6,    /* an allocation failed or would exceed a limit */
    SS_ERR_CANCELLED = 7, /* the progress callback or ss_ctx_cancel asked to stop */
    SS_ERR_INTERNAL = 8   /* a bug: please report it */
} ss_status;

typedef struct ss_ctx ss_ctx;

/* Same shape as GDALProgressFunc: return 0 to cancel the run. */
typedef int (*ss_progress_fn)(double complete, const char *message, void *user);

SS_API ss_ctx *ss_ctx_new(void);
SS_API void ss_ctx_free(ss_ctx *ctx);
/* The one-line message of the last call's failure: each call that can fail
 * clears it as it begins, so after a call that returned SS_OK it is empty
 * (or says what a fallback recovered from). Every call leaves the context
 * usable after a failure of any kind. */
SS_API const char *ss_ctx_message(const ss_ctx *ctx);
/* Records a failure of the caller's own in the context (one line, printf
 * format) and returns status, so callers report theirs like the library's. */
SS_API ss_status ss_ctx_error(ss_ctx *ctx, ss_status status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
SS_API void ss_ctx_set_progress(ss_ctx *ctx, ss_progress_fn fn, void *user);
/* Asks the call running on ctx to stop: it returns SS_ERR_CANCELLED within
 * about two directions' sweeps (the C twin checks between lines, an OpenCL
 * device keeps at most one pass queued behind the running one). It only
 * sets a flag, so a signal handler or another thread may call it. The
 * request holds for every later call until ss_ctx_cancel_clear. */
SS_API void ss_ctx_cancel(ss_ctx *ctx);
SS_API void ss_ctx_cancel_clear(ss_ctx *ctx);
SS_API const char *ss_version(void);

/* Devices. spec NULL or "" picks the default: the environment variable
 * SKYSWEEP_DEVICE where set (same forms as spec), else the first CPU device
 * of a PoCL platform, else the first device found; "reference" runs the plain C
 * twin of the kernels; "auto" lets each job's plan choose (ss_plan_make's
 * "device" item, applied by ss_ctx_apply_plan; the C twin until then);
 * anything else is "P:D" (platform and device numbers) or a
 * case-insensitive part of "platform name: device name". */
SS_API ss_status ss_ctx_use_device(ss_ctx *ctx, const char *spec);
/* Directions walked at once on a device (one launch per batch of them and
 * band): 0, the default, chooses from the device's memory; the C twin walks
 * a batch one direction after the other, so it gives the same result at
 * any batch. */
SS_API void ss_ctx_set_batch(ss_ctx *ctx, int directions);
/* Where insolation's per-cell work after each step's sweep runs on an
 * OpenCL device: SS_CELLS_AUTO, the default, on a GPU (the horizons then
 * never leave it) and on the host for a CPU device (whose memory is the
 * host's, and whose kernels are slower than the host's SIMD lanes,
 * doc/gpu.md); SS_CELLS_HOST or SS_CELLS_DEVICE to choose. The C twin
 * always runs it on the host. A new context takes the environment's
 * SKYSWEEP_CELLS ("host", "device"; else auto). */
typedef enum { SS_CELLS_AUTO, SS_CELLS_HOST, SS_CELLS_DEVICE } ss_cells_where;
SS_API void ss_ctx_set_cells(ss_ctx *ctx, ss_cells_where where);
/* Human-readable name of the selected device, opening it if needed. */
SS_API const char *ss_ctx_device_name(ss_ctx *ctx);
/* Lists the OpenCL devices, one "P:D platform: device (OpenCL C x.y)" line
 * each, into buf. Returns the number of devices (0 when none). */
SS_API int ss_list_devices(ss_ctx *ctx, char *buf, size_t buf_size);

/* Work counters since the context was made: products report what they did,
 * and tests check that work planned away really was skipped. */
typedef struct {
    uint64_t sweeps;      /* directions swept */
    uint64_t cells_swept; /* cells x directions */
    double sweep_seconds; /* wall time inside sweeps, kernel build excluded */
    double build_seconds; /* kernel program build (cached or not) */
    uint64_t time_steps;            /* daylight time steps evaluated */
    uint64_t night_steps_skipped;   /* steps with the sun below every cell's horizontal */
    uint64_t shadow_sweeps_skipped; /* steps with the sun above every possible horizon */
    /* Weather records: missing (adding nothing), split from GHI alone
     * (Erbs), DNI from GHI and DHI (closure), with beam on the horizontal
     * above the global (used as given), with beam or diffuse while the
     * sun is below the horizontal (adding nothing), and with the file's DNI
     * above the extraterrestrial (adding nothing). */
    uint64_t records_missing, records_split, records_dni_from_closure, records_beam_above_global,
        records_light_at_night, records_dni_above_extraterrestrial;
    uint64_t records_without_temperature; /* PV yield: the options' air temperature or wind used */
    uint64_t sun_bins; /* the cumulative sky's occupied bins of suns */
    /* Insolation's cells x daylight steps, and of them those whose sun's
     * terms were computed per cell, outside the step's tables (suns spread
     * too wide for them, air masses past r.sun's Rayleigh split at 20) or,
     * for weather records, more than 0.5 rad from the centre's sun
     * (doc/insolation.md). */
    uint64_t cell_steps, cell_steps_exact_sun;
    /* Samples of the exact shadow walks that per-cell horizon bounds could
     * stop early, and of them those left unwalked: past the last cell of
     * their line whose bound the sun may not clear. */
    uint64_t shadow_steps, shadow_steps_skipped;
    /* Weather records with neither beam nor circumsolar light, on which
     * shadows change nothing: no shadow sweep (nor stored horizons) for them. */
    uint64_t shadow_sweeps_unshaded;
    /* Of cell_steps, those an OpenCL device computed (ss_ctx_set_cells):
     * every cell with a height, of every step it took. */
    uint64_t cell_steps_on_device;
    /* Exact shadows on box lines by each cell's own ray (box_shadows
     * march): the steps, their cells with a height, and of those the
     * cells the proven bounds left to the march. */
    uint64_t box_march_steps, box_march_cells, box_march_marched;
    /* Crowns crossed on box lines by each cell's own ray (box_shadows
     * march): the suns, their cells with a height, and of those the cells
     * the proven bound left to the march. */
    uint64_t crown_march_steps, crown_march_cells, crown_march_marched;
    /* Directions of the box model's sky view or horizons (horizon
     * rasters, Perez's band, stored horizons) by each cell's own ray
     * (box_sky march), on the host; cells_swept counts their cells. */
    uint64_t box_sky_directions;
} ss_counters;
SS_API ss_counters ss_ctx_counters(const ss_ctx *ctx);

/* A DEM in memory. Heights are float32 relative to z_origin_m so that large
 * offsets (a plateau at 1e5 m) keep their float precision. */
typedef struct {
    int width, height;
    double cell_x_m, cell_y_m; /* cell size east-west and north-south, metres */
    double z_origin_m;         /* height of the stored zero, metres */
    float *z;                  /* width*height heights, NAN = nodata */
} ss_grid;

/* Allocates z (filled with NAN) for a width x height grid. */
SS_API ss_status ss_grid_alloc(ss_ctx *ctx, ss_grid *grid, int width, int height, double cell_x_m,
                        double cell_y_m);
SS_API void ss_grid_free(ss_grid *grid);
/* Heights beyond +-this many metres are not terrain: readers store them as
 * nodata (and count them). */
#define SS_Z_PLAUSIBLE_M 1e7
/* The stored form of height_m (metres) in a grid: relative to z_origin_m,
 * which the first plausible height sets, rounded to the metre (*have_origin
 * 0 on entry to a grid, 1 after), so that large offsets keep their float
 * precision. NAN for nodata: a height that is NaN, infinite or beyond
 * SS_Z_PLAUSIBLE_M. The GDAL reader and the front ends fill grids through it
 * (heightmaps keep origin 0: their heights are pixel values times a scale). */
SS_API float ss_grid_stored_height(ss_grid *grid, int *have_origin, double height_m);
/* Fills a grid from ss_grid_alloc with width*height heights in metres (row
 * by row from the north-west cell) through ss_grid_stored_height; *rejected
 * (may be NULL) counts the finite heights beyond SS_Z_PLAUSIBLE_M. */
SS_API void ss_grid_set_heights(ss_grid *grid, const double *heights_m, size_t *rejected);
/* Checks that a grid can be swept: sizes, cell sizes, at least one valid
 * height; a 1x1 grid has no horizon and is refused. *valid_cells may be NULL. */
SS_API ss_status ss_grid_check(ss_ctx *ctx, const ss_grid *grid, size_t *valid_cells);

/* How lines sample the grid (doc/model.md). The values are part of the
 * kernel interface (kernels/ss_lines.h). */
typedef enum {
    SS_LINES_AUTO = -1,         /* plan requests only: the planner chooses (walls: box) */
    SS_LINES_INTERPOLATED = 0,  /* samples on exact lines, interpolated across them (default) */
    SS_LINES_DIGITAL = 1,  /* digital lines through cell centres */
    SS_LINES_BOX = 2       /* cells as flat-topped columns: city DSMs with vertical walls */
} ss_line_model;

typedef enum { SS_BOX_SHADOWS_MARCH = 0, SS_BOX_SHADOWS_LINES = 1 } ss_box_shadows;
typedef enum { SS_BOX_SKY_MARCH = 0, SS_BOX_SKY_LINES = 1 } ss_box_sky;

typedef struct {
    int directions;        /* D >= 1, evenly spaced */
    double offset_deg;     /* azimuth of the first direction */
    double earth_radius_m; /* for earth curvature; 0 switches curvature off */
    double refraction_k;   /* terrestrial refraction coefficient, 0 <= k < 1 */
    ss_line_model lines;
    /* True azimuth of the grid's north (meridian convergence): directions are
     * given in true azimuths and swept at true - grid_north_deg. 0: the grid
     * frame is taken as true. */
    double grid_north_deg;
    /* SS_LINES_BOX: lines per cell across (a power of two, 1 to
     * SS_BOX_LINES_MAX); a cell takes the nearest, at most half a spacing
     * beside its centre (doc/model.md, "City DSMs"). */
    int box_lines;
    /* SS_LINES_BOX's cast shadows (shadow, hillshade's cast shadows,
     * insolation's exact steps): each cell's own ray, settled by proven
     * bounds or marched, on the host for every device and band height (in
     * bands from the heights held whole, ss_source_heights; horizon angles
     * follow box_sky), or the box_lines families' walks (doc/box_lines.md). */
    ss_box_shadows box_shadows;
    /* SS_LINES_BOX: lines per cell for insolation's sky view where its exact
     * shadows take none from them (0: box_lines; the planner's choice,
     * doc/planner.md). */
    int sky_box_lines;
    /* SS_LINES_BOX's sky view and horizons (SVF, openness, horizon angles,
     * the sky terms of hillshade and insolation, Perez's band and stored
     * horizons; not radius-limited): each cell's own ray, the box model
     * exactly, on the host for every device and band height (in bands from
     * the heights held whole), or the box_lines (or sky_box_lines)
     * families' walks (doc/model.md, "The sky view: each cell's own ray",
     * "The horizons: each cell's own ray"). */
    ss_box_sky box_sky;
} ss_sweep_options;

#define SS_BOX_LINES_MAX 64
#define SS_BOX_LINES_DEFAULT 32

SS_API void ss_sweep_options_default(ss_sweep_options *opt);
/* "interpolated", "digital" or "box": the --lines word. */
SS_API const char *ss_line_model_name(ss_line_model lines);
SS_API ss_status ss_sweep_options_check(ss_ctx *ctx, const ss_sweep_options *opt);
/* Azimuth of direction i (in the frame of the options), degrees in [0, 360). */
SS_API double ss_direction_azimuth(const ss_sweep_options *opt, int i);

typedef enum {
    SS_SVF_DEF_GEOMETRIC = 0,  /* 1 - mean sin h+ (Zaksek et al. 2011, RVT) */
    SS_SVF_DEF_HORIZONTAL = 1, /* mean cos^2 h+: radiative, horizontal surface */
    SS_SVF_DEF_RADIATIVE = 2   /* Dozier & Frew 1990: radiative, the cell's own slope (the
                                  --definition choice "radiative"; the kernels' tilted term) */
} ss_svf_definition;

/* Sky-view factor of every cell into out (width*height, SS_NODATA at nodata). */
SS_API ss_status ss_svf(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                 ss_svf_definition definition, float *out);
/* The same from horizons within radius_m only (0: unlimited, as ss_svf);
 * geometric or horizontal definitions. */
SS_API ss_status ss_svf_within(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                        ss_svf_definition definition, double radius_m, float *out);

/* Topographic openness (Yokoyama et al. 2002), degrees: positive (negative
 * nonzero: the openness of the inverted surface), from horizons at
 * unlimited distance, or within radius_m when it is > 0. A flat plane
 * gives 90. SS_NODATA at nodata. */
SS_API ss_status ss_openness(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                      int negative, double radius_m, float *out);

/* ---- one driver for every DEM size ---------------------------------------- */

/* Reads rows [row0, row0 + n_rows) of the DEM, all columns, into z (NaN at
 * nodata); returns SS_OK or a status (with a message in the context). */
typedef ss_status (*ss_rows_read)(void *user, int row0, int n_rows, float *z);

/* What a run in bands handed on between bands. */
typedef struct {
    size_t handoffs;              /* a line's hull handed to the next band */
    size_t hull_points_handed_on; /* summed over the handoffs */
    size_t max_hull_points;       /* the largest hull handed on */
} ss_band_stats;

/* A DEM for the row-wise calls (ss_*_rows): held whole (z), or read band by
 * band through read, for a DEM larger than memory. Every product runs
 * through one driver that walks the DEM in bands of band_rows rows on the
 * context's device, handing each line's hull on exactly from band to band;
 * the whole grid is the case of one band. Any band height gives the whole
 * grid's answer, up to the order of float additions over directions. */
typedef struct {
    int width, height;
    double cell_x_m, cell_y_m; /* ground cell sizes, metres */
    /* The height of the stored zero, metres (NULL: 0), read when needed, so
     * that a reader may set it with the first heights it reads. */
    const double *z_origin_m;
    const float *z;            /* width*height heights (NaN at nodata), or NULL: */
    ss_rows_read read;         /* ... the rows are read through this */
    void *read_user;
    int band_rows;             /* rows per band; 0: the whole grid in one band */
    ss_band_stats *stats;      /* over the whole call, filled in as it runs; may be NULL */
} ss_source;

/* A source's heights, whole: its own where it holds them (*owned NULL),
 * else read a band's rows at a time into *owned (width * height floats),
 * which the caller frees; NaN at nodata, an infinite height included (a
 * copy into *owned where the source's own hold one). For work that reads
 * rows anywhere (box shadows and sky view by each cell's own ray, whose
 * comparisons would meet an infinite top as a wall). Refuses a DEM without
 * a valid height; Ctrl-C (ss_ctx_cancel) stops it between bands. */
SS_API ss_status ss_source_heights(ss_ctx *ctx, const ss_source *src, float **owned,
                                   const float **z);

/* Receives finished rows [row0, row0 + n_rows) of one output of a row-wise
 * product: `output` says which (the product's SS_OUT_* values), `index`
 * which band of it (a direction, a month, a time step; 0 for outputs of one
 * band). Every (output, index) receives each row once, band by band.
 * Values are SS_NODATA at nodata. */
typedef ss_status (*ss_rows_sink)(void *user, int output, int index, int row0, int n_rows,
                                  const float *values);

/* Adds up the per-cell sums of a band (n floats) over the processes that
 * share a run (MPI: src/cli/mpi_share.c), in place, before they are
 * finished; every process calls it once per band, in the same order. */
typedef ss_status (*ss_rows_reduce)(void *user, float *sums, size_t n);

/* A run shared between processes: this one takes the directions (or time
 * steps) first, first + stride, ..., and its band sums meet the others'
 * through reduce. NULL, or {0, 1, NULL, NULL}: the whole run. */
typedef struct {
    int first, stride;
    ss_rows_reduce reduce;
    void *user;
} ss_share;

/* ---- memory: one planner (doc/engine.md) ------------------------------------ */

/* What a run costs, for ss_memory_plan_make. */
typedef struct {
    double budget_bytes;     /* the bound on the whole process's peak resident memory */
    double baseline_bytes;   /* resident now: the program, its libraries, GDAL, the device */
    double peak_bytes;       /* the process's peak so far (a device's kernel build); 0: none */
    int width, height;       /* the grid */
    double cell_bytes;       /* held per cell of a band, halo rows included */
    double whole_cell_bytes; /* held per cell swept whole (at least cell_bytes and 24) */
    double column_bytes;     /* per column and hull line carried between bands */
    int hull_lines;          /* lines per column and band edge handing hulls on: directions
                                (times box lines per cell) */
    int halo_rows;           /* rows held on each side beyond the sweep's own (radius walks) */
    double cache_bytes;      /* GDAL's block cache, as capped */
    double grid_cell_bytes;  /* held per cell of the whole grid beside the sweep's own
                                (svf's trees); 0: none */
    double device_memory_bytes; /* a device's own memory to plan against, less than a GPU's
                                   (CL_DEVICE_GLOBAL_MEM_SIZE, which the plan takes by itself),
                                   or simulated where the device is the host's or the C twin
                                   (tests); 0: the context's GPU's, none for other devices */
} ss_memory_need;

/* The plan: band rows, and what the device's buffers may take. */
typedef struct {
    int band_rows;        /* 0: the whole grid at once; -1: the budget is too small */
    double least_budget;  /* the least budget_bytes that would do */
    double planned_bytes; /* the peak the plan expects */
    double hull_bytes;    /* the allowance for the hulls handed on between bands */
    double device_bytes;  /* what the device's batch of directions' buffers may take (a CPU
                             device's: host memory); 0: a quarter of the device's memory */
    double device_cells_bytes; /* what its cells' buffers may take; 0: as device_bytes */
    double device_memory;  /* the device's own memory planned against; 0: none (the C twin, a
                              CPU device: host memory, within budget_bytes) */
    double device_planned; /* the bytes of the device's own memory the plan expects */
    double device_least;   /* the least device memory one band would do with; band_rows is
                              -1 where device_memory is less */
} ss_memory_plan;

/* Plans a run within need->budget_bytes on ctx's device (opened, so that
 * its buffers are counted where they are host memory); the context keeps
 * the plan for its device's batch and cells. */
SS_API ss_status ss_memory_plan_make(ss_ctx *ctx, const ss_memory_need *need,
                                     ss_memory_plan *plan);

/* The bytes a banded sweep holds for its bands (the hulls handed on come
 * on top; ss_band_stats counts them). */
SS_API size_t ss_band_bytes(int width, int band_rows);
/* About what a whole-grid SVF or openness run needs, buffers included. */
SS_API double ss_whole_sweep_bytes(int width, int height);
/* Rows per band for a run within budget_bytes: 0 when the whole grid fits,
 * -1 when not even one band does (directions 0: not known yet). */
SS_API int ss_band_rows_for(int width, int height, int directions, double budget_bytes);
/* The same for any banded run: band_cell_bytes held per cell of a band
 * (halo rows included), column_bytes per column and direction besides. The
 * whole grid, one band of all rows, holds band_cell_bytes a cell too (at
 * least ss_whole_sweep_bytes' 24). */
SS_API int ss_band_rows_within(int width, int height, int directions, double budget_bytes,
                        double band_cell_bytes, double column_bytes);
/* The smallest budget_bytes with which ss_band_rows_within does not refuse
 * (returns 0 or more): one band of one row, or the whole grid if less. */
SS_API double ss_band_min_budget(int width, int height, int directions, double band_cell_bytes,
                          double column_bytes);

/* ---- sky-view factor and openness, in rows ---------------------------------- */

/* SVF and openness are means over the directions of a per-direction term;
 * processes that share the directions add their sums, then finish. */
typedef enum {
    SS_SKY_SVF_GEOMETRIC = 0, /* the values match ss_svf_definition */
    SS_SKY_SVF_HORIZONTAL = 1,
    SS_SKY_SVF_RADIATIVE = 2,
    SS_SKY_OPENNESS_POSITIVE = 3,
    SS_SKY_OPENNESS_NEGATIVE = 4
} ss_sky_term;

/* Checks a term and a radius (0: unlimited). */
SS_API ss_status ss_sky_check(ss_ctx *ctx, ss_sky_term term, double radius_m);
/* The product from the sum over all `directions`. */
SS_API float ss_sky_value(ss_sky_term term, float sum, int directions);
/* Bytes a banded sweep of term holds per cell of a band (halo rows
 * included): heights, stack slots, sums, and the radiative SVF's surface
 * gradients. */
SS_API double ss_sky_band_cell_bytes(ss_sky_term term);

/* The sky product of term (as ss_svf and ss_openness) of every cell of
 * src, from horizons at unlimited distance or within radius_m (> 0), into
 * output 0 of sink (index 0). share (may be NULL) deals out the directions. */
#define SS_OUT_SKY 0
SS_API ss_status ss_sky_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                      ss_sky_term term, double radius_m, const ss_share *share,
                      ss_rows_sink sink, void *user);

/* ---- horizons, in rows -------------------------------------------------------- */

/* What ss_horizon gives besides the angles (bits of its `want`). */
#define SS_HORIZON_DISTANCE 1    /* metres to the horizon-casting point, 0: none */
#define SS_HORIZON_CAST_HEIGHT 2 /* that point's ground height, metres (z_origin_m
                                    included), SS_NODATA where none */
/* Outputs of ss_horizon_rows, each with one band per direction (index). */
#define SS_OUT_HORIZON_ANGLE 0       /* degrees; -90 where no terrain lies ahead */
#define SS_OUT_HORIZON_DISTANCE 1    /* with SS_HORIZON_DISTANCE */
#define SS_OUT_HORIZON_CAST_HEIGHT 2 /* with SS_HORIZON_CAST_HEIGHT */

/* Every direction's horizon as ss_horizon computes it, for src. */
SS_API ss_status ss_horizon_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                          int want, ss_rows_sink sink, void *user);
/* What a banded horizon run holds, with `want` as in ss_horizon: bytes per
 * cell of a band (ss_band_rows_within's band_cell_bytes), and bytes per
 * column and direction for the rows of sums carried between bands. */
SS_API double ss_horizon_band_cell_bytes(int want);
/* Bytes per cell a line model adds to a band's (box lines: more hull slots). */
SS_API double ss_lines_extra_cell_bytes(ss_line_model lines);
/* Bytes per cell a walk within radius_m adds to a band's where it takes
 * hulls (their stack slots hold whole hull points; shorter radii are
 * scanned and add none). Cell sizes not finite: counted. */
SS_API double ss_radius_extra_cell_bytes(double radius_m, double cell_x_m, double cell_y_m);
SS_API double ss_horizon_column_bytes(void);

/* RVT's VAT relief blend (Kokalj & Somrak 2019) of one cell, 0..1 (1 =
 * white): hillshade 0..1 (cosine of incidence), slope in degrees, positive
 * openness in degrees, geometric SVF. src/core/relief_blend.c gives the
 * recipe. */
SS_API float ss_vat_compose(float hillshade, float slope_deg, float openness_deg, float svf);
/* The VAT blend of every cell (0..1, SS_NODATA at nodata): gdaldem's
 * hillshade at 315/35 deg, Horn's slope, and SVF and positive openness from
 * horizons within radius_m (0: unlimited). */
SS_API ss_status ss_vat(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt, double radius_m,
                 float *out);

/* Receives the horizon of every cell for one direction; dist_m and
 * cast_height_m are NULL unless asked for. The caster of a cell is that of
 * its nearer sample with terrain ahead (doc/model.md, Edges). Return 0 to
 * stop the run (it then ends with SS_ERR_CANCELLED). */
typedef int (*ss_horizon_sink)(int index, double azimuth_deg, const float *angle_deg,
                               const float *dist_m, const float *cast_height_m, void *user);
SS_API ss_status ss_horizon(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt, int want,
                     ss_horizon_sink sink, void *user);

/* Cast shadows for one sun: a sweep along sun_azimuth_deg (the options'
 * frame); a cell is sunlit (1) when its sun elevation, per cell or else the
 * single value, is above its terrain horizon in that azimuth, else 0;
 * SS_NODATA at nodata. Elevations are apparent (refracted) degrees. If
 * horizon_deg is given it gets the terrain horizon in that azimuth (0 where
 * no terrain lies ahead inside the grid). */
SS_API ss_status ss_cast_shadow(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                         double sun_azimuth_deg, double sun_elevation_deg,
                         const float *sun_elevation_per_cell_deg, float *sunlit,
                         float *horizon_deg);

/* Trees (doc/vegetation.md; UMEP/SOLWEIG's model): crowns over the grid's
 * surface, which holds ground and buildings, never trees. A cell's crown
 * spans (z + trunk, z + height) above its surface z; light that crosses a
 * crown keeps the fraction `transmissivity`. */
typedef struct {
    const float *height_m; /* crown top above the surface, width*height; 0: no tree */
    const float *trunk_m;  /* crown bottom above the surface; NULL: trunk_ratio x height */
    double trunk_ratio;    /* 0..1, where trunk_m is NULL */
    double transmissivity; /* 0..1, leaf on */
} ss_canopy;

/* Refuses heights below 0 or not finite, a trunk below 0 or above its
 * crown's top, a ratio or transmissivity outside 0..1. */
SS_API ss_status ss_canopy_check(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy);
/* For one sun (grid azimuth, elevation in degrees): crossed[c] = 1 where the
 * ray from cell c's surface toward the sun passes strictly inside a crown
 * of a cell ahead, else 0 (solid terrain is not looked at: that is
 * ss_cast_shadow's). An exact sweep on the engine's lines, the earth flat:
 * box lines (crowns as columns from trunk to top, lines->box_lines per cell)
 * where lines asks for them, else digital lines (lines may be NULL). */
SS_API ss_status ss_canopy_crossed(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                   const ss_sweep_options *lines, double sun_grid_azimuth_deg,
                                   double sun_elevation_deg, unsigned char *crossed);
/* Shadow classes of n cells from the solid verdict (sunlit 1 / 0 /
 * SS_NODATA) and the crowns crossed: klass 0 lit, 1 solid shadow, 2
 * vegetation shadow; fraction of the beam that arrives: 1, 0, or the
 * transmissivity. SS_NODATA where sunlit is. */
SS_API void ss_canopy_classes(const ss_canopy *canopy, size_t n, const float *sunlit,
                              const unsigned char *crossed, float *klass, float *fraction);
/* Beer-Lambert crowns (doc/vegetation.md, a knob beside the constant
 * transmissivity): path_m[c] = the length of the ray from cell c's surface
 * toward the sun (grid azimuth, elevation in degrees) inside crowns of
 * cells ahead, on digital lines, the earth flat: each crown cell whose
 * interval the ray passes strictly inside (as ss_canopy_crossed on digital
 * lines, so path_m > 0 exactly where that finds a crossing) adds the ray's
 * run through one cell of the line over cos(elevation). SS_NODATA at
 * nodata. */
SS_API ss_status ss_canopy_path(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                double sun_grid_azimuth_deg, double sun_elevation_deg,
                                float *path_m);
/* fraction[c] = exp(-G LAD path_m[c]), the beam that crosses path_m metres
 * of crown of leaf area density LAD (m2/m3) with extinction coefficient G
 * (0.5: leaves at random angles); SS_NODATA where path_m is. */
SS_API ss_status ss_canopy_path_fraction(ss_ctx *ctx, double extinction,
                                         double leaf_area_density, size_t n,
                                         const float *path_m, float *fraction);

/* How the sky view treats the gaps under crowns (between the ground and the
 * trunk height): IGNORE takes each crown as a column down to the ground
 * (two horizons a cell, O(log n)); OPEN sees the sky through them (the
 * crowns of a line walked back from each cell until they cover its sky
 * up to the canopy-top horizon). */
typedef enum { SS_TRUNK_GAPS_IGNORE = 0, SS_TRUNK_GAPS_OPEN = 1 } ss_trunk_gaps;
/* Trees in the sky view (doc/vegetation.md, "svf"): crown_share[c] = the
 * share of cell c's sky (the SVF's mean over opt->directions, geometric or
 * horizontal definition) that crowns of other cells hide above the solid
 * horizon, seen from the cell's surface, the gaps under crowns as `gaps`
 * says; solid_share (may be NULL) = the share the surface hides, on the
 * same lines. The SVF with crowns opaque is the SVF less crown_share.
 * Digital lines, the earth flat; SS_NODATA where the grid has none. */
SS_API ss_status ss_canopy_sky(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                               const ss_sweep_options *opt, ss_svf_definition definition,
                               ss_trunk_gaps gaps, float *solid_share, float *crown_share);
/* The SVF with trees from n cells' SVF and ss_canopy_sky's crown_share
 * (UMEP's bands): svfveg = 1 - hidden, svfbuveg = svf - hidden x (1 -
 * transmissivity), with hidden = min(crown_share, svf) (the crowns never
 * hide more than the SVF sees). SS_NODATA where svf is. svfveg may be
 * crown_share (in place). */
SS_API void ss_canopy_svf_bands(size_t n, const float *svf, const float *crown_share,
                                double transmissivity, float *svfveg, float *svfbuveg);

/* The crowns' horizon toward one direction (grid azimuth, degrees):
 * crown_deg[c] = the elevation, in degrees, of the highest crown top
 * (surface + canopy height) ahead of cell c seen from its surface, -90
 * where no crown lies ahead, SS_NODATA at nodata. Digital lines, the earth
 * flat. The canopy horizon is the larger of it and the solid horizon. */
SS_API ss_status ss_canopy_top_horizon(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                       double grid_azimuth_deg, float *crown_deg);

/* Cosine of the angle between the sun and each cell's surface normal (Horn's
 * 3x3 gradient; cell azimuths in the grid's frame): <= 0 where the cell
 * faces away from the sun (self-shadow). Per-cell sun arrays may be NULL
 * for one sun. SS_NODATA at nodata. */
SS_API ss_status ss_sun_incidence(ss_ctx *ctx, const ss_grid *grid, double grid_azimuth_deg,
                           double elevation_deg, const float *grid_azimuth_per_cell_deg,
                           const float *elevation_per_cell_deg, float *cos_incidence);

/* Hillshade as gdaldem computes it: 1 + 254 cos(i) for a light at
 * light_azimuth_deg (grid frame) and light_altitude_deg, 1 where the cell
 * faces away; the z factor scales heights; Horn's gradient or (nonzero
 * zevenbergen_thorne) Zevenbergen-Thorne's; multidirectional_light uses
 * gdaldem's blend of four lights. Values 1..255 as floats, SS_NODATA at
 * nodata; edges and holes get one-sided gradients. */
SS_API ss_status ss_hillshade(ss_ctx *ctx, const ss_grid *grid, double light_azimuth_deg,
                       double light_altitude_deg, double z_factor, int zevenbergen_thorne,
                       int multidirectional_light, float *shade);

/* An upper bound (degrees) on every terrain horizon the grid can cast in the
 * line model (box_lines per cell for box lines; ignored by the others),
 * curvature or not: no cell is in a cast shadow when the sun is above it
 * (doc/insolation.md gives the proof). 90 for a grid whose heights are not
 * in memory (z NULL). */
SS_API double ss_horizon_bound_deg(const ss_grid *grid, ss_line_model lines, int box_lines);

/* ---- insolation --------------------------------------------------------- */

typedef enum {
    SS_SHADOW_AUTO = -1,        /* the planner's choice (ss_plan_request; not for ss_insolation) */
    SS_SHADOW_EXACT = 0,        /* a sweep at every daylight step's sun azimuth */
    SS_SHADOW_INTERPOLATED = 1, /* horizons stored at the sweep's directions, interpolated */
    SS_SHADOW_CUMULATIVE = 2    /* weather records only: the suns binned by direction and
                                   elevation, each bin lit or not at its direction's stored
                                   horizon (doc/insolation.md, "Cumulative sky") */
} ss_shadow_mode;

/* Sky diffuse on a tilted cell for weather records (doc/insolation.md,
 * "Real sky"); clear-sky steps use Muneer's model whatever is chosen. */
typedef enum {
    SS_SKY_MODEL_ISOTROPIC = 0, /* the cell's tilted sky view */
    SS_SKY_MODEL_HAYDAVIES = 1, /* Hay & Davies 1980: a circumsolar part shaded like the beam */
    SS_SKY_MODEL_PEREZ = 2      /* Perez et al. 1990: circumsolar and a horizon band */
} ss_sky_model;

/* PV yield, PVWatts-style (doc/insolation.md, "PV yield"): DC energy per
 * kWp of modules lying in each cell's surface, from the plane-of-array
 * global of weather records, the cell temperature and a temperature
 * coefficient, less system losses. */
typedef enum { SS_PV_TEMP_FAIMAN = 0, SS_PV_TEMP_SAPM = 1 } ss_pv_temp_model;
typedef struct {
    int on;
    double gamma_pdc;        /* 1/K, e.g. -0.0047 (PVWatts' standard module) */
    ss_pv_temp_model temp_model;
    double losses;           /* fraction of DC energy lost, 0..1 */
    double temp_air_c, wind_speed_m_s; /* where a record gives none */
    /* The AC yield (ss_insolation_out's pv_ac_yield): pvlib.inverter.pvwatts
     * with this nominal efficiency (eta_inv_nom, e.g. 0.96) behind modules
     * of dc_ac_ratio times the inverter's AC rating (PVWatts' 1.2). */
    double inverter_efficiency, dc_ac_ratio;
} ss_pv_options;

/* The surface irradiated in each cell: the cell's own slope (roofs,
 * terrain), a horizontal one, or a module of fixed tilt and azimuth; the
 * terrain's horizons and shadows are the cell's in every case. */
typedef enum { SS_SURFACE_CELL = 0, SS_SURFACE_HORIZONTAL = 1, SS_SURFACE_FIXED = 2 } ss_surface_kind;
typedef struct {
    ss_surface_kind kind;
    double tilt_deg;    /* SS_SURFACE_FIXED: 0..90 from the horizontal ... */
    double azimuth_deg; /* ... facing this azimuth, clockwise from the options' north */
} ss_surface;

typedef struct {
    double albedo;             /* ground reflectance for the reflected term, 0..1 */
    ss_shadow_mode shadow_mode;
    ss_sky_model sky_model;    /* for weather records */
    ss_pv_options pv;          /* for weather records */
    double elevation_step_deg; /* cumulative sky: height of a sun bin (0: 1 degree) */
    ss_surface surface;        /* zeros: each cell's own slope */
    const struct ss_insolation_trees_s *trees; /* NULL: no trees */
} ss_insolation_options;

/* Trees in insolation (doc/vegetation.md, "insolation"): at each step the
 * beam and the circumsolar diffuse of a cell whose ray toward the step's
 * sun (the centre's) crosses a crown (ss_canopy_crossed) keep the step's
 * transmissivity T; the cell's sky view loses sky_hidden x (1 - T), for
 * the isotropic diffuse and the reflected light alike (SOLWEIG's
 * svfbuveg), and under Perez's sky the share of the horizon band it sees
 * loses the share crowns hide x (1 - T), which the run sweeps itself from
 * the canopy and trunk_gaps. The steps run on the host. The cumulative sky bins leaf-on
 * and leaf-off records apart within each bin and sweeps the crowns once per
 * (direction, elevation) of its bins, at their mean sun
 * (doc/cumulative_sky.md, "Trees"). */
typedef struct ss_insolation_trees_s {
    const ss_grid *ground;   /* the DSM held whole, the run's grid */
    const ss_canopy *canopy; /* its transmissivity: leaf on */
    const float *sky_hidden; /* per cell: the share of its sky crowns hide (ss_canopy_sky,
                                horizontal definition); NULL: none */
    double transmissivity_leaf_off;
    const unsigned char *leaf_off; /* per step: nonzero where the leaves are off; NULL: none */
    int digital_lines; /* the crowns' beam on digital lines, not the solid sweep's model */
    ss_trunk_gaps trunk_gaps; /* the horizon band's crowns (sky_hidden's, as its caller took) */
    /* Beer-Lambert crowns where leaf_area_density > 0 (doc/vegetation.md):
     * in a leaf-on step the beam, circumsolar light and hours of sun of a
     * cell keep exp(-extinction x leaf_area_density x the ray's path inside
     * crowns) (ss_canopy_path, digital lines) instead of the canopy's
     * transmissivity, and the sky and horizon band the crowns hide pass
     * the mean of that over the directions they hide (the run sweeps it
     * from sky_hidden's options: its directions, horizontal definition and
     * trunk_gaps); leaf-off steps keep transmissivity_leaf_off. Every
     * step's crowns go on digital lines. The cumulative sky refuses it. 0:
     * the constant model. */
    double leaf_area_density, extinction;
} ss_insolation_trees;

/* The leaf season of insolation's steps (doc/vegetation.md, "insolation"),
 * for ss_insolation_trees' leaf_off; the command line and the Python
 * package both take it from here. A leaf date is a day of the year (1-366)
 * or MM-DD; ss_leaf_date_valid says whether text is one. */
SS_API int ss_leaf_date_valid(const char *text);
typedef struct {
    int on_day, off_day; /* the season's days (a date given as MM-DD: in 2001) */
    int south;           /* UMEP's defaults shifted by half a year (183 days) */
    int leaf_off_steps;  /* steps with the leaves off */
} ss_leaf_season;
/* Each of n steps (instants mid_s, Unix seconds) leaf off (1) or on (0)
 * into leaf_off, by its local date in mean solar time at longitude_deg.
 * Leaves are on from leaf_on up to the day before leaf_off (over the new
 * year where leaf_on comes later); NULL dates (or malformed ones) take
 * UMEP's: on from day 98, off from day 300 (its firstdayleaf 97 and
 * lastdayleaf 300), half a year later where latitude_deg is south of the
 * equator. */
SS_API void ss_leaf_seasons(const char *leaf_on, const char *leaf_off, double latitude_deg,
                            double longitude_deg, const double *mid_s, int n,
                            unsigned char *leaf_off_out, ss_leaf_season *season);

/* Per-cell suns given by a lattice (ss_sun_step's lattice, in place of
 * per-cell arrays; insolation reads it, the shadow product takes arrays):
 * the sun's grid azimuth, true elevation and refraction (degrees) at nodes
 * on the grid's columns cols[0..n_cols) and rows rows[0..n_rows) (at least
 * two of each, in increasing order; the columns from the grid's first to
 * its last, the rows, counted from the grid's first, spanning those the
 * step was asked for; node (i, j) at j * n_cols + i), bilinear between
 * them. Where the sun is
 * down at any of the four nodes around a cell, refraction bends too
 * sharply to interpolate: the cell's is computed from its elevation
 * (ss_spa_refraction_deg, with these air parameters). A cell between two
 * lattice columns takes the segment it starts, the last column the last
 * segment's end. ss_sun_lattice_cells (skysweep_sun.h) gives the cells'
 * suns. */
typedef struct {
    int n_cols, n_rows;
    const int *cols, *rows;
    const double *grid_azimuth_deg, *elevation_deg, *refraction_deg;
    double pressure_hpa, temperature_c, atmos_refract_deg;
} ss_sun_lattice;

/* The sun for one time step, supplied by the caller (who knows where the
 * grid lies): at the grid's centre, plus per-cell fields where one sun does
 * not serve every cell (per-cell arrays, or a lattice they are interpolated
 * from). */
typedef struct {
    double duration_h;             /* hours this step stands for */
    double linke;                  /* Linke turbidity (air mass 2) */
    double extraterrestrial_w_m2;  /* normal irradiance above the atmosphere */
    double unix_s;                 /* the instant (UTC): Erbs's day of the year */
    double azimuth_deg;            /* in the sweep options' frame (the shadow sweep) */
    double grid_azimuth_deg;       /* the same in the grid's frame (cell slopes) */
    double elevation_deg;          /* true, airless */
    double apparent_elevation_deg; /* with refraction, for shadows */
    double spread_deg;             /* largest difference of any cell's sun from this one */
    const float *grid_azimuth_per_cell, *elevation_per_cell, *apparent_per_cell; /* or NULL */
    const ss_sun_lattice *lattice; /* or NULL; insolation: where given, the arrays are not read */
    /* A weather record instead of the clear sky (real_sky nonzero): its
     * irradiance in W/m^2 (dni and dhi NAN: split from ghi by Erbs; any
     * other NAN: the record is missing and adds nothing), the ground's
     * albedo (NAN: the options'), and the month it counts to (1..12; 0:
     * none) for the monthly sums. */
    int real_sky;
    double ghi_w_m2, dni_w_m2, dhi_w_m2, albedo;
    double temp_air_c, wind_speed_m_s; /* NAN: the PV options' */
    int month;
} ss_sun_step;

typedef ss_status (*ss_sun_step_fn)(ss_ctx *ctx, int index, ss_sun_step *step, void *user);
/* Receives each step's global irradiation (Wh/m^2, SS_NODATA at nodata);
 * return 0 to stop. */
typedef int (*ss_step_sink)(int index, const float *global_wh_m2, void *user);

typedef struct {
    float *global, *beam, *diffuse, *reflected; /* Wh/m^2 over all steps */
    float *sun_hours; /* hours the cell's surface received direct sun */
    float *monthly_global; /* NULL, or 12 planes: the global of steps in January..December */
    float *pv_yield;       /* NULL, or kWh/kWp (options' pv.on, weather records) */
    float *pv_ac_yield;    /* NULL, or AC kWh/kWp after the options' inverter (pv.on) */
} ss_insolation_out;

/* Clear-sky irradiation (ESRA with Linke turbidity, as GRASS r.sun; sky
 * diffuse scaled by the cell's radiative sky-view factor over the options'
 * directions, reflected by albedo times the terrain the cell sees): beam,
 * diffuse and reflected on each cell's slope, summed over n_steps. */
SS_API ss_status ss_insolation(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                        const ss_insolation_options *io, int n_steps, ss_sun_step_fn sun_at,
                        void *sun_user, ss_step_sink sink, void *sink_user,
                        ss_insolation_out *out);

/* The sun of step `index` for rows [row0, row0 + n_rows): as
 * ss_sun_step_fn, with per-cell arrays (where one sun does not serve the
 * grid) covering those rows only, from their first cell; n_rows 0 asks for
 * the centre's values alone. */
typedef ss_status (*ss_sun_rows_fn)(ss_ctx *ctx, int index, int row0, int n_rows,
                                    ss_sun_step *step, void *user);
/* Outputs of ss_insolation_rows (Wh/m^2 unless said; index 0 unless said). */
#define SS_OUT_GLOBAL 0
#define SS_OUT_BEAM 1
#define SS_OUT_DIFFUSE 2
#define SS_OUT_REFLECTED 3
#define SS_OUT_SUN_HOURS 4 /* hours */
#define SS_OUT_MONTHLY 5   /* the global of each month's steps, index 0..11 */
#define SS_OUT_PV 6        /* kWh/kWp DC (options' pv.on, weather records) */
#define SS_OUT_PV_AC 7     /* kWh/kWp AC after the inverter (pv.on) */
#define SS_OUT_STEP 8      /* each step's global, index the step */
/* Which of them a run gives besides the first five (bits of `want`). */
#define SS_INSOLATION_MONTHLY 1
#define SS_INSOLATION_PV 2
#define SS_INSOLATION_STEPS 4

/* What ss_insolation computes, for src: sun_rows gives each step's sun for
 * the rows of a band; share (may be NULL) deals out the time steps. */
SS_API ss_status ss_insolation_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                             const ss_insolation_options *io, int n_steps, ss_sun_rows_fn sun_rows,
                             void *sun_user, int want, const ss_share *share, ss_rows_sink sink,
                             void *user);
/* Directions whose hulls a run in bands holds at once: size the bands for
 * this many. */
#define SS_INSOLATION_STEPS_PER_RUN 64
/* Bytes an insolation run in bands holds per cell of a band, besides the
 * sweep's own (ss_band_rows_within's band_cell_bytes), for its outputs
 * (SS_INSOLATION_* bits) and the directions whose horizons it stores
 * (interpolated shadows, the cumulative sky; 0 with exact shadows). */
SS_API double ss_insolation_band_cell_bytes(int want, int stored_directions);
/* Bytes per cell of the whole grid that insolation's exact shadow walks
 * hold beside its bands: their bounds' largest level per block of cells
 * and sector (lit_levels.h), in the bounds, in a band's copy and in a
 * device's. */
SS_API double ss_insolation_grid_cell_bytes(void);

/* Irradiation (Wh/m^2 over the steps, into global_wh_m2[0..n_planes)) on
 * open planes of the given tilts (0..90) and azimuths (degrees clockwise
 * from the steps' north, the way each plane faces) over level ground: the
 * weather records' steps (real_sky) by the options' sky model and albedo,
 * with no horizon but the ground's, computed as every insolation run
 * computes a cell's step (a fixed module on level ground). */
SS_API ss_status ss_insolation_open_planes(ss_ctx *ctx, const ss_insolation_options *io,
                                           int n_steps, ss_sun_step_fn sun_at, void *sun_user,
                                           int n_planes, const double *tilt_deg,
                                           const double *azimuth_deg, double *global_wh_m2);

/* A clear sky as a weather record (W/m^2): ESRA's direct normal and diffuse
 * horizontal irradiance of a clear-sky step (ss_sun_step_clear_sky: its
 * true elevation, Linke turbidity and extraterrestrial irradiance) on level
 * ground height_m above sea level, as every clear-sky insolation step takes
 * them, and their global horizontal; all 0 with the sun below the
 * horizontal. skysweep roofs runs a clear-sky year through the weather
 * path with them. */
SS_API void ss_clear_sky_record(const ss_sun_step *step, double height_m, double *ghi_w_m2,
                                double *dni_w_m2, double *dhi_w_m2);

/* ---- shadows and shaded relief, in rows ---------------------------------- */

/* Outputs of ss_shadow_rows. */
#define SS_OUT_SUNLIT 0 /* 1 sunlit, 0 in a cast shadow */
#define SS_OUT_FACING 1 /* 1 facing the sun, 0 away from it (self-shadow) */
#define SS_OUT_LIGHT 2  /* cos(incidence) on sunlit cells facing the sun, else 0 */
/* Cast shadows and illumination for the sun of step 0 of sun_rows: a sweep
 * along its azimuth_deg, each cell lit where its apparent elevation is
 * above its terrain horizon (the horizontal where none lies ahead), its
 * incidence by Horn's gradient with grid_azimuth_deg. */
SS_API ss_status ss_shadow_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                         ss_sun_rows_fn sun_rows, void *sun_user, ss_rows_sink sink, void *user);

/* Shaded relief (ss_hillshade_rows): gdaldem's hillshade, or RVT's VAT blend. */
typedef struct {
    double azimuth_deg, altitude_deg; /* the light, degrees; azimuth in the raster's frame */
    double z_factor;                  /* vertical exaggeration */
    int zevenbergen_thorne;           /* the gradient: Horn's (0) or Zevenbergen-Thorne's */
    int multidirectional;             /* gdaldem's blend of four lights */
    int cast_shadows;                 /* cells in the light's cast shadows take 1 */
    double sky_view;                  /* weight W: (1 - W) shade + W (1 + 254 SVF), geometric */
    int vat;                          /* RVT's VAT blend instead (1 + 254 x 0..1) */
    double radius_m;                  /* the VAT's SVF and openness: horizons within it (0:
                                         unlimited) */
    /* Trees in the cast shadows (NULL: none): per cell of the whole grid,
     * whether the light's ray crosses a crown (ss_canopy_crossed along the
     * light); such a cell, lit past the terrain, takes 1 + T (shade - 1):
     * the share T of the light that passes the crowns. */
    const unsigned char *crowns_crossed;
    double transmissivity;
} ss_hillshade_options;
#define SS_OUT_SHADE 0 /* 1..255 */
SS_API ss_status ss_hillshade_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                            const ss_hillshade_options *ho, ss_rows_sink sink, void *user);
/* Checks ss_hillshade_rows' options without a DEM: the light, a positive
 * z factor, the sky-view weight and radius in range, and the VAT blend
 * alone (it has its own light and layers). SS_ERR_ARGUMENT, naming the
 * problem, otherwise. */
SS_API ss_status ss_hillshade_check(ss_ctx *ctx, const ss_hillshade_options *ho);

/* ---- the effects planner (doc/planner.md) -------------------------------- */

/* What the planner weighs a job as: the sweep it runs and the accuracy it
 * is judged by, which products share (openness plans as horizons,
 * hillshade as no sweep, its shadows or its sky view; the registry's
 * plans_as). */
typedef enum {
    SS_PLAN_HORIZONS,   /* horizon angles: horizon, openness */
    SS_PLAN_SKY_VIEW,   /* the sky-view factor, judged by svf_tolerance */
    SS_PLAN_SHADOW,     /* one sweep along the sun */
    SS_PLAN_NO_SWEEP,   /* per-cell arithmetic alone: plain hillshade */
    SS_PLAN_INSOLATION  /* the sky's sweeps and the steps' shadows */
} ss_plan_kind;

typedef enum { SS_AUTO = -1, SS_OFF = 0, SS_ON = 1 } ss_switch;

/* Where the grid lies, from the DEM's CRS (the CLI's frame). */
typedef struct {
    int georeferenced, geographic;
    double centre_lon_deg, centre_lat_deg;
    double grid_north_deg, grid_north_min_deg, grid_north_max_deg;
    double cell_variation; /* relative spread of ground cell sizes over the grid */
    double diagonal_m;     /* the longest distance a horizon can span */
    double earth_radius_m;
} ss_place;

/* A weather file's site farther than this (km) from the DEM's centre is
 * not the DEM's weather: the CLI refuses it unless confirmed
 * (--weather-far-ok), and the plan says so (doc/weather.md). */
#define SS_WEATHER_NEAR_KM 100.0

/* How a weather record's beam and diffuse were had (ss_irradiance_complete). */
typedef enum {
    SS_IRRADIANCE_AS_GIVEN, /* all three given, or the record is missing */
    SS_IRRADIANCE_CLOSURE,  /* DNI = (GHI - DHI) / cos(zenith) */
    SS_IRRADIANCE_ERBS      /* DNI and DHI split from GHI by Erbs et al. 1982 */
} ss_irradiance_source;

/* Completes a weather record as pvlib 0.16 does, at the sun's true zenith
 * (degrees) and instant (UTC seconds): with *dni NAN and *dhi given,
 * DNI = (GHI - DHI) / cos(zenith) (pvlib.irradiance.dni, whose NAN, for a
 * negative DNI or one not 0 at a zenith of 88 degrees or more, is 0 here:
 * no beam, the diffuse kept); with both NAN, Erbs's split
 * (pvlib.irradiance.erbs: clearness index against pvlib's extraterrestrial
 * irradiance, Spencer's of the UTC day of the year with 1366.1 W/m^2, at
 * cos(zenith) of at least 0.065, clipped to 0..1; no beam beyond a zenith
 * of 87 degrees). Anything else is left as it is. */
SS_API ss_irradiance_source ss_irradiance_complete(double ghi, double *dni, double *dhi,
                                                   double zenith_deg, double unix_s);

/* Insolation from weather records, for the plan to say: what they are
 * (NULL: clear sky), how far their site lies from the DEM's centre (km;
 * NAN: the file names none), and whether Perez's horizon band is swept. */
typedef struct {
    const char *what;
    double distance_km;
    int horizon_band;
    int per_step; /* per-step bands asked for: each record is needed, exactly */
    int pv;       /* the PV yield asked for: each record is needed, and its error counts */
    /* The error a cell's annual and monthly sums (and PV yield) may take,
     * percent at p95: shadow mode auto takes interpolated shadows or the
     * cumulative sky only where their measured error is within it
     * (doc/planner.md); 0 allows none, so exact shadows. */
    double tolerance_pct;
} ss_plan_weather;

typedef struct {
    ss_plan_kind kind;
    double horizon_tolerance_deg; /* horizon angles, shadows, azimuths */
    double svf_tolerance;         /* SVF (0..1 units) */
    double sun_tolerance_deg;     /* the sun's direction per cell */
    ss_switch curvature, true_north, sun_per_cell; /* SS_AUTO: the planner decides */
    double refraction_k;
    int directions; /* 0: the planner chooses */
    ss_svf_definition svf_definition; /* the SVF product's (insolation uses the radiative) */
    ss_line_model lines;        /* SS_LINES_AUTO: the planner chooses */
    int box_lines;              /* box lines per cell (0: the planner chooses, doc/planner.md) */
    ss_box_shadows box_shadows; /* box lines' cast shadows (ss_sweep_options') */
    ss_box_sky box_sky;         /* box lines' sky view (ss_sweep_options') */
    /* The product's sky view or horizons are a sky or horizon walk (svf,
     * openness, the horizon rasters, hillshade's sky layers, insolation's
     * own surface): on box lines with box_sky march, each cell's own ray,
     * which takes no box lines. */
    int sky_walk;
    double radius_m;            /* svf and openness: horizons within it (0: unlimited) */
    ss_shadow_mode shadow_mode;
    int n_steps;                /* time steps (shadow, insolation) ... */
    const double *step_unix_s;  /* ... and the instants they are evaluated at */
    ss_plan_weather weather;    /* insolation: zeros for the clear sky */
} ss_plan_request;

#define SS_PLAN_MAX_ITEMS 20
typedef struct {
    char key[24];     /* curvature, true_north, cell_sizes, sun_per_cell, directions, ... */
    int on;
    char reason[400]; /* in the scene's own numbers */
    double bound;     /* the error the decision allows (0: none) */
    char unit[8];
} ss_plan_item;

typedef struct {
    ss_plan_item items[SS_PLAN_MAX_ITEMS];
    int n_items;
    int curvature, true_north, sun_per_cell; /* the decisions */
    ss_shadow_mode shadow_mode;              /* insolation */
    int directions;
    ss_line_model lines;
    int box_lines;
    int sky_box_lines; /* insolation's sky view, where not box_lines (0) */
    int steps_total, steps_night, steps_high_sun;
    int sweeps;
    double cells, estimated_seconds;
    /* The device estimated_seconds is for: "reference" or, on a context
     * with device "auto", "P:D" where the cost model chose an OpenCL device
     * (doc/devices.md); "opencl" for one the caller named (modelled as
     * PoCL). ss_ctx_apply_plan opens it on an "auto" context. */
    char device[16];
} ss_plan;

SS_API ss_status ss_plan_make(ss_ctx *ctx, const ss_grid *grid, const ss_place *place,
                       const ss_plan_request *request, ss_plan *plan);
/* The sweep options that obey a plan: its directions and line model (and
 * box lines per cell);
 * curvature (with the place's earth radius and refraction_k) and true north
 * (the place's grid north) only where it turned them on. The other fields
 * are kept. */
SS_API void ss_plan_sweep_options(const ss_plan *plan, const ss_place *place, double refraction_k,
                           ss_sweep_options *opt);
/* Opens the device the plan chose where the context's device is "auto"
 * (the context stays "auto" for the next plan; one that does not open
 * leaves the job to the C twin); otherwise does nothing. SS_ERR_CANCELLED
 * when the run is cancelled while the device's kernels build. */
SS_API ss_status ss_ctx_apply_plan(ss_ctx *ctx, const ss_plan *plan);
/* The plan as text lines ("effect ON/OFF reason [error allowed]") or JSON;
 * returns the length needed, as snprintf. */
SS_API size_t ss_plan_format(const ss_plan *plan, int json, char *buf, size_t size);

/* The bare pass along the lines of one azimuth: every sample read and its
 * cells written (out[c] += weight * height), no hull. The yardstick of the
 * sweep's cost, and with z = 1 it adds up the weight each cell receives
 * (exactly 1). out must be width*height floats. */
SS_API ss_status ss_bare_pass(ss_ctx *ctx, const ss_grid *grid, double azimuth_deg,
                       ss_line_model lines, float *out);

#ifdef __cplusplus
}
#endif
#endif
