/* Insolation of a DEM that is never held whole (ss_insolation_banded).
 *
 * First the radiative SVF, which the diffuse and reflected terms need, is
 * swept in bands (ss_sky_banded) into a temporary file of floats. Then
 * every daylight step is one direction of a banded horizon run
 * (ss_horizon_banded) at its sun's azimuth, the horizontal where nothing
 * lies ahead, as ss_cast_shadow takes it. A band's rows arrive from every
 * direction of a pass in turn, so each band keeps its cells' terms
 * (gradient, SVF, slope term, air pressure) and five sums while it is
 * walked; at the end of the first pass its sums wait in a second temporary
 * file, at the end of the second they are added to it, finished and
 * written. Each cell's step is insolation_cell.h's, as on the whole grid. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "insolation_cell.h"
#include "products_internal.h"

#define N_SUMS 5 /* beam, diffuse, reflected, global, sun hours */

enum { STEP_NIGHT, STEP_DAY, STEP_ELSEWHERE /* another process's */ };

typedef struct {
    ss_ctx *ctx;
    const ss_insolation_band_io *io;
    float albedo;
    int n_steps;
    int *step_of;       /* daylight direction -> step */
    int step_base;      /* the current group's first daylight direction */
    int group, n_groups; /* groups of daylight steps, one banded horizon run each */
    unsigned char *day; /* per step: STEP_NIGHT, STEP_DAY or STEP_ELSEWHERE */
    FILE *svf;          /* the radiative SVF, whole rows */
    FILE *partial;      /* the first pass's sums: per band, N_SUMS planes of its rows */
    /* The band being walked. */
    int row0, ready;
    float *z;        /* its rows and one row either side (Horn's gradient) */
    float *sky_view; /* its rows */
    ss_cell_terms *terms;
    float *sums;   /* N_SUMS planes of its rows' cells each: beam, diffuse, reflected,
                      global, hours */
    float *loaded; /* the same, as the first pass left them */
    float *step_global;
} insolation_run;

double ss_insolation_band_cell_bytes(void)
{
    /* Heights (with a halo row), SVF 4, terms 20, sums and loaded sums 40,
     * one step's global 4; the horizon sweep's own band comes on top. */
    return 72.0;
}

static ss_status file_rows(insolation_run *r, FILE *f, int row0, int n_rows, size_t per_cell,
                           float *data, int write)
{
    size_t w = (size_t)r->io->width, n = (size_t)n_rows * w * per_cell;
    if (fseeko(f, (off_t)((size_t)row0 * w * per_cell * sizeof(float)), SEEK_SET) != 0)
        return ss_fail(r->ctx, SS_ERR_OUTPUT, "temporary file: cannot seek");
    size_t done = write ? fwrite(data, sizeof(float), n, f) : fread(data, sizeof(float), n, f);
    return done == n ? SS_OK
                     : ss_fail(r->ctx, SS_ERR_OUTPUT, "temporary file: %s failed%s",
                               write ? "write" : "read", write ? " (disk full?)" : "");
}

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    insolation_run *r = user;
    return r->io->read(r->io->user, row0, n_rows, z);
}

static ss_status svf_rows(void *user, int row0, int n_rows, const float *values)
{
    insolation_run *r = user;
    return file_rows(r, r->svf, row0, n_rows, 1, (float *)values, 1);
}

/* The band's heights (with a row either side), SVF and cell terms; its
 * sums start at 0. */
static ss_status prepare_band(insolation_run *r, int row0, int n_rows)
{
    const ss_insolation_band_io *io = r->io;
    int w = io->width;
    int lo = row0 > 0 ? row0 - 1 : 0;
    int hi = row0 + n_rows < io->height ? row0 + n_rows + 1 : io->height;
    ss_status st = io->read(io->user, lo, hi - lo, r->z);
    if (st == SS_OK)
        st = file_rows(r, r->svf, row0, n_rows, 1, r->sky_view, 0);
    if (st != SS_OK)
        return st;
    const float *z = r->z + (size_t)(row0 - lo) * w;
    float cx = (float)io->cell_x_m, cy = (float)io->cell_y_m;
    double origin = *io->z_origin_m;
#pragma omp parallel for schedule(static)
    for (int y = 0; y < n_rows; ++y)
        for (int c = 0; c < w; ++c) {
            size_t k = (size_t)y * w + c;
            if (!isfinite(z[k]))
                continue;
            float dz_de, dz_dn;
            /* The rows read form a grid whose first row is lo. */
            ss_gradient_horn(r->z, w, hi - lo, c, row0 - lo + y, cx, cy, &dz_de, &dz_dn);
            r->terms[k] = ss_cell_terms_of(dz_de, dz_dn, r->sky_view[k], z[k] + origin);
        }
    memset(r->sums, 0, sizeof(float) * N_SUMS * (size_t)n_rows * w);
    r->row0 = row0;
    r->ready = 1;
    return SS_OK;
}

/* The band's own heights (after the row above it, if read). */
static const float *band_z(const insolation_run *r)
{
    return r->z + (size_t)(r->row0 > 0 ? 1 : 0) * r->io->width;
}

/* One daylight step's shadows for the band's rows: the step's sums. */
static ss_status step_rows(void *user, int direction, int row0, int n_rows,
                           const float *horizon_deg, const float *dist_m,
                           const float *cast_height_m)
{
    (void)dist_m, (void)cast_height_m;
    insolation_run *r = user;
    ss_status st = SS_OK;
    if (!r->ready || r->row0 != row0)
        st = prepare_band(r, row0, n_rows);
    int k = r->step_of[r->step_base + direction];
    ss_sun_step sun;
    if (st == SS_OK)
        st = r->io->sun_rows(r->ctx, k, row0, n_rows, &sun, r->io->user);
    if (st == SS_OK && sun.real_sky)
        st = ss_fail(r->ctx, SS_ERR_ARGUMENT,
                     "weather records are evaluated on a DEM held whole, not in bands");
    if (st != SS_OK)
        return st;
    const float rad = (float)(M_PI / 180.0);
    float g0 = (float)sun.extraterrestrial_w_m2, linke = (float)sun.linke;
    float dt = (float)sun.duration_h;
    const float *z = band_z(r);
    size_t n = (size_t)n_rows * r->io->width;
    float *beam = r->sums, *diffuse = beam + n, *reflected = diffuse + n;
    float *global = reflected + n, *hours = global + n;
#pragma omp parallel for schedule(static)
    for (size_t c = 0; c < n; ++c) {
        r->step_global[c] = isfinite(z[c]) ? 0.0f : SS_NODATA;
        if (!isfinite(z[c]))
            continue;
        float az = (sun.grid_azimuth_per_cell ? sun.grid_azimuth_per_cell[c]
                                              : (float)sun.grid_azimuth_deg) *
                   rad;
        float h0 =
            (sun.elevation_per_cell ? sun.elevation_per_cell[c] : (float)sun.elevation_deg) * rad;
        float app =
            sun.apparent_per_cell ? sun.apparent_per_cell[c] : (float)sun.apparent_elevation_deg;
        if (h0 <= 0.0f)
            continue;
        ss_cell_step add =
            ss_cell_step_of(&r->terms[c], az, h0, app, horizon_deg[c], g0, linke, r->albedo, dt);
        beam[c] += add.beam;
        diffuse[c] += add.diffuse;
        reflected[c] += add.reflected;
        global[c] += add.global;
        hours[c] += add.sun_hours;
        r->step_global[c] = add.global;
    }
    return r->io->write_step ? r->io->write_step(r->io->user, k, row0, n_rows, r->step_global)
                             : SS_OK;
}

/* A band's rows have seen every direction of a pass: its sums are added to
 * what earlier passes (and groups of steps) left in the file, and wait
 * there; after the last, they are finished and written, with the night
 * steps' rows of the step file. */
static ss_status band_done(void *user, int pass, int row0, int n_rows)
{
    insolation_run *r = user;
    ss_status st = SS_OK;
    if (!r->ready || r->row0 != row0)
        st = prepare_band(r, row0, n_rows);
    r->ready = 0;
    size_t n = (size_t)n_rows * r->io->width;
    int first = r->group == 0 && pass == 0, last = r->group == r->n_groups - 1 && pass == 1;
    if (st == SS_OK && !first)
        st = file_rows(r, r->partial, row0, n_rows, N_SUMS, r->loaded, 0);
    const float *z = band_z(r);
    for (int k = 0; k < N_SUMS && st == SS_OK && !first; ++k) {
        float *sum = r->sums + (size_t)k * n;
        const float *before = r->loaded + (size_t)k * n;
        for (size_t c = 0; c < n; ++c)
            sum[c] = before[c] + sum[c];
    }
    if (st != SS_OK || !last)
        return st == SS_OK ? file_rows(r, r->partial, row0, n_rows, N_SUMS, r->sums, 1) : st;
    for (int k = 0; k < N_SUMS; ++k)
        for (size_t c = 0; c < n; ++c)
            r->sums[(size_t)k * n + c] = isfinite(z[c]) ? r->sums[(size_t)k * n + c] : SS_NODATA;
    ss_insolation_out rows = {.global = r->sums + 3 * n,
                              .beam = r->sums,
                              .diffuse = r->sums + n,
                              .reflected = r->sums + 2 * n,
                              .sun_hours = r->sums + 4 * n};
    if (st == SS_OK)
        st = r->io->write(r->io->user, row0, n_rows, &rows);
    for (size_t c = 0; c < n; ++c)
        r->step_global[c] = isfinite(z[c]) ? 0.0f : SS_NODATA;
    for (int k = 0; k < r->n_steps && st == SS_OK && r->io->write_step; ++k)
        if (r->day[k] == STEP_NIGHT)
            st = r->io->write_step(r->io->user, k, row0, n_rows, r->step_global);
    return st;
}

/* No daylight step: every band's two passes, with no direction walked, in
 * the order ss_horizon_banded visits them (down, then up), so that every
 * process writes, and adds, its bands in the same order. */
static ss_status run_nights(insolation_run *r, int band_rows)
{
    ss_status st = SS_OK;
    int bands = (r->io->height + band_rows - 1) / band_rows;
    for (int pass = 0; pass < 2; ++pass)
        for (int k = 0; k < bands && st == SS_OK; ++k) {
            int row0 = (pass == 0 ? k : bands - 1 - k) * band_rows;
            int rows = row0 + band_rows < r->io->height ? band_rows : r->io->height - row0;
            st = band_done(r, pass, row0, rows);
        }
    return st;
}

static ss_status check_io(ss_ctx *ctx, const ss_insolation_band_io *io,
                          const ss_insolation_options *options, int n_steps)
{
    if (!io || !io->read || !io->write || !io->sun_rows || !io->z_origin_m || io->width < 2 ||
        io->height < 2 || io->band_rows < 1 || !(io->cell_x_m > 0) || !(io->cell_y_m > 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "banded insolation needs a grid of at least 2 x 2 cells with positive "
                       "cell sizes, a reader, a writer, the sun and at least one row per band");
    ss_status st = ss_insolation_check(ctx, options, n_steps);
    if (st != SS_OK)
        return st;
    if (options->surface.kind != SS_SURFACE_CELL)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a DEM swept in bands takes each cell's own surface only (--surface cell)");
    if (options->shadow_mode != SS_SHADOW_EXACT)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a DEM swept in bands takes exact shadows only: interpolated shadows "
                       "store every direction's horizons for the whole grid");
    return SS_OK;
}

/* The daylight steps, and their suns' azimuths for the shadow sweep. */
static ss_status classify_steps(insolation_run *r, const ss_insolation_options *options,
                                double **azimuths, int *n_day)
{
    *n_day = 0;
    *azimuths = ss_malloc(sizeof(double) * (size_t)r->n_steps);
    if (!*azimuths)
        return ss_fail(r->ctx, SS_ERR_MEMORY, "out of memory for %d steps", r->n_steps);
    for (int k = 0; k < r->n_steps; ++k) {
        if (!ss_insolation_step_is_mine(options, k)) {
            r->day[k] = STEP_ELSEWHERE;
            continue;
        }
        ss_sun_step sun;
        ss_status st = r->io->sun_rows(r->ctx, k, 0, 0, &sun, r->io->user);
        if (st != SS_OK)
            return st;
        /* As on the whole grid: night where no cell's sun is up. */
        r->day[k] = sun.elevation_deg + sun.spread_deg > 0.0 ? STEP_DAY : STEP_NIGHT;
        if (r->day[k] == STEP_NIGHT) {
            r->ctx->counters.night_steps_skipped++;
            continue;
        }
        r->ctx->counters.time_steps++;
        r->step_of[*n_day] = k;
        (*azimuths)[(*n_day)++] = sun.azimuth_deg;
    }
    return SS_OK;
}

ss_status ss_insolation_banded(ss_ctx *ctx, const ss_insolation_band_io *io,
                               const ss_sweep_options *opt, const ss_insolation_options *options,
                               int n_steps)
{
    ss_status st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK)
        st = check_io(ctx, io, options, n_steps);
    if (st != SS_OK)
        return st;
    insolation_run r = {0};
    r.ctx = ctx;
    r.io = io;
    r.albedo = (float)options->albedo;
    r.n_steps = n_steps;
    int band_rows = io->band_rows < io->height ? io->band_rows : io->height;
    size_t cells = (size_t)band_rows * io->width;
    r.step_of = ss_malloc(sizeof(int) * (size_t)n_steps);
    r.day = ss_calloc((size_t)n_steps, 1);
    if (!r.step_of || !r.day)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for %d steps", n_steps);
    if (st == SS_OK && (!(r.svf = tmpfile()) || !(r.partial = tmpfile())))
        st = ss_fail(ctx, SS_ERR_OUTPUT, "cannot create a temporary file for the banded sweep");
    double *azimuths = NULL;
    int n_day = 0;
    if (st == SS_OK)
        st = classify_steps(&r, options, &azimuths, &n_day);
    /* The radiative SVF of every cell, for the diffuse and reflected terms. */
    ss_band_io svf_io = {
        io->width, io->height, io->cell_x_m, io->cell_y_m, band_rows, read_rows, svf_rows, &r, 0,
        1,         0,          NULL};
    if (st == SS_OK)
        st = ss_sky_banded(ctx, &svf_io, opt, SS_SKY_SVF_TILTED);
    /* The bands' own buffers, once the SVF's are free. */
    if (st == SS_OK) {
        r.z = ss_malloc(sizeof(float) * (cells + 2 * (size_t)io->width));
        r.sky_view = ss_malloc(sizeof(float) * cells);
        r.terms = ss_malloc(sizeof(ss_cell_terms) * cells);
        r.sums = ss_malloc(sizeof(float) * N_SUMS * cells);
        r.loaded = ss_malloc(sizeof(float) * N_SUMS * cells);
        r.step_global = ss_malloc(sizeof(float) * cells);
        if (!r.z || !r.sky_view || !r.terms || !r.sums || !r.loaded || !r.step_global)
            st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of %d rows", band_rows);
    }
    /* Then the shadows of the daylight steps, summed band by band. A run
     * holds every line's hull for each of its directions, so the steps go
     * in groups of SS_INSOLATION_STEPS_PER_RUN, each a banded horizon run. */
    r.n_groups = n_day > 0 ? (n_day + SS_INSOLATION_STEPS_PER_RUN - 1) /
                                 SS_INSOLATION_STEPS_PER_RUN
                           : 1;
    ss_band_stats total = {0, 0, 0};
    for (r.group = 0; st == SS_OK && r.group < r.n_groups; ++r.group) {
        r.step_base = r.group * SS_INSOLATION_STEPS_PER_RUN;
        int in_group = n_day - r.step_base < SS_INSOLATION_STEPS_PER_RUN
                           ? n_day - r.step_base
                           : SS_INSOLATION_STEPS_PER_RUN;
        ss_band_stats stats = {0, 0, 0};
        ss_horizon_band_io shadow_io = {io->width,  io->height, io->cell_x_m,
                                        io->cell_y_m, band_rows, read_rows,
                                        step_rows,  &r,         in_group,
                                        azimuths + r.step_base, 0.0f, &stats,
                                        band_done};
        st = n_day > 0 ? ss_horizon_banded(ctx, &shadow_io, opt, 0) : run_nights(&r, band_rows);
        total.handoffs += stats.handoffs;
        total.hull_points_handed_on += stats.hull_points_handed_on;
        if (stats.max_hull_points > total.max_hull_points)
            total.max_hull_points = stats.max_hull_points;
    }
    if (io->stats)
        *io->stats = total;
    free(azimuths);
    if (r.svf)
        fclose(r.svf);
    if (r.partial)
        fclose(r.partial);
    free(r.step_of);
    free(r.day);
    free(r.z);
    free(r.sky_view);
    free(r.terms);
    free(r.sums);
    free(r.loaded);
    free(r.step_global);
    return st;
}
