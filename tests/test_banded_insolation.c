/* Insolation in bands (ss_insolation_rows, src/core/engine.c) against the
 * whole-grid one (exact shadows): the same five outputs and per-step
 * global bands on random terrain with nodata holes across band edges, for
 * bands from 1 row to more than the grid, with one sun for the grid and
 * with a sun per cell (a field that varies across rows and columns, handed
 * over row by row), steps at night, with and without curvature. Every
 * row of every output and step must be written exactly once. The SVF is
 * swept in bands too, so sums differ in the order of float additions:
 * the tolerances say how much. A sun per cell given as a lattice
 * (ss_sun_step.lattice), interpolated run by run, gives the outputs of the
 * arrays the lattice fills, to the bit, whole and in bands, for the clear
 * sky and for weather records; on an OpenCL device, which takes the
 * lattice itself, they are the C twin's to float rounding. Runs of 48
 * walked steps or more stop their shadow walks by the cells' proven
 * bounds (src/core/lit_levels.h), in bands as on the whole grid: on box
 * lines of 32 families, each banded run leaves some of its walks' samples
 * unwalked. Box shadows by each cell's own ray run in every band too. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "box_march.h"
#include "skysweep_sun.h"
#include "tap.h"
#include "testlib.h"

#define N_STEPS 7

/* Suns from low in the east over the top to below the horizon in the west,
 * and one at night; per cell they turn by up to 2 degrees across the grid. */
typedef struct {
    const ss_grid *g;
    int per_cell;
    int weather;                                     /* the steps are weather records */
    int first;                                       /* run step k is the table's step first + k */
    float *az[N_STEPS], *el[N_STEPS], *app[N_STEPS]; /* whole-grid fields */
} sun_setup;

static const double step_az[N_STEPS] = {80.0, 110.0, 150.0, 200.0, 250.0, 280.0, 0.0};
static const double step_el[N_STEPS] = {3.0, 25.0, 52.0, 47.0, 18.0, 0.8, -30.0};

static int sun_init(sun_setup *s, const ss_grid *g, int per_cell)
{
    memset(s, 0, sizeof *s);
    s->g = g;
    s->per_cell = per_cell;
    size_t n = (size_t)g->width * g->height;
    for (int k = 0; per_cell && k < N_STEPS; ++k) {
        s->az[k] = malloc(n * sizeof(float));
        s->el[k] = malloc(n * sizeof(float));
        s->app[k] = malloc(n * sizeof(float));
        if (!s->az[k] || !s->el[k] || !s->app[k])
            return 0;
        for (int r = 0; r < g->height; ++r)
            for (int c = 0; c < g->width; ++c) {
                size_t i = (size_t)r * g->width + c;
                double u = (double)c / g->width - 0.5, v = (double)r / g->height - 0.5;
                s->az[k][i] = (float)(step_az[k] + 2.0 * u);
                s->el[k][i] = (float)(step_el[k] + 1.5 * v);
                s->app[k][i] = s->el[k][i] + 0.1f;
            }
    }
    return 1;
}

static void sun_free(sun_setup *s)
{
    for (int k = 0; k < N_STEPS; ++k) {
        free(s->az[k]);
        free(s->el[k]);
        free(s->app[k]);
    }
}

/* Step k of the table at the grid's centre, its cells' suns within
 * spread_deg of it. */
static void table_step(int k, double spread_deg, ss_sun_step *step)
{
    memset(step, 0, sizeof *step);
    step->duration_h = 0.5;
    step->linke = 3.0 + 0.2 * k;
    step->extraterrestrial_w_m2 = 1360.0;
    step->azimuth_deg = step->grid_azimuth_deg = step_az[k];
    step->elevation_deg = step_el[k];
    step->apparent_elevation_deg = step_el[k] + 0.1;
    step->spread_deg = spread_deg;
}

/* A weather record of light enough to cast shadows, in June. */
static void weather_step(ss_sun_step *step)
{
    step->real_sky = 1;
    step->ghi_w_m2 = 600.0;
    step->dni_w_m2 = 500.0;
    step->dhi_w_m2 = 150.0;
    step->albedo = step->temp_air_c = step->wind_speed_m_s = NAN;
    step->month = 6;
}

static void fill_step(const sun_setup *s, int k, size_t offset, ss_sun_step *step)
{
    k = (k + s->first) % N_STEPS; /* long runs repeat the table */
    table_step(k, s->per_cell ? 2.5 : 0.0, step);
    if (s->weather)
        weather_step(step);
    if (s->per_cell && offset != (size_t)-1) {
        step->grid_azimuth_per_cell = s->az[k] + offset;
        step->elevation_per_cell = s->el[k] + offset;
        step->apparent_per_cell = s->app[k] + offset;
    }
}

static ss_status sun_whole(ss_ctx *ctx, int k, ss_sun_step *step, void *user)
{
    (void)ctx;
    fill_step(user, k, 0, step);
    return SS_OK;
}

static ss_status sun_rows(ss_ctx *ctx, int k, int row0, int n_rows, ss_sun_step *step, void *user)
{
    (void)ctx;
    const sun_setup *s = user;
    fill_step(s, k, n_rows > 0 ? (size_t)row0 * s->g->width : (size_t)-1, step);
    return SS_OK;
}

/* Where a run's grids go: five outputs and N_STEPS step bands. */
typedef struct {
    const ss_grid *g;
    sun_setup *sun;
    float *out[5], *steps[N_STEPS];
    int *writes; /* per row: outputs; then per step and row */
} grids;

static int grids_init(grids *o, const ss_grid *g, sun_setup *sun)
{
    memset(o, 0, sizeof *o);
    o->g = g;
    o->sun = sun;
    size_t n = (size_t)g->width * g->height;
    int ok = 1;
    for (int k = 0; k < 5; ++k)
        ok &= (o->out[k] = malloc(n * sizeof(float))) != NULL;
    for (int k = 0; k < N_STEPS; ++k)
        ok &= (o->steps[k] = malloc(n * sizeof(float))) != NULL;
    ok &= (o->writes = calloc((size_t)(N_STEPS + 1) * g->height, sizeof(int))) != NULL;
    return ok;
}

static void grids_free(grids *o)
{
    for (int k = 0; k < 5; ++k)
        free(o->out[k]);
    for (int k = 0; k < N_STEPS; ++k)
        free(o->steps[k]);
    free(o->writes);
}

static int whole_step(int k, const float *global, void *user)
{
    grids *o = user;
    memcpy(o->steps[k], global, sizeof(float) * (size_t)o->g->width * o->g->height);
    return 1;
}

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    grids *o = user;
    memcpy(z, o->g->z + (size_t)row0 * o->g->width, sizeof(float) * (size_t)n_rows * o->g->width);
    return SS_OK;
}

/* Rows of the five outputs (SS_OUT_GLOBAL .. SS_OUT_SUN_HOURS; the
 * globals' counted) and of each step's global. */
static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    grids *o = user;
    size_t at = (size_t)row0 * o->g->width, n = (size_t)n_rows * o->g->width;
    if (output == SS_OUT_STEP) {
        if (index < 0 || index >= N_STEPS)
            return SS_ERR_INTERNAL;
        memcpy(o->steps[index] + at, values, sizeof(float) * n);
        for (int r = row0; r < row0 + n_rows; ++r)
            o->writes[(size_t)(index + 1) * o->g->height + r]++;
        return SS_OK;
    }
    if (output < SS_OUT_GLOBAL || output > SS_OUT_SUN_HOURS)
        return SS_ERR_INTERNAL;
    memcpy(o->out[output] + at, values, n * sizeof(float));
    for (int r = row0; output == SS_OUT_GLOBAL && r < row0 + n_rows; ++r)
        o->writes[r]++;
    return SS_OK;
}

/* Worst |a - b| / max(|a|, 1) over valid cells; nodata must match. */
static double worst_of(const float *a, const float *b, size_t n, size_t *nodata_mismatch)
{
    double w = 0;
    for (size_t c = 0; c < n; ++c) {
        if ((a[c] == SS_NODATA) != (b[c] == SS_NODATA)) {
            (*nodata_mismatch)++;
            continue;
        }
        double e = fabs((double)a[c] - b[c]) / fmax(1.0, fabs(a[c]));
        w = isfinite(e) ? fmax(w, e) : INFINITY;
    }
    return w;
}

/* A context on the default OpenCL device, or NULL after skipping what
 * (one TAP skip) where none opens here. */
static ss_ctx *opencl_or_skip(const char *what)
{
    ss_ctx *dev = ss_ctx_new();
    if (ss_ctx_use_device(dev, NULL) != SS_OK || strstr(ss_ctx_device_name(dev), "reference") ||
        strstr(ss_ctx_device_name(dev), "no device")) {
        tap_skip(what, "no OpenCL device opens here");
        ss_ctx_free(dev);
        return NULL;
    }
    return dev;
}

/* On the device of ctx (the caller's). Box lines of box_lines families (0: interpolated lines), their cast
 * shadows by the families' walks or (march) by each cell's own ray, which
 * must then run in every band; want_skips: every banded run must stop
 * some walks by the bounds. */
static void compare_lines(ss_ctx *ctx, const ss_grid *g, const char *terrain, int per_cell,
                          int curved, int first, int n_steps, const int *band_rows,
                          int n_band_rows, int box_lines, int march, int want_skips)
{
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    if (box_lines > 0) {
        opt.lines = SS_LINES_BOX;
        opt.box_lines = box_lines;
        opt.box_shadows = march ? SS_BOX_SHADOWS_MARCH : SS_BOX_SHADOWS_LINES;
    }
    opt.directions = 12;
    opt.earth_radius_m = curved ? 3e4 : 0;
    opt.refraction_k = 0;
    ss_insolation_options io = {.albedo = 0.25, .shadow_mode = SS_SHADOW_EXACT};
    sun_setup sun;
    grids ref, out;
    int ok = sun_init(&sun, g, per_cell) && grids_init(&ref, g, &sun) && grids_init(&out, g, &sun);
    sun.first = first;
    ss_insolation_out whole = {.global = ref.out[0],
                               .beam = ref.out[1],
                               .diffuse = ref.out[2],
                               .reflected = ref.out[3],
                               .sun_hours = ref.out[4]};
    /* Runs longer than the table check the five outputs only. */
    int per_step = n_steps <= N_STEPS;
    uint64_t marched_before = ss_ctx_counters(ctx).box_march_steps;
    if (ok && ss_insolation(ctx, g, &opt, &io, n_steps, sun_whole, &sun,
                            per_step ? whole_step : NULL, &ref, &whole) != SS_OK) {
        tap_diag("whole-grid run failed: %s", ss_ctx_message(ctx));
        ok = 0;
    }
    size_t n = (size_t)g->width * g->height, mismatch = 0;
    double worst[5] = {0}, worst_step = 0;
    int rows_ok = 1, runs_skipping = 0, runs_marching = 0;
    /* Each daylight step is marched once however many bands it takes. */
    uint64_t marched_whole = ss_ctx_counters(ctx).box_march_steps - marched_before;
    char why[300] = "";
    for (int b = 0; ok && b < n_band_rows; ++b) {
        memset(out.writes, 0, sizeof(int) * (size_t)(N_STEPS + 1) * g->height);
        ss_source src = test_source(g, read_rows, &out, band_rows[b], NULL);
        uint64_t skipped = ss_ctx_counters(ctx).shadow_steps_skipped;
        uint64_t marched = ss_ctx_counters(ctx).box_march_steps;
        if (ss_insolation_rows(ctx, &src, &opt, &io, n_steps, sun_rows, &sun,
                               per_step ? SS_INSOLATION_STEPS : 0, NULL, write_rows,
                               &out) != SS_OK) {
            snprintf(why, sizeof why, "%s", ss_ctx_message(ctx));
            ok = 0;
            break;
        }
        runs_skipping += ss_ctx_counters(ctx).shadow_steps_skipped > skipped;
        runs_marching += marched_whole > 0 &&
                         ss_ctx_counters(ctx).box_march_steps - marched == marched_whole;
        for (int r = 0; r < (per_step ? n_steps + 1 : 1) * g->height; ++r)
            rows_ok &= out.writes[r] == 1;
        for (int k = 0; k < 5; ++k)
            worst[k] = fmax(worst[k], worst_of(ref.out[k], out.out[k], n, &mismatch));
        for (int k = 0; k < n_steps && per_step; ++k)
            worst_step = fmax(worst_step, worst_of(ref.steps[k], out.steps[k], n, &mismatch));
    }
    /* Relative to the value (or absolute below 1 Wh/m^2). The steps are
     * summed in another order (each pass's, then the passes and groups of
     * steps), which moves a sum of n float terms by up to about n 2^-24
     * (1.2e-7 n); the SVF's own sums in another order move the diffuse and
     * reflected terms, the smallest, by up to a few 1e-5, more where many
     * steps meet the largest. Horizons are exact, so the hours of sun (sums
     * of whole half hours) are too. The sun's tables lie on the step's
     * lattice, whatever the band (sun_table.h), so a step's beam is the
     * whole grid's and its sum differs by the order alone. */
    double long_run = per_step ? 1.0 : 3.0;
    int bounded = want_skips;
    tap_ok(ok && rows_ok && !mismatch && worst[0] <= 1e-5 && worst[1] <= 1.2e-7 * n_steps &&
               worst[2] <= 1e-4 && worst[3] <= 1e-4 * long_run && worst[4] == 0 &&
               worst_step <= 1e-5 && (!bounded || runs_skipping == n_band_rows) &&
               (!march || runs_marching == n_band_rows),
           "%s, %s, %s, curvature %s, %d steps: banded insolation == whole grid for %d band heights "
           "(worst relative: global %.2g, beam %.2g, diffuse %.2g, reflected %.2g, sun hours %.2g, "
           "steps %.2g; every "
           "row written once: %s; %d banded runs left samples of their shadow walks unwalked%s; "
           "%d marched each cell's own ray in every daylight step%s)%s%s",
           ss_ctx_device_name(ctx), terrain, per_cell ? "a sun per cell" : "one sun",
           curved ? "on" : "off", n_steps,
           n_band_rows, worst[0], worst[1], worst[2], worst[3], worst[4],
           worst_step,
           rows_ok ? "yes" : "no", runs_skipping, bounded ? ", want all" : "", runs_marching,
           march ? ", want all" : "", why[0] ? ": " : "", why);
    if (mismatch)
        tap_diag("%zu nodata mismatches", mismatch);
    sun_free(&sun);
    grids_free(&ref);
    grids_free(&out);
}

/* ---- a lattice against the arrays it fills ---------------------------------- */

enum { LATTICE_COLS = 4, LATTICE_ROWS = 3 };

typedef struct {
    const ss_grid *g;
    int use_lattice, weather;
    int cols[LATTICE_COLS], rows[LATTICE_ROWS];
    double az[N_STEPS][LATTICE_COLS * LATTICE_ROWS], el[N_STEPS][LATTICE_COLS * LATTICE_ROWS],
        refr[N_STEPS][LATTICE_COLS * LATTICE_ROWS];
    ss_sun_lattice lattice[N_STEPS];
    float *arrays[N_STEPS][3]; /* the whole grid's azimuth, elevation, apparent elevation */
} lattice_setup;

/* Nodes whose suns turn by 2 degrees across the grid, the lowest straddling
 * the horizontal (refraction per cell there), and the arrays they fill. */
static int lattice_init(lattice_setup *s, const ss_grid *g)
{
    memset(s, 0, sizeof *s);
    s->g = g;
    int w = g->width, h = g->height;
    int cols[LATTICE_COLS] = {0, w / 3, 2 * w / 3, w - 1}, rows[LATTICE_ROWS] = {0, h / 2, h - 1};
    memcpy(s->cols, cols, sizeof cols);
    memcpy(s->rows, rows, sizeof rows);
    for (int k = 0; k < N_STEPS; ++k) {
        for (int j = 0; j < LATTICE_ROWS; ++j)
            for (int i = 0; i < LATTICE_COLS; ++i) {
                int at = j * LATTICE_COLS + i;
                double u = (double)cols[i] / w - 0.5, v = (double)rows[j] / h - 0.5;
                s->az[k][at] = step_az[k] + 2.0 * u;
                s->el[k][at] = step_el[k] + 2.0 * v;
                s->refr[k][at] = ss_spa_refraction_deg(s->el[k][at], 1013.25, 12.0, 0.5667);
            }
        s->lattice[k] = (ss_sun_lattice){LATTICE_COLS, LATTICE_ROWS, s->cols, s->rows,
                                         s->az[k], s->el[k], s->refr[k], 1013.25, 12.0, 0.5667};
        double *tx = malloc(sizeof(double) * ss_sun_lattice_tx_count(&s->lattice[k]));
        for (int v = 0; v < 3; ++v)
            s->arrays[k][v] = malloc(sizeof(float) * (size_t)w * h);
        if (!tx || !s->arrays[k][0] || !s->arrays[k][1] || !s->arrays[k][2]) {
            free(tx);
            return 0;
        }
        ss_sun_lattice_tx(&s->lattice[k], tx);
        for (int r = 0; r < h; ++r) {
            size_t at = (size_t)r * w;
            ss_sun_lattice_cells(&s->lattice[k], tx, r, 0, w, s->arrays[k][0] + at,
                                 s->arrays[k][1] + at, s->arrays[k][2] + at);
        }
        free(tx);
    }
    return 1;
}

static void lattice_free(lattice_setup *s)
{
    for (int k = 0; k < N_STEPS; ++k)
        for (int v = 0; v < 3; ++v)
            free(s->arrays[k][v]);
}

/* Step k for rows from row0 (n_rows 0: the centre's sun alone). */
static ss_status lattice_sun(ss_ctx *ctx, int k, int row0, int n_rows, ss_sun_step *step,
                             void *user)
{
    (void)ctx;
    const lattice_setup *s = user;
    table_step(k, 2.5, step);
    if (s->weather)
        weather_step(step);
    size_t at = (size_t)row0 * s->g->width;
    if (n_rows > 0 && s->use_lattice)
        step->lattice = &s->lattice[k];
    else if (n_rows > 0) {
        step->grid_azimuth_per_cell = s->arrays[k][0] + at;
        step->elevation_per_cell = s->arrays[k][1] + at;
        step->apparent_per_cell = s->arrays[k][2] + at;
    }
    return SS_OK;
}

static ss_status lattice_sun_whole(ss_ctx *ctx, int k, ss_sun_step *step, void *user)
{
    return lattice_sun(ctx, k, 0, 1, step, user);
}

static int same_floats(const float *a, const float *b, size_t n)
{
    return memcmp(a, b, n * sizeof(float)) == 0;
}

static void lattice_against_arrays(const ss_grid *g, int weather, const int *band_rows,
                                   int n_band_rows)
{
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 12;
    ss_insolation_options io = {.albedo = 0.25, .shadow_mode = SS_SHADOW_EXACT};
    lattice_setup sun;
    grids out[2];
    int ok = lattice_init(&sun, g) && grids_init(&out[0], g, NULL) && grids_init(&out[1], g, NULL);
    size_t n = (size_t)g->width * g->height;
    int same_whole = 1, same_bands = 1, runs = 0;
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    sun.weather = weather;
    for (int b = -1; ok && b < n_band_rows; ++b) {
        for (int use = 0; use < 2 && ok; ++use) {
            sun.use_lattice = use;
            grids *o = &out[use];
            ss_insolation_out whole = {.global = o->out[0],
                                       .beam = o->out[1],
                                       .diffuse = o->out[2],
                                       .reflected = o->out[3],
                                       .sun_hours = o->out[4]};
            ss_source src = b >= 0 ? test_source(g, read_rows, o, band_rows[b], NULL)
                                   : (ss_source){0};
            ok = (b < 0 ? ss_insolation(ctx, g, &opt, &io, N_STEPS, lattice_sun_whole, &sun,
                                        whole_step, o, &whole)
                        : ss_insolation_rows(ctx, &src, &opt, &io, N_STEPS, lattice_sun, &sun,
                                             SS_INSOLATION_STEPS, NULL, write_rows, o)) == SS_OK;
            runs += ok;
        }
        int same = ok;
        for (int k = 0; ok && k < 5; ++k)
            same &= same_floats(out[0].out[k], out[1].out[k], n);
        for (int k = 0; ok && k < N_STEPS; ++k)
            same &= same_floats(out[0].steps[k], out[1].steps[k], n);
        *(b < 0 ? &same_whole : &same_bands) &= same;
    }
    tap_ok(ok && same_whole && same_bands,
           "%s, a sun per cell as a lattice: the whole grid's and %d band heights' outputs and "
           "steps are those of the arrays it fills, to the bit (%d runs)%s%s",
           weather ? "weather records" : "clear sky", n_band_rows, runs, ok ? "" : ": ",
           ok ? "" : ss_ctx_message(ctx));
    /* A lattice one column short of the grid is refused, not extrapolated. */
    sun.use_lattice = 1;
    sun.cols[LATTICE_COLS - 1] = g->width - 2;
    ss_insolation_out whole = {.global = out[0].out[0],
                               .beam = out[0].out[1],
                               .diffuse = out[0].out[2],
                               .reflected = out[0].out[3],
                               .sun_hours = out[0].out[4]};
    ss_status st = ss_insolation(ctx, g, &opt, &io, N_STEPS, lattice_sun_whole, &sun, NULL, NULL,
                                 &whole);
    tap_ok(st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), "sun lattice does not span"),
           "%s: a lattice short of the grid's last column is refused: %s",
           weather ? "weather records" : "clear sky", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    lattice_free(&sun);
    grids_free(&out[0]);
    grids_free(&out[1]);
}

/* Insolation's steps on an OpenCL device (ss_ctx_set_cells), each cell's
 * sun from the lattice there (kernels/ss_sun_lattice.h), its shadows from
 * the walk left there or from the stored horizons uploaded there
 * (interpolated), each step's global read back where asked for, whole and
 * in bands: the same device's outputs with the steps on the host to float
 * rounding (a clear sky's sun terms are exact on the device, from tables
 * on the host), and the C twin's within what the device's walks and the
 * bands' sums move them. Skipped without a device. */
static void lattice_on_device(const ss_grid *g, int weather, ss_shadow_mode shadows, int steps,
                              const int *band_rows, int n_band_rows)
{
    ss_ctx *dev = opencl_or_skip("insolation's steps on a device"), *twin = ss_ctx_new();
    if (!dev) {
        ss_ctx_free(twin);
        return;
    }
    ss_ctx_use_device(twin, "reference");
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 12;
    ss_insolation_options io = {.albedo = 0.25, .shadow_mode = shadows};
    int want = steps ? SS_INSOLATION_STEPS : 0;
    lattice_setup sun;
    grids twin_out, host, device;
    int ok = lattice_init(&sun, g) && grids_init(&twin_out, g, NULL) &&
             grids_init(&host, g, NULL) && grids_init(&device, g, NULL);
    size_t n = (size_t)g->width * g->height, nodata_mismatch = 0;
    sun.weather = weather;
    sun.use_lattice = 1;
    ss_source whole = test_source(g, read_rows, &twin_out, 0, NULL);
    ok = ok && ss_insolation_rows(twin, &whole, &opt, &io, N_STEPS, lattice_sun, &sun, want, NULL,
                                  write_rows, &twin_out) == SS_OK;
    double worst_host = 0, worst_twin = 0;
    uint64_t on_device = 0, left_on_host = 0;
    int runs = 0, bad_writes = 0;
    for (int b = -1; ok && b < n_band_rows; ++b)
        for (int where = 0; ok && where < 2; ++where) {
            grids *o = where ? &device : &host;
            ss_source src = test_source(g, read_rows, o, b < 0 ? 0 : band_rows[b], NULL);
            ss_ctx_set_cells(dev, where ? SS_CELLS_DEVICE : SS_CELLS_HOST);
            /* What a run leaves unwritten shows, and what it writes twice. */
            for (size_t c = 0; c < n; ++c) {
                for (int k = 0; k < 5; ++k)
                    o->out[k][c] = -7777.0f;
                for (int k = 0; k < N_STEPS; ++k)
                    o->steps[k][c] = -7777.0f;
            }
            memset(o->writes, 0, sizeof(int) * (size_t)(N_STEPS + 1) * g->height);
            ss_counters before = ss_ctx_counters(dev);
            ok = ss_insolation_rows(dev, &src, &opt, &io, N_STEPS, lattice_sun, &sun, want, NULL,
                                    write_rows, o) == SS_OK;
            ss_counters after = ss_ctx_counters(dev);
            on_device += after.cell_steps_on_device - before.cell_steps_on_device;
            if (where) /* every cell-step, walked, stored or unshaded, on the device */
                left_on_host += (after.cell_steps - before.cell_steps) -
                                (after.cell_steps_on_device - before.cell_steps_on_device);
            for (int k = 0; k < (steps ? N_STEPS + 1 : 1); ++k)
                for (int r = 0; r < g->height; ++r)
                    bad_writes += o->writes[(size_t)k * g->height + r] != 1;
            runs += ok;
            float *const *host_out = host.out, *const *device_out = device.out,
                        *const *twin_outs = twin_out.out;
            int outputs = 5;
            for (int pass = 0; ok && where && pass < 1 + steps; ++pass) {
                if (pass) { /* each step's global */
                    host_out = host.steps;
                    device_out = device.steps;
                    twin_outs = twin_out.steps;
                    outputs = N_STEPS;
                }
                for (int k = 0; k < outputs; ++k) {
                    worst_host = fmax(worst_host, worst_of(host_out[k], device_out[k], n,
                                                           &nodata_mismatch));
                    worst_twin = fmax(worst_twin, worst_of(twin_outs[k], device_out[k], n,
                                                           &nodata_mismatch));
                }
            }
        }
    tap_ok(ok && worst_host <= 2e-6 && worst_twin <= 5e-5 && nodata_mismatch == 0 &&
               on_device > 0 && left_on_host == 0 && bad_writes == 0,
           "%s, %s shadows%s, a sun per cell as a lattice, steps on the device (%d runs, whole "
           "and %d band heights): the outputs of the steps on the host within %.2g relative "
           "(2e-6 allowed), the C twin's within %.2g (5e-5), %llu cell-steps on the device and "
           "%llu left on the host, %d rows not written once%s%s",
           weather ? "weather records" : "clear sky",
           shadows == SS_SHADOW_EXACT ? "exact" : "interpolated",
           steps ? ", each step's global" : "", runs, n_band_rows, worst_host, worst_twin,
           (unsigned long long)on_device, (unsigned long long)left_on_host, bad_writes,
           ok ? "" : ": ", ok ? "" : ss_ctx_message(dev));
    ss_ctx_free(dev);
    ss_ctx_free(twin);
    lattice_free(&sun);
    grids_free(&twin_out);
    grids_free(&host);
    grids_free(&device);
}

/* Exact box shadows by each cell's own ray (src/core/box_shadow.c) in the
 * whole-grid insolation, with one sun and a sun per cell (2.5 degrees of
 * spread), against the walks of 64 box-line families, which agree with
 * the box model on all but a few cells in a thousand: the hours of sun
 * (whole half hours) must be the same on 99 % of cells, and the march
 * must have run for every daylight step. A wrong sun, azimuth frame or
 * range of elevations handed to the march breaks that on most cells. */
static void march_against_lines(const ss_grid *g, int per_cell)
{
    size_t n = (size_t)g->width * g->height;
    float *hours[2] = {malloc(n * sizeof(float)), malloc(n * sizeof(float))};
    float *rest[4] = {malloc(n * sizeof(float)), malloc(n * sizeof(float)),
                      malloc(n * sizeof(float)), malloc(n * sizeof(float))};
    sun_setup sun;
    int ok = sun_init(&sun, g, per_cell) && hours[0] && hours[1] && rest[0] && rest[1] &&
             rest[2] && rest[3];
    uint64_t marched_steps = 0;
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    for (int m = 0; ok && m < 2; ++m) {
        ss_sweep_options opt;
        ss_sweep_options_default(&opt);
        opt.lines = SS_LINES_BOX;
        opt.box_lines = 64;
        opt.box_shadows = m ? SS_BOX_SHADOWS_MARCH : SS_BOX_SHADOWS_LINES;
        opt.directions = 12;
        ss_insolation_options io = {.albedo = 0.25, .shadow_mode = SS_SHADOW_EXACT};
        ss_insolation_out out = {.global = rest[0],
                                 .beam = rest[1],
                                 .diffuse = rest[2],
                                 .reflected = rest[3],
                                 .sun_hours = hours[m]};
        ok = ss_insolation(ctx, g, &opt, &io, N_STEPS, sun_whole, &sun, NULL, NULL, &out) ==
             SS_OK;
        if (!ok)
            tap_diag("insolation failed: %s", ss_ctx_message(ctx));
        if (m)
            marched_steps = ss_ctx_counters(ctx).box_march_steps;
    }
    ss_ctx_free(ctx);
    size_t same = 0, valid = 0;
    for (size_t c = 0; ok && c < n; ++c)
        if (isfinite(g->z[c])) {
            valid++;
            same += hours[0][c] == hours[1][c];
        }
    /* Six of the seven steps are in daylight. */
    tap_ok(ok && valid && same >= 0.99 * valid && marched_steps == N_STEPS - 1,
           "box city, %s: insolation's box shadows by each cell's own ray give the hours of sun "
           "of 64 box-line families on %.2f %% of cells (at least 99 %%), in %llu marched steps",
           per_cell ? "a sun per cell" : "one sun", valid ? 100.0 * same / valid : 0.0,
           (unsigned long long)marched_steps);
    sun_free(&sun);
    for (int k = 0; k < 2; ++k)
        free(hours[k]);
    for (int k = 0; k < 4; ++k)
        free(rest[k]);
}

/* The march runs on the host on every device, and so do the steps that
 * use it: on an OpenCL device asked to keep the steps in its memory (as a
 * GPU does, SS_CELLS_DEVICE), a whole-grid exact run on box lines marches
 * every daylight step and adds no cell-step there, and its hours of sun
 * are the C twin's on every cell (the shadows are the same march), its
 * global within what the device's sky-view walks move it. Skipped
 * without a device. */
static void march_on_device(const ss_grid *g)
{
    ss_ctx *dev = opencl_or_skip("the box shadows' march in insolation on a device"),
           *twin = ss_ctx_new();
    if (!dev) {
        ss_ctx_free(twin);
        return;
    }
    ss_ctx_use_device(twin, "reference");
    ss_ctx_set_cells(dev, SS_CELLS_DEVICE);
    size_t n = (size_t)g->width * g->height;
    float *hours[2], *global[2];
    sun_setup sun;
    int ok = sun_init(&sun, g, 0);
    ss_counters before = ss_ctx_counters(dev), after = before;
    for (int k = 0; k < 2; ++k) {
        hours[k] = malloc(n * sizeof(float));
        global[k] = malloc(n * sizeof(float));
        ok = ok && hours[k] && global[k];
    }
    for (int k = 0; ok && k < 2; ++k) {
        ss_ctx *ctx = k ? dev : twin;
        ss_sweep_options opt;
        ss_sweep_options_default(&opt);
        opt.lines = SS_LINES_BOX;
        opt.directions = 12;
        ss_insolation_options io = {.albedo = 0.25, .shadow_mode = SS_SHADOW_EXACT};
        ss_insolation_out out = {.global = global[k], .sun_hours = hours[k]};
        ok = ss_insolation(ctx, g, &opt, &io, N_STEPS, sun_whole, &sun, NULL, NULL, &out) ==
             SS_OK;
        if (!ok)
            tap_diag("insolation failed: %s", ss_ctx_message(ctx));
    }
    after = ss_ctx_counters(dev);
    size_t nodata_mismatch = 0, hours_differ = 0;
    for (size_t c = 0; ok && c < n; ++c)
        hours_differ += memcmp(&hours[0][c], &hours[1][c], sizeof(float)) != 0;
    double worst = ok ? worst_of(global[0], global[1], n, &nodata_mismatch) : INFINITY;
    uint64_t marched = after.box_march_steps - before.box_march_steps;
    uint64_t on_device = after.cell_steps_on_device - before.cell_steps_on_device;
    tap_ok(ok && marched == N_STEPS - 1 && on_device == 0 && hours_differ == 0 &&
               nodata_mismatch == 0 && worst <= 5e-5,
           "box city, insolation on %s with the steps asked on the device: %llu marched steps "
           "(want %d), %llu cell-steps on the device (want 0), hours of sun differing from the "
           "C twin's on %zu cells, the global within %.2g relative (5e-5 allowed)",
           ss_ctx_device_name(dev), (unsigned long long)marched, N_STEPS - 1,
           (unsigned long long)on_device, hours_differ, worst);
    sun_free(&sun);
    for (int k = 0; k < 2; ++k)
        free(hours[k]), free(global[k]);
    ss_ctx_free(dev);
    ss_ctx_free(twin);
}

/* The global of a whole-grid exact run with box lines (box_lines,
 * sky_box_lines; the sky view on them, --box-sky lines) and shadows by
 * each cell's own ray. */
static int box_run(const ss_grid *g, sun_setup *sun, int box_lines, int sky_box_lines,
                   float *global)
{
    size_t n = (size_t)g->width * g->height;
    float *rest = malloc(4 * n * sizeof(float));
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = SS_LINES_BOX;
    opt.box_lines = box_lines;
    opt.sky_box_lines = sky_box_lines;
    opt.box_sky = SS_BOX_SKY_LINES; /* the sky view on the lines, not each cell's own ray */
    opt.directions = 12;
    ss_insolation_options io = {.albedo = 0.25, .shadow_mode = SS_SHADOW_EXACT};
    ss_insolation_out out = {.global = global,
                             .beam = rest,
                             .diffuse = rest + n,
                             .reflected = rest + 2 * n,
                             .sun_hours = rest + 3 * n};
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    int ok = rest && ss_insolation(ctx, g, &opt, &io, N_STEPS, sun_whole, sun, NULL, NULL,
                                   &out) == SS_OK;
    ss_ctx_free(ctx);
    free(rest);
    return ok;
}

/* sky_box_lines: the sky view's own box lines per cell, where the exact
 * shadows come from each cell's own ray and take none: 32 lines with a sky
 * view of 2 give 2 lines' global to the bit, and not 32's. */
static void sky_box_lines_obeyed(const ss_grid *g)
{
    size_t n = (size_t)g->width * g->height;
    float *global[3] = {malloc(n * sizeof(float)), malloc(n * sizeof(float)),
                        malloc(n * sizeof(float))};
    sun_setup sun;
    int ok = global[0] && global[1] && global[2] && sun_init(&sun, g, 0) &&
             box_run(g, &sun, 32, 2, global[0]) && box_run(g, &sun, 2, 0, global[1]) &&
             box_run(g, &sun, 32, 0, global[2]);
    int same = ok && memcmp(global[0], global[1], n * sizeof(float)) == 0;
    int other = ok && memcmp(global[0], global[2], n * sizeof(float)) != 0;
    tap_ok(same && other,
           "box city, exact shadows by each cell's own ray: 32 box lines with the sky view's 2 "
           "give 2 lines' global to the bit (%s), not 32's (%s)",
           same ? "yes" : "no", other ? "differs" : "the same");
    sun_free(&sun);
    for (int k = 0; k < 3; ++k)
        free(global[k]);
}

/* The box model's horizons by each cell's own ray in bands (horizon_walk.c):
 * the stored horizons of interpolated shadows, and under weather records
 * Perez's horizon band, which takes each cell's horizons too. A cell's
 * ray reads the heights held whole and its own cell alone, so each step's
 * global is the whole grid's to the bit in every band height, and so are
 * the summed outputs from one band height to the next. Against the whole
 * grid the sums differ in their order alone (a run of several bands sums
 * each pass's steps, then the passes: compare_lines), by a rounding per
 * step; band_rows[0] must be under the grid's height. */
static void rays_in_bands(const ss_grid *g, int weather, ss_shadow_mode shadows,
                          const int *band_rows, int n_band_rows)
{
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = SS_LINES_BOX;
    opt.box_lines = 8;
    opt.directions = 12;
    ss_insolation_options io = {.albedo = 0.25,
                                .shadow_mode = shadows,
                                .sky_model = weather ? SS_SKY_MODEL_PEREZ : SS_SKY_MODEL_ISOTROPIC};
    sun_setup sun;
    grids whole, first, banded;
    int ok = sun_init(&sun, g, 1) && grids_init(&whole, g, &sun) && grids_init(&first, g, &sun) &&
             grids_init(&banded, g, &sun);
    sun.weather = weather;
    size_t n = (size_t)g->width * g->height, mismatch = 0;
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    int steps_same = 1, sums_same = 1, runs = 0, rays = 0;
    double worst = 0;
    for (int b = -1; ok && b < n_band_rows; ++b) {
        grids *o = b < 0 ? &whole : b == 0 ? &first : &banded;
        ss_source src = test_source(g, read_rows, o, b < 0 ? 0 : band_rows[b], NULL);
        uint64_t before = ss_ctx_counters(ctx).box_sky_directions;
        ok = ss_insolation_rows(ctx, &src, &opt, &io, N_STEPS, sun_rows, &sun,
                                SS_INSOLATION_STEPS, NULL, write_rows, o) == SS_OK;
        runs += ok;
        rays += ok && ss_ctx_counters(ctx).box_sky_directions > before;
        for (int k = 0; ok && b >= 0 && k < N_STEPS; ++k)
            steps_same &= same_floats(whole.steps[k], o->steps[k], n);
        for (int k = 0; ok && b >= 0 && k < 5; ++k) {
            worst = fmax(worst, worst_of(whole.out[k], o->out[k], n, &mismatch));
            /* A band of the whole grid's height sums as the whole grid;
             * the others as the first band height. */
            if (b > 0)
                sums_same &= same_floats(band_rows[b] >= g->height ? whole.out[k] : first.out[k],
                                         o->out[k], n);
        }
    }
    tap_ok(ok && steps_same && sums_same && !mismatch && worst <= 1.2e-7 * N_STEPS &&
               rays == n_band_rows + 1,
           "box city, %s, %s shadows, the horizons by each cell's own ray: %d band heights give "
           "the whole grid's steps to the bit (%s) and each other's sums to the bit (%s), within "
           "%.2g of the whole grid's (want <= %.2g: the order of the sums; %zu nodata "
           "mismatches; %d runs, %d by the rays)%s%s",
           weather ? "weather records under Perez's sky" : "clear sky",
           shadows == SS_SHADOW_EXACT ? "exact" : "interpolated", n_band_rows,
           steps_same ? "yes" : "no", sums_same ? "yes" : "no", worst, 1.2e-7 * N_STEPS, mismatch,
           runs, rays, ok ? "" : ": ", ok ? "" : ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    sun_free(&sun);
    grids_free(&whole);
    grids_free(&first);
    grids_free(&banded);
}

static void compare(ss_ctx *ctx, const ss_grid *g, const char *terrain, int per_cell, int curved,
                    int first, int n_steps, const int *band_rows, int n_band_rows)
{
    compare_lines(ctx, g, terrain, per_cell, curved, first, n_steps, band_rows, n_band_rows, 0, 0,
                  0);
}

int main(void)
{
    static const int band_rows[] = {1, 2, 5, 16, 200};
    ss_ctx *twin = ss_ctx_new();
    ss_ctx_use_device(twin, "reference");
    ss_grid g = test_grid(41, 36, 25, 25);
    test_fill(&g, TERRAIN_SMOOTH, 17, 700);
    test_holes(&g, 6, 4, 5);
    g.z_origin_m = 1200.0; /* the air pressure sees heights above the datum */
    const int nb = (int)(sizeof band_rows / sizeof *band_rows);
    compare(twin, &g, "smooth hills 41x36", 0, 0, 0, N_STEPS, band_rows, nb);
    compare(twin, &g, "smooth hills 41x36", 1, 1, 0, N_STEPS, band_rows, nb);
    ss_grid_free(&g);
    ss_grid s = test_grid(30, 44, 10, 10);
    test_fill(&s, TERRAIN_SPIKES, 4, 250);
    test_holes(&s, 3, 3, 4);
    compare(twin, &s, "spikes 30x44", 1, 0, 0, N_STEPS, band_rows, nb);
    /* 150 steps, 128 of them in daylight: two groups of 64 and one of 0
     * (SS_INSOLATION_STEPS_PER_RUN), their sums carried between runs. */
    compare(twin, &s, "spikes 30x44, 150 steps", 1, 0, 0, 150, band_rows, nb);
    /* The same on box lines of 32 families, whose walks repay bounds per
     * sector (lit_levels.h): every banded run stops walks by them. */
    compare_lines(twin, &s, "spikes 30x44, 150 steps, box lines x32", 1, 0, 0, 150, band_rows, nb, 32,
                  0, 1);
    /* The same bounds on an OpenCL device in bands, each band's levels
     * loaded with its heights: the whole grid's answer there. */
    ss_ctx *dev = opencl_or_skip("banded insolation stopped by the bounds on a device");
    if (dev) {
        compare_lines(dev, &s, "spikes 30x44, 150 steps, box lines x32", 1, 0, 0, 150, band_rows,
                      nb, 32, 0, 0);
        compare(dev, &s, "spikes 30x44, 150 steps", 1, 0, 0, 150, band_rows, nb);
        ss_ctx_free(dev);
    }
    /* Only the night step: nothing swept, every row still written. */
    compare(twin, &s, "spikes 30x44, night only", 0, 0, N_STEPS - 1, 1, band_rows, nb);
    ss_grid city = box_march_city(90);
    /* Each cell's own ray in bands, from the heights held whole: the
     * whole grid's shadows to the bit (the hours of sun exact). */
    compare_lines(twin, &city, "box city 90x90, box lines x8 marched", 0, 1, 0, N_STEPS, band_rows, nb,
                  8, 1, 0);
    compare_lines(twin, &city, "box city 90x90, box lines x8 marched", 1, 0, 0, N_STEPS, band_rows, nb,
                  8, 1, 0);
    march_against_lines(&city, 0);
    march_against_lines(&city, 1);
    march_on_device(&city);
    sky_box_lines_obeyed(&city);
    rays_in_bands(&city, 1, SS_SHADOW_EXACT, band_rows, nb);
    rays_in_bands(&city, 1, SS_SHADOW_INTERPOLATED, band_rows, nb);
    rays_in_bands(&city, 0, SS_SHADOW_INTERPOLATED, band_rows, nb);
    ss_grid_free(&city);
    lattice_against_arrays(&s, 0, band_rows, nb);
    lattice_against_arrays(&s, 1, band_rows, nb);
    lattice_on_device(&s, 0, SS_SHADOW_EXACT, 0, band_rows, nb);
    lattice_on_device(&s, 1, SS_SHADOW_EXACT, 1, band_rows, nb);
    lattice_on_device(&s, 0, SS_SHADOW_INTERPOLATED, 1, band_rows, nb);
    lattice_on_device(&s, 1, SS_SHADOW_INTERPOLATED, 0, band_rows, nb);
    ss_grid_free(&s);
    ss_ctx_free(twin);
    return tap_done();
}
