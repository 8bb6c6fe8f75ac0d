/* skysweep shadow: where the terrain casts shadows for one sun (an exact
 * sweep along the sun's azimuth), where cells face away from it, and the
 * shaded relief that combines both; on the whole grid, or band by band for
 * a DEM whose sweep does not fit in --memory. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include "commands.h"
#include "iso_time.h"
#include "run.h"
#include "sun_field.h"

typedef struct {
    common_settings common;
} shadow_settings;

/* The three bands of the output for some rows. */
typedef struct {
    float *sunlit, *facing, *light;
    size_t lit, valid;
} shadow_rows;

/* From sunlit (SS_NODATA at nodata) and light holding cos(incidence):
 * facing, and light zeroed in shadows and on cells facing away. */
static void finish_rows(shadow_rows *out, size_t n)
{
    for (size_t c = 0; c < n; ++c) {
        if (out->sunlit[c] == SS_NODATA) {
            out->facing[c] = SS_NODATA;
            out->light[c] = SS_NODATA;
            continue;
        }
        out->facing[c] = out->light[c] > 0.0f ? 1.0f : 0.0f;
        out->light[c] = out->light[c] > 0.0f ? out->light[c] * out->sunlit[c] : 0.0f;
        out->lit += out->sunlit[c] > 0.0f;
        out->valid++;
    }
}

static ss_status write_rows(ss_raster_writer *w, int row0, int n_rows, const shadow_rows *out)
{
    ss_status st = ss_writer_rows(w, 1, row0, n_rows, out->sunlit);
    if (st == SS_OK)
        st = ss_writer_rows(w, 2, row0, n_rows, out->facing);
    if (st == SS_OK)
        st = ss_writer_rows(w, 3, row0, n_rows, out->light);
    return st;
}

static int alloc_rows(shadow_rows *out, size_t n)
{
    out->sunlit = malloc(n * sizeof(float));
    out->facing = malloc(n * sizeof(float));
    out->light = malloc(n * sizeof(float));
    return out->sunlit && out->facing && out->light;
}

static void free_rows(shadow_rows *out)
{
    free(out->sunlit);
    free(out->facing);
    free(out->light);
}

/* The whole grid in memory: one exact sweep along the sun's azimuth. */
static ss_status shade_whole(sweep_job *job, ss_sun_field *sun, double sun_az_true,
                             ss_raster_writer *w, shadow_rows *out)
{
    const ss_grid *g = &job->dem.grid;
    size_t n = (size_t)g->width * (size_t)g->height;
    if (!alloc_rows(out, n))
        return command_out_of_memory(&job->run);
    ss_status st = ss_cast_shadow(job->run.ctx, g, &job->opt, sun_az_true,
                                  sun->centre.apparent_elevation_deg,
                                  sun->apparent_elevation_deg, out->sunlit, NULL);
    if (st == SS_OK)
        st = ss_sun_incidence(job->run.ctx, g, sun->centre_grid_azimuth_deg,
                              sun->centre.apparent_elevation_deg, sun->grid_azimuth_deg,
                              sun->apparent_elevation_deg, out->light);
    if (st == SS_OK) {
        finish_rows(out, n);
        st = write_rows(w, 0, g->height, out);
    }
    return st;
}

/* A DEM swept in bands: the horizon along the sun's azimuth arrives band by
 * band (ss_horizon_banded, the horizontal where nothing lies ahead, as
 * ss_cast_shadow takes it); each band's rows are read again with one row
 * either side for the slopes, given their suns, and written. */
typedef struct {
    sweep_job *job;
    ss_sun_field *sun;
    ss_raster_writer *w;
    float *z;        /* the band's rows and one row either side */
    shadow_rows out; /* the band's rows */
} band_shade;

static ss_status read_band_rows(void *user, int row0, int n_rows, float *z)
{
    band_shade *b = user;
    return job_read_rows(b->job, row0, n_rows, z);
}

static ss_status shade_band(void *user, int direction, int row0, int n_rows,
                            const float *horizon_deg, const float *dist_m,
                            const float *cast_height_m)
{
    (void)direction, (void)dist_m, (void)cast_height_m;
    band_shade *b = user;
    ss_ctx *ctx = b->job->run.ctx;
    const ss_grid *g = &b->job->dem.grid;
    int lo = row0 > 0 ? row0 - 1 : 0;
    int hi = row0 + n_rows < g->height ? row0 + n_rows + 1 : g->height;
    ss_status st = job_read_rows(b->job, lo, hi - lo, b->z);
    if (st == SS_OK)
        st = ss_sun_field_rows(ctx, b->sun, lo, hi - lo);
    /* The rows read as a grid of their own: inside it Horn's slopes are
     * the whole grid's, and its first and last rows are either the grid's
     * or only there for the slopes. */
    ss_grid rows = {g->width, hi - lo, g->cell_x_m, g->cell_y_m, g->z_origin_m, b->z};
    float *cos_i = b->out.light;
    size_t read = (size_t)(hi - lo) * g->width;
    if (st == SS_OK && !run_any_height(b->z, read))
        for (size_t c = 0; c < read; ++c) /* all nodata: no slopes */
            cos_i[c] = SS_NODATA;
    else if (st == SS_OK)
        st = ss_sun_incidence(ctx, &rows, b->sun->centre_grid_azimuth_deg,
                              b->sun->centre.apparent_elevation_deg, b->sun->grid_azimuth_deg,
                              b->sun->apparent_elevation_deg, cos_i);
    if (st != SS_OK)
        return st;
    size_t skip = (size_t)(row0 - lo) * (size_t)g->width, n = (size_t)n_rows * g->width;
    const float *cell_sun = b->sun->apparent_elevation_deg;
    for (size_t c = 0; c < n; ++c) {
        double sun = cell_sun ? cell_sun[skip + c] : b->sun->centre.apparent_elevation_deg;
        b->out.sunlit[c] = horizon_deg[c] == SS_NODATA ? SS_NODATA
                           : sun > horizon_deg[c]      ? 1.0f
                                                       : 0.0f;
        cos_i[c] = cos_i[skip + c];
    }
    finish_rows(&b->out, n);
    return write_rows(b->w, row0, n_rows, &b->out);
}

static ss_status shade_banded(sweep_job *job, ss_sun_field *sun, double sun_az_true,
                              ss_raster_writer *w, shadow_rows *out, ss_band_stats *bands)
{
    const ss_grid *g = &job->dem.grid;
    band_shade b = {job, sun, w, NULL, {NULL, NULL, NULL, 0, 0}};
    /* The light band holds cos(i) of the rows read, two more than the band. */
    size_t n = (size_t)(job->band_rows + 2) * (size_t)g->width;
    ss_status st = SS_OK;
    if (!(b.z = malloc(n * sizeof(float))) || !alloc_rows(&b.out, n))
        st = command_out_of_memory(&job->run);
    ss_horizon_band_io io = {g->width, g->height, g->cell_x_m, g->cell_y_m, job->band_rows,
                             read_band_rows, shade_band, &b, 1, &sun_az_true, 0.0f, bands, NULL};
    if (st == SS_OK)
        st = ss_horizon_banded(job->run.ctx, &io, &job->opt, 0);
    out->lit = b.out.lit;
    out->valid = b.out.valid;
    free(b.z);
    free_rows(&b.out);
    return st;
}

int cmd_shadow(int argc, char **argv)
{
    shadow_settings set = {0};
    common_settings_init(&set.common);
    const opt_spec *tables[] = {sun_options, common_options, NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("shadow", tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 2,
                       "skysweep shadow (--time ISO8601 | --sun-azimuth DEG --sun-elevation DEG) "
                       "[options] DEM... OUTPUT",
                       "Cast shadows for one sun, by an exact sweep along its azimuth. Bands: 1 "
                       "sunlit (1) or in a cast\nshadow (0); 2 facing the sun (1) or away "
                       "(self-shadow, 0); 3 illumination cos(i) on sunlit cells facing\nthe "
                       "sun, else 0 (shaded relief with cast shadows).",
                       &set.common.device);
    if (rc >= 0)
        return rc;
    /* One horizon, along the sun's azimuth. */
    band_cost cost = {ss_horizon_band_cell_bytes(0), ss_horizon_column_bytes(), 1};
    sweep_job job;
    if ((rc = job_open_banded(&job, "shadow", &set.common, pos, n_pos, cost)))
        return rc;
    double when;
    int timed = set.common.time && ss_parse_instant(job.run.ctx, set.common.time, &when) == SS_OK;
    if ((rc = job_plan(&job, &set.common, SS_PRODUCT_SHADOW, timed, timed ? &when : NULL,
                       SS_SHADOW_EXACT)) >= 0) {
        job_close(&job);
        return rc;
    }
    ss_sun_field sun = {0};
    shadow_rows out = {NULL, NULL, NULL, 0, 0};
    ss_band_stats bands = {0};
    ss_raster_writer *w = NULL;
    ss_status st = job_sun(&job, &set.common, &sun);
    int have_sun = st == SS_OK;
    if (st == SS_OK)
        st = ss_writer_open(job.run.ctx, job.output, &job.dem, 3, set.common.format,
                            set.common.creation_options.items, &w);
    /* The sweep runs along the sun's azimuth at the DEM's centre. */
    double sun_az_true = sun.centre_grid_azimuth_deg + job.opt.grid_north_deg;
    if (st == SS_OK)
        st = job.source ? shade_banded(&job, &sun, sun_az_true, w, &out, &bands)
                        : shade_whole(&job, &sun, sun_az_true, w, &out);
    size_t lit = out.lit, valid = out.valid;
    if (st == SS_OK) {
        char buf[200];
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        snprintf(buf, sizeof buf, "azimuth %.6f deg (true), apparent elevation %.6f deg, %s",
                 sun_az_true, sun.centre.apparent_elevation_deg,
                 ss_sun_field_per_cell(&sun) ? "per cell" : "one sun for the DEM");
        ss_writer_metadata(w, "SUN", buf);
        if (set.common.time)
            ss_writer_metadata(w, "TIME", set.common.time);
        ss_writer_describe(w, 1, "sunlit (1) or in a cast shadow (0)", "1");
        ss_writer_describe(w, 2, "facing the sun (1) or away from it (0)", "1");
        ss_writer_describe(w, 3, "illumination cos(incidence), 0 in shadow", "1");
    }
    if (st == SS_OK)
        st = run_commit(&job.run, w);
    else
        ss_writer_abort(w);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        command_print_job_sweep(&job, &bands);
        printf("sun     azimuth %.4f, apparent elevation %.4f deg (%s, spread %.4f deg)\n",
               sun_az_true, sun.centre.apparent_elevation_deg,
               ss_sun_field_per_cell(&sun) ? "per cell" : "one sun", sun.spread_deg);
        printf("shadow  %.1f %% of cells sunlit -> %s\n", valid ? 100.0 * lit / valid : 0.0,
               job.output);
    }
    if (have_sun)
        ss_sun_field_free(&sun);
    free_rows(&out);
    job_close(&job);
    return rc;
}
