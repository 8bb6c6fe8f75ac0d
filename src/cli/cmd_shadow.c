/* skysweep shadow: where the terrain casts shadows for one sun (an exact
 * sweep along the sun's azimuth), where cells face away from it, and the
 * shaded relief that combines both (the registry's run), on the DEM held whole
 * or read band by band; with --canopy, the trees' shadow besides
 * (doc/vegetation.md). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "crown_light.h"
#include "skysweep_sun.h"
#include "run.h"
#include "sun_field.h"
#include "trees.h"

typedef struct {
    common_settings common; /* first: common_options()' offsets are relative to it */
    tree_settings trees;
    crown_light_settings light;
} shadow_settings;

/* The sun of the run for the library: the centre's, and each cell's for
 * the rows asked for where the plan put a sun in every cell. */
typedef struct {
    sweep_job *job;
    ss_sun_field *field;
} shadow_sun;

static ss_status sun_rows(ss_ctx *ctx, int index, int row0, int n_rows, ss_sun_step *step,
                          void *user)
{
    (void)index;
    shadow_sun *s = user;
    ss_sun_field *f = s->field;
    memset(step, 0, sizeof *step);
    /* The sweep runs along the sun's azimuth at the DEM's centre. */
    step->azimuth_deg = f->centre_grid_azimuth_deg + s->job->opt.grid_north_deg;
    step->grid_azimuth_deg = f->centre_grid_azimuth_deg;
    step->elevation_deg = f->centre.elevation_deg;
    step->apparent_elevation_deg = f->centre.apparent_elevation_deg;
    step->spread_deg = f->spread_deg;
    if (n_rows == 0 || !ss_sun_field_per_cell(f))
        return SS_OK;
    size_t at = 0;
    if (s->job->source) {
        ss_status st = ss_sun_field_rows(ctx, f, row0, n_rows);
        if (st != SS_OK)
            return st;
    } else {
        at = (size_t)row0 * (size_t)s->job->dem.grid.width;
    }
    step->grid_azimuth_per_cell = f->grid_azimuth_deg + at;
    step->elevation_per_cell = f->elevation_deg + at;
    step->apparent_per_cell = f->apparent_elevation_deg + at;
    return SS_OK;
}

/* The output's three bands, and how many cells are sunlit; with trees,
 * the whole sunlit band kept for their classes. */
typedef struct {
    ss_raster_writer *w;
    int width;
    size_t lit, valid;
    float *sunlit;
} shadow_out;

/* The registry's one output, its bands SS_OUT_SUNLIT, _FACING, _LIGHT. */
static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)output;
    shadow_out *o = user;
    size_t n = (size_t)n_rows * (size_t)o->width;
    for (size_t c = 0; index == SS_OUT_SUNLIT && c < n; ++c) {
        o->lit += values[c] == 1.0f;
        o->valid += values[c] != SS_NODATA;
    }
    if (index == SS_OUT_SUNLIT && o->sunlit)
        memcpy(o->sunlit + (size_t)row0 * (size_t)o->width, values, n * sizeof(float));
    return ss_writer_rows(o->w, index + 1, row0, n_rows, values);
}

/* Beer-Lambert (--crown-light): each cell's path inside crowns toward
 * the sun into path_m, and the fraction that arrives in the cells of
 * vegetation shadow. */
static ss_status beer_lambert(sweep_job *job, const ss_grid *ground, const trees *t,
                              const crown_light_settings *light, const ss_sun_field *sun,
                              const float *klass, float *path_m, float *fraction)
{
    size_t n = (size_t)ground->width * (size_t)ground->height;
    float *attenuated = malloc(n * sizeof(float));
    ss_status st = attenuated ? ss_canopy_path(job->run.ctx, ground, &t->canopy,
                                               sun->centre_grid_azimuth_deg,
                                               sun->centre.apparent_elevation_deg, path_m)
                              : ss_ctx_error(job->run.ctx, SS_ERR_MEMORY,
                                             "out of memory for the trees");
    if (st == SS_OK)
        st = ss_canopy_path_fraction(job->run.ctx, light->extinction, light->leaf_area_density,
                                     n, path_m, attenuated);
    for (size_t i = 0; st == SS_OK && i < n; ++i)
        if (klass[i] == 2.0f)
            fraction[i] = attenuated[i];
    free(attenuated);
    return st;
}

/* Bands 4 and 5 (and 6, Beer-Lambert's paths): the crowns crossed on the
 * way to the sun (the centre's), over the solid verdict kept in
 * out->sunlit; *shaded counts the cells in vegetation shadow. */
static ss_status trees_write(sweep_job *job, trees *t, const crown_light_settings *light,
                             shadow_out *out, const ss_sun_field *sun, size_t *shaded)
{
    ss_grid ground = trees_ground(job, t);
    size_t n = (size_t)ground.width * (size_t)ground.height;
    unsigned char *crossed = malloc(n);
    float *klass = malloc(n * sizeof(float)), *fraction = malloc(n * sizeof(float));
    float *path_m = light->beer_lambert ? malloc(n * sizeof(float)) : NULL;
    /* Beer-Lambert's paths are found on digital lines: its classes too, so
     * that a path lies exactly where a crown is crossed. */
    ss_status st = crossed && klass && fraction && (path_m || !light->beer_lambert)
                       ? ss_canopy_crossed(job->run.ctx, &ground, &t->canopy,
                                           light->beer_lambert ? NULL : &job->opt,
                                           sun->centre_grid_azimuth_deg,
                                           sun->centre.apparent_elevation_deg, crossed)
                       : ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
    if (st == SS_OK) {
        ss_canopy_classes(&t->canopy, n, out->sunlit, crossed, klass, fraction);
        for (size_t i = 0; i < n; ++i)
            *shaded += klass[i] == 2.0f;
    }
    if (st == SS_OK && light->beer_lambert)
        st = beer_lambert(job, &ground, t, light, sun, klass, path_m, fraction);
    if (st == SS_OK)
        st = ss_writer_rows(out->w, 4, 0, ground.height, klass);
    if (st == SS_OK)
        st = ss_writer_rows(out->w, 5, 0, ground.height, fraction);
    if (st == SS_OK && path_m)
        st = ss_writer_rows(out->w, 6, 0, ground.height, path_m);
    free(crossed);
    free(klass);
    free(fraction);
    free(path_m);
    return st;
}

static void trees_bands(ss_raster_writer *w, int beer_lambert)
{
    ss_writer_describe(w, 4, "shadow class: 0 lit, 1 solid shadow, 2 vegetation shadow", "1");
    if (!beer_lambert) {
        ss_writer_describe(w, 5,
                           "fraction of the beam that arrives: 1 lit, 0 solid, T through crowns",
                           "1");
        return;
    }
    ss_writer_describe(w, 5,
                       "fraction of the beam that arrives: 1 lit, 0 solid, exp(-G LAD path) "
                       "through crowns",
                       "1");
    ss_writer_describe(w, 6, "path of the ray toward the sun inside crowns", "m");
}

int cmd_shadow(int argc, char **argv)
{
    shadow_settings set = {0};
    common_settings_init(&set.common);
    opt_spec tree_opts[TREE_OPTIONS_MAX];
    const opt_spec *tables[] = {
        tree_options(offsetof(shadow_settings, trees), 0,
                     "bands 4 (class) and 5 (fraction of the beam that arrives)", tree_opts),
        crown_light_options(offsetof(shadow_settings, light)), sun_options(), common_options(),
        NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("shadow", tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 2,
                       "skysweep shadow (--time ISO8601 | --sun-azimuth DEG --sun-elevation DEG) "
                       "[options] DEM... OUTPUT",
                       ss_product_named("shadow")->description,
                       &set.common.device);
    if (rc < 0)
        rc = trees_options_alone("shadow", tables, &set, &set.trees);
    if (rc < 0)
        rc = crown_light_alone("shadow", tables, &set, &set.light, set.trees.canopy != NULL);
    if (rc >= 0)
        return rc;
    /* One horizon, along the sun's azimuth, and the planes facing the sun
     * and illumination that ss_shadow_rows holds a band of. */
    band_cost cost = {.cell_bytes = ss_product_named("shadow")->cell_bytes(NULL, 0),
                      .column_bytes = ss_horizon_column_bytes(),
                      .directions = 1,
                      .grid_cell_bytes = (set.trees.canopy ? TREES_SHADOW_CELL_BYTES : 0.0) +
                                         (set.light.beer_lambert ? CROWN_LIGHT_CELL_BYTES : 0.0) +
                                         run_march_cell_bytes(&set.common)};
    sweep_job job;
    if ((rc = job_open_banded(&job, "shadow", &set.common, pos, n_pos, cost)))
        return rc;
    /* The sun's options are checked before the plan is made and shown; a
     * plan alone (--plan, skysweep plan) may leave the sun out. */
    const ss_sun_params *sun_given = &set.common.sun;
    int no_sun = !sun_given->time && !isfinite(sun_given->sun_azimuth_deg) &&
                 !isfinite(sun_given->sun_elevation_deg);
    double when = NAN;
    ss_status checked = no_sun && set.common.plan_only
                            ? SS_OK
                            : ss_sun_params_check(job.run.ctx, sun_given, &when);
    int timed = sun_given->time != NULL;
    if (checked != SS_OK)
        rc = job_finish(&job, checked);
    else
        rc = job_plan(&job, &set.common, ss_product_named("shadow"), NULL, timed,
                      timed ? &when : NULL);
    if (rc >= 0) {
        job_close(&job);
        return rc;
    }
    ss_sun_field sun = {0};
    ss_band_stats bands = {0};
    trees tr = {0};
    size_t shaded = 0;
    ss_status st = set.trees.canopy ? trees_open(&job, &set.trees, &tr) : SS_OK;
    if (st == SS_OK)
        st = job_sun(&job, &set.common, &sun);
    int have_sun = st == SS_OK;
    size_t cells = (size_t)job.dem.grid.width * (size_t)job.dem.grid.height;
    shadow_out out = {NULL, job.dem.grid.width, 0, 0, NULL};
    if (st == SS_OK && set.trees.canopy && !(out.sunlit = malloc(cells * sizeof(float))))
        st = ss_ctx_error(job.run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
    if (st == SS_OK)
        st = ss_writer_open(job.run.ctx, job.output, &job.dem,
                            set.trees.canopy ? 5 + set.light.beer_lambert : 3,
                            set.common.format, set.common.creation_options.items, &out.w);
    ss_raster_writer *w = out.w;
    double sun_az_true = sun.centre_grid_azimuth_deg + job.opt.grid_north_deg;
    shadow_sun ss = {&job, &sun};
    ss_product_sun one_sun = {.n_steps = 1, .sun_rows = sun_rows, .sun_user = &ss};
    ss_source src = job_source(&job, &bands);
    if (st == SS_OK)
        st = ss_product_named("shadow")->run(job.run.ctx, &src, &job.opt, NULL, &one_sun, 0, NULL,
                                             write_rows, &out);
    double trees_s = run_now();
    if (st == SS_OK && set.trees.canopy)
        st = trees_write(&job, &tr, &set.light, &out, &sun, &shaded);
    trees_s = run_now() - trees_s;
    size_t lit = out.lit, valid = out.valid;
    if (st == SS_OK) {
        char buf[200];
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        snprintf(buf, sizeof buf, "azimuth %.6f deg (true), apparent elevation %.6f deg, %s",
                 sun_az_true, sun.centre.apparent_elevation_deg,
                 ss_sun_field_per_cell(&sun) ? "per cell" : "one sun for the DEM");
        ss_writer_metadata(w, "SUN", buf);
        if (set.common.sun.time)
            ss_writer_metadata(w, "TIME", set.common.sun.time);
        ss_writer_describe(w, 1, "sunlit (1) or in a cast shadow (0)", "1");
        ss_writer_describe(w, 2, "facing the sun (1) or away from it (0)", "1");
        ss_writer_describe(w, 3, "illumination cos(incidence), 0 in shadow", "1");
        if (set.trees.canopy) {
            trees_metadata(w, &set.trees, &tr);
            crown_light_describe(&set.light, set.trees.transmissivity, buf, sizeof buf);
            crown_light_metadata(w, &set.light, buf);
            trees_bands(w, set.light.beer_lambert);
        }
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
        command_print_box_march(&job.run, "shadow ");
        char described[400];
        trees_describe(&set.trees, &tr, described, sizeof described);
        if (set.trees.canopy)
            printf("trees   %s: %.1f %% of cells in "
                   "vegetation shadow (crowns met on the host: %s, %.3f s)\n",
                   described, valid ? 100.0 * shaded / valid : 0.0,
                   trees_crown_lines(&job.opt, set.light.beer_lambert), trees_s);
        if (set.trees.canopy && set.light.beer_lambert) {
            crown_light_describe(&set.light, set.trees.transmissivity, described,
                                 sizeof described);
            printf("trees   light through crowns: %s\n", described);
        }
        if (set.trees.canopy && tr.below_ground)
            printf("trees   %zu absolute crown tops below the DSM taken as no tree\n",
                   tr.below_ground);
    }
    if (have_sun)
        ss_sun_field_free(&sun);
    free(out.sunlit);
    trees_free(&tr);
    job_close(&job);
    return rc;
}
