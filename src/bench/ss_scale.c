/* ss-scale: a sweep in bands (ss_sky_rows, ss_horizon_rows with
 * --horizon, or ss_insolation_rows with --insolation) on a synthetic fractal
 * DEM of any size, generated band by band as it is read, so that nothing
 * but the bands is ever held: the figures of doc/scale.md. Links only the
 * core.
 *
 *   ss-scale --size N [--directions D] [--band-rows R | --memory MIB]
 *            [--whole] [--horizon | --insolation RANGE [--interpolated]]
 *            [--cell METRES] [--device SPEC]
 *
 * --insolation takes a time range with its step as the CLI's --time does
 * (2026-01-01T00:00Z/P1Y/PT1H: a year of hourly steps), with the clear sky
 * of Linke 3 over a DEM placed at 19.4 N 155.3 W, exact shadows unless
 * --interpolated; --whole then runs ss_insolation on the grid held whole.
 *
 * Prints wall time, cell-directions per second, peak resident memory, and
 * the hulls handed on between bands; --whole runs the whole-grid sweep on
 * the same DEM instead (it must fit in memory), for a side-by-side row. */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "skysweep.h"
#include "skysweep_sun.h"

static double seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct {
    int size;
    int directions;
    int band_rows;
    double memory_mib;
    int whole;
    int horizon; /* horizon angles (one grid per direction) instead of SVF */
    const char *insolation; /* a time range: clear-sky insolation instead of SVF */
    int interpolated;       /* insolation's shadows interpolated between directions */
    double cell_m;
    const char *device;
} scale_args;

static int parse(int argc, char **argv, scale_args *a)
{
    *a = (scale_args){.directions = 16, .cell_m = 30.0};
    for (int i = 1; i < argc; ++i) {
        const char *o = argv[i];
        int more = argc - i - 1;
        if (!strcmp(o, "--size") && more)
            a->size = atoi(argv[++i]);
        else if (!strcmp(o, "--directions") && more)
            a->directions = atoi(argv[++i]);
        else if (!strcmp(o, "--band-rows") && more)
            a->band_rows = atoi(argv[++i]);
        else if (!strcmp(o, "--memory") && more)
            a->memory_mib = atof(argv[++i]);
        else if (!strcmp(o, "--cell") && more)
            a->cell_m = atof(argv[++i]);
        else if (!strcmp(o, "--device") && more)
            a->device = argv[++i];
        else if (!strcmp(o, "--whole"))
            a->whole = 1;
        else if (!strcmp(o, "--horizon"))
            a->horizon = 1;
        else if (!strcmp(o, "--insolation") && more)
            a->insolation = argv[++i];
        else if (!strcmp(o, "--interpolated"))
            a->interpolated = 1;
        else {
            fprintf(stderr, "ss-scale: bad argument '%s' (see the comment in ss_scale.c)\n", o);
            return -1;
        }
    }
    if (a->size < 2 || a->directions < 1) {
        fprintf(stderr, "ss-scale: --size N >= 2 and --directions >= 1 are needed\n");
        return -1;
    }
    if (a->horizon && a->insolation) {
        fprintf(stderr, "ss-scale: --horizon or --insolation, not both\n");
        return -1;
    }
    return 0;
}

/* Value noise on an integer lattice, smoothly interpolated: octaves of it
 * from 2048 cells down to 4 make a fractal (fBm) landscape whose heights
 * any band computes on its own. */
static double lattice(int64_t x, int64_t y, int octave)
{
    uint64_t h = (uint64_t)x * 0x9E3779B97F4A7C15ull ^ (uint64_t)y * 0xC2B2AE3D27D4EB4Full ^
                 (uint64_t)octave * 0x165667B19E3779F9ull;
    h ^= h >> 31;
    h *= 0xD6E8FEB86659FD93ull;
    h ^= h >> 32;
    return (double)(h >> 11) / 9007199254740992.0; /* [0, 1) */
}

static double fractal_height(int row, int col)
{
    double z = 0, amplitude = 1200;
    int wavelength = 2048;
    for (int octave = 0; wavelength >= 4; ++octave, wavelength /= 2, amplitude *= 0.5) {
        double fx = (double)col / wavelength, fy = (double)row / wavelength;
        int64_t x0 = (int64_t)floor(fx), y0 = (int64_t)floor(fy);
        double tx = fx - x0, ty = fy - y0;
        tx = tx * tx * (3 - 2 * tx);
        ty = ty * ty * (3 - 2 * ty);
        double a = lattice(x0, y0, octave), b = lattice(x0 + 1, y0, octave);
        double c = lattice(x0, y0 + 1, octave), d = lattice(x0 + 1, y0 + 1, octave);
        z += amplitude * ((a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty);
    }
    return z;
}

typedef struct {
    int width;
    double checksum; /* of the product, so the work cannot be skipped */
    size_t rows_written;
} scale_io;

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    scale_io *s = user;
#pragma omp parallel for schedule(static)
    for (int r = 0; r < n_rows; ++r)
        for (int c = 0; c < s->width; ++c)
            z[(size_t)r * s->width + c] = (float)fractal_height(row0 + r, c);
    return SS_OK;
}

/* The product's rows (horizons: every direction's angles, degrees). */
static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)output, (void)index, (void)row0;
    scale_io *s = user;
    for (size_t c = 0; c < (size_t)n_rows * s->width; ++c)
        s->checksum += values[c];
    s->rows_written += (size_t)n_rows;
    return SS_OK;
}

/* Insolation's rows: only the global counts towards the check. */
static ss_status global_rows(void *user, int output, int index, int row0, int n_rows,
                             const float *values)
{
    return output == SS_OUT_GLOBAL ? write_rows(user, output, index, row0, n_rows, values) : SS_OK;
}

static int horizon_sink(int index, double azimuth_deg, const float *angle_deg,
                        const float *dist_m, const float *cast_height_m, void *user)
{
    (void)index, (void)azimuth_deg, (void)dist_m, (void)cast_height_m;
    scale_io *s = user;
    return write_rows(user, 0, 0, 0, s->width /* a square grid */, angle_deg) == SS_OK;
}

/* The clear-sky suns of a time range's steps, at one place. */
typedef struct {
    ss_sun_step *steps;
    int n;
    long long daylight;
} scale_suns;

static ss_status make_suns(ss_ctx *ctx, const char *range_text, const ss_sweep_options *opt,
                           scale_suns *suns)
{
    ss_time_range range;
    ss_status st = ss_parse_time_range(ctx, range_text, &range);
    if (st == SS_OK && (!range.has_step || range.count > 1000000))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "--insolation needs START/END/STEP with at "
                                                  "most a million steps");
    if (st != SS_OK)
        return st;
    suns->n = (int)range.count;
    suns->steps = calloc((size_t)suns->n, sizeof *suns->steps);
    if (!suns->steps)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for %d steps", suns->n);
    ss_spa_params p;
    ss_spa_params_default(&p);
    for (int k = 0; k < suns->n && st == SS_OK; ++k) {
        double mid, hours;
        ss_spa_result sun;
        ss_time_range_step(&range, k, &mid, &hours);
        st = ss_spa(ctx, mid, 19.4, -155.3, &p, &sun);
        if (st == SS_OK)
            ss_sun_step_clear_sky(&sun, sun.azimuth_deg, opt->grid_north_deg, hours, 3.0,
                                  1361.0, &suns->steps[k]);
        suns->daylight += suns->steps[k].elevation_deg > 0;
    }
    return st;
}

static ss_status sun_of_step(ss_ctx *ctx, int index, ss_sun_step *step, void *user)
{
    (void)ctx;
    *step = ((const scale_suns *)user)->steps[index];
    return SS_OK;
}

static ss_status sun_of_step_rows(ss_ctx *ctx, int index, int row0, int n_rows, ss_sun_step *step,
                                  void *user)
{
    (void)row0, (void)n_rows;
    return sun_of_step(ctx, index, step, user);
}

int main(int argc, char **argv)
{
    scale_args a;
    if (parse(argc, argv, &a) != 0)
        return 2;
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, a.device ? a.device : "reference");
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = a.directions;
    int n = a.size;
    scale_io s = {n, 0, 0};
    ss_band_stats stats = {0};
    ss_insolation_options io = {.albedo = 0.2,
                                .shadow_mode = a.interpolated ? SS_SHADOW_INTERPOLATED
                                                              : SS_SHADOW_EXACT};
    scale_suns suns = {0};
    if (a.insolation && make_suns(ctx, a.insolation, &opt, &suns) != SS_OK) {
        fprintf(stderr, "ss-scale: %s\n", ss_ctx_message(ctx));
        return 2;
    }
    double t0 = seconds_now();
    ss_status st;
    int band_rows = a.band_rows;
    if (a.whole) {
        ss_grid g;
        st = ss_grid_alloc(ctx, &g, n, n, a.cell_m, a.cell_m);
        float *out = st == SS_OK ? malloc(sizeof(float) * (size_t)n * n) : NULL;
        if (st == SS_OK && out) {
            read_rows(&s, 0, n, g.z);
            if (a.horizon) {
                st = ss_horizon(ctx, &g, &opt, 0, horizon_sink, &s);
            } else if (a.insolation) {
                ss_insolation_out io_out = {.global = out};
                float *parts = malloc(sizeof(float) * (size_t)n * n * 4);
                io_out.beam = parts;
                io_out.diffuse = parts ? parts + (size_t)n * n : NULL;
                io_out.reflected = parts ? parts + (size_t)2 * n * n : NULL;
                io_out.sun_hours = parts ? parts + (size_t)3 * n * n : NULL;
                st = parts ? ss_insolation(ctx, &g, &opt, &io, suns.n, sun_of_step, &suns, NULL,
                                           NULL, &io_out)
                           : ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
                free(parts);
                write_rows(&s, 0, 0, 0, n, out);
            } else {
                st = ss_svf(ctx, &g, &opt, SS_SVF_DEF_GEOMETRIC, out);
                write_rows(&s, 0, 0, 0, n, out);
            }
        }
        free(out);
        if (st == SS_OK)
            ss_grid_free(&g);
    } else {
        if (band_rows < 1) {
            /* The CLI's rule for --memory (default 256 MiB). */
            double budget = (a.memory_mib > 0 ? a.memory_mib : 256) * 1048576.0;
            /* As the CLI sizes an insolation run's bands (cmd_insolation.c). */
            int held = a.directions > SS_INSOLATION_STEPS_PER_RUN ? a.directions
                                                                  : SS_INSOLATION_STEPS_PER_RUN;
            band_rows = a.insolation ? ss_band_rows_within(n, n, held, budget,
                                                           ss_horizon_band_cell_bytes(0) +
                                                               ss_insolation_band_cell_bytes(0, 0),
                                                           ss_horizon_column_bytes())
                        : a.horizon ? ss_band_rows_within(n, n, a.directions, budget,
                                                          ss_horizon_band_cell_bytes(0),
                                                          ss_horizon_column_bytes())
                                    : ss_band_rows_for(n, n, a.directions, budget);
            if (band_rows == 0)
                band_rows = n;
            if (band_rows < 0) {
                fprintf(stderr, "ss-scale: %g MiB is too small for one band\n", a.memory_mib);
                return 2;
            }
        }
        ss_source src = {.width = n,
                         .height = n,
                         .cell_x_m = a.cell_m,
                         .cell_y_m = a.cell_m,
                         .read = read_rows,
                         .read_user = &s,
                         .band_rows = band_rows,
                         .stats = &stats};
        st = a.insolation ? ss_insolation_rows(ctx, &src, &opt, &io, suns.n, sun_of_step_rows,
                                               &suns, 0, NULL, global_rows, &s)
             : a.horizon  ? ss_horizon_rows(ctx, &src, &opt, 0, write_rows, &s)
                          : ss_sky_rows(ctx, &src, &opt, SS_SKY_SVF_GEOMETRIC, 0.0, NULL,
                                        write_rows, &s);
    }
    double wall = seconds_now() - t0;
    if (st != SS_OK) {
        fprintf(stderr, "ss-scale: %s\n", ss_ctx_message(ctx));
        return 5;
    }
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double cd = (double)n * n * a.directions;
    const char *product = a.insolation ? "insolation" : a.horizon ? "horizon" : "SVF";
    printf("grid      %d x %d (%.0f MiB of float heights), %d directions, %s %s\n", n, n,
           (double)n * n * 4 / 1048576.0, a.directions, a.whole ? "whole grid" : "banded",
           product);
    if (a.insolation) {
        ss_counters c = ss_ctx_counters(ctx);
        printf("steps     %d of '%s', %lld in daylight, %s shadows; %.0f %% of the cell-steps "
               "on the device\n",
               suns.n, a.insolation, suns.daylight, a.interpolated ? "interpolated" : "exact",
               c.cell_steps ? 100.0 * (double)c.cell_steps_on_device / (double)c.cell_steps : 0.0);
    }
    if (!a.whole && !a.insolation)
        printf("bands     %d rows (%.1f MiB of band buffers)\n", band_rows,
               (a.horizon ? ss_horizon_band_cell_bytes(0) * (band_rows + 4.0) * n
                          : (double)ss_band_bytes(n, band_rows)) /
                   1048576.0);
    else if (!a.whole)
        printf("bands     %d rows\n", band_rows);
    printf("device    %s\n", ss_ctx_device_name(ctx));
    if (a.insolation)
        printf("time      %.2f s wall, %.1f M cell-steps/s of daylight (DEM generated on the "
               "fly)\n",
               wall, (double)n * n * (double)suns.daylight / wall / 1e6);
    else
        printf("time      %.2f s wall, %.1f M cell-directions/s (DEM generated on the fly)\n",
               wall, cd / wall / 1e6);
    printf("peak RSS  %.1f MiB\n", ru.ru_maxrss / 1024.0);
    if (!a.whole)
        printf("hulls     %zu handed on, mean %.1f points, max %zu\n", stats.handoffs,
               stats.handoffs ? (double)stats.hull_points_handed_on / stats.handoffs : 0.0,
               stats.max_hull_points);
    if (a.insolation)
        printf("check     mean global %.3f Wh/m2 over %zu rows\n", s.checksum / ((double)n * n),
               s.rows_written);
    else if (a.horizon)
        printf("check     mean horizon %.6f deg over %zu rows of all directions\n",
               s.checksum / ((double)n * n * a.directions), s.rows_written);
    else
        printf("check     mean SVF %.6f over %zu rows\n", s.checksum / ((double)n * n),
               s.rows_written);
    free(suns.steps);
    ss_ctx_free(ctx);
    return 0;
}
