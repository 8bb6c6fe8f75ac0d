/* skysweep shadow: where the terrain casts shadows for one sun (an exact
 * sweep along the sun's azimuth), where cells face away from it, and the
 * shaded relief that combines both (ss_shadow_rows), on the DEM held whole
 * or read band by band; with --canopy, the trees' shadow besides
 * (doc/vegetation.md). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "skysweep_sun.h"
#include "grid_warp.h"
#include "run.h"
#include "sun_field.h"

typedef struct {
    common_settings common; /* first: common_options()' offsets are relative to it */
    const char *canopy, *trunk;
    double trunk_ratio, transmissivity;
    int canopy_heights; /* index into "above-ground|absolute" */
} shadow_settings;

#define SET(field) offsetof(shadow_settings, field)
static const opt_spec tree_options[] = {
    {"canopy", OPT_INPUT, SET(canopy), "FILE", NULL, 0, 0, NULL,
     "trees (doc/vegetation.md): crown tops on the DSM's grid (warped onto it otherwise), 0 "
     "where no tree; adds bands 4 (class) and 5 (fraction of the beam that arrives)"},
    {"canopy-heights", OPT_CHOICE, SET(canopy_heights), NULL, "above-ground", 0, 0,
     "above-ground|absolute",
     "--canopy's heights: above the ground (UMEP's), or above the datum (the DSM is "
     "subtracted where they are above 0)"},
    {"trunk", OPT_INPUT, SET(trunk), "FILE", NULL, 0, 0, NULL,
     "crown bottoms above the ground (a raster like --canopy), instead of --trunk-ratio"},
    {"trunk-ratio", OPT_DOUBLE, SET(trunk_ratio), "R", "0.25", 0, 1, NULL,
     "crown bottoms at R x the canopy height"},
    {"transmissivity", OPT_DOUBLE, SET(transmissivity), "T", "0.03", 0, 1, NULL,
     "fraction of the beam that crosses a crown (leaf on)"},
    OPT_END};
#undef SET

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

static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)index;
    shadow_out *o = user;
    size_t n = (size_t)n_rows * (size_t)o->width;
    for (size_t c = 0; output == SS_OUT_SUNLIT && c < n; ++c) {
        o->lit += values[c] == 1.0f;
        o->valid += values[c] != SS_NODATA;
    }
    if (output == SS_OUT_SUNLIT && o->sunlit)
        memcpy(o->sunlit + (size_t)row0 * (size_t)o->width, values, n * sizeof(float));
    return ss_writer_rows(o->w, output + 1, row0, n_rows, values);
}

/* The trees of a run (--canopy), on the DEM's grid and held whole, with
 * the DSM's heights they stand on. */
typedef struct {
    ss_canopy canopy;
    float *height, *trunk, *z;
    int z_owned; /* z read here: the DEM is swept in bands */
    int warped;  /* the canopy or the trunks were warped onto the DEM's grid */
    size_t below_ground; /* absolute tops below the DSM, taken as no tree */
    size_t shaded;       /* cells in vegetation shadow */
} trees;

static void trees_free(trees *t)
{
    free(t->height);
    free(t->trunk);
    if (t->z_owned)
        free(t->z);
}

/* Nodata in a tree raster is no tree (0); absolute tops become heights
 * above the DSM, those below it no tree. */
static void trees_heights(sweep_job *job, const shadow_settings *set, trees *t, size_t n)
{
    for (size_t i = 0; i < n; ++i) {
        float *h = &t->height[i];
        if (*h == SS_NODATA || isnan(*h))
            *h = 0.0f;
        if (set->canopy_heights == 1 && *h > 0.0f) {
            double above = isfinite(t->z[i]) ? *h - (t->z[i] + job->dem.grid.z_origin_m) : 0.0;
            t->below_ground += above < 0.0;
            *h = above > 0.0 ? (float)above : 0.0f;
        }
        if (t->trunk && (t->trunk[i] == SS_NODATA || isnan(t->trunk[i])))
            t->trunk[i] = 0.0f;
    }
}

/* Reads --canopy and --trunk onto the DEM's grid and checks them (neither
 * can be the output: both are declared inputs, refused as outputs when the
 * options are parsed). */
static ss_status trees_open(sweep_job *job, const shadow_settings *set, trees *t)
{
    ss_status st = SS_OK;
    const ss_grid *g = &job->dem.grid;
    size_t n = (size_t)g->width * (size_t)g->height;
    t->height = malloc(n * sizeof(float));
    t->trunk = set->trunk ? malloc(n * sizeof(float)) : NULL;
    t->z = g->z;
    if (!t->z) {
        t->z = malloc(n * sizeof(float));
        t->z_owned = 1;
    }
    if (!t->height || !t->z || (set->trunk && !t->trunk))
        return ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
    if (t->z_owned)
        st = job_read_rows(job, 0, g->height, t->z);
    int warped = 0;
    if (st == SS_OK)
        st = ss_raster_onto_dem(job->run.ctx, set->canopy, "canopy", &job->dem, t->height,
                                &t->warped);
    if (st == SS_OK && set->trunk)
        st = ss_raster_onto_dem(job->run.ctx, set->trunk, "trunk raster", &job->dem, t->trunk,
                                &warped);
    if (st != SS_OK)
        return st;
    t->warped |= warped;
    trees_heights(job, set, t, n);
    t->canopy = (ss_canopy){t->height, t->trunk, set->trunk_ratio, set->transmissivity};
    ss_grid ground = *g;
    ground.z = t->z;
    return ss_canopy_check(job->run.ctx, &ground, &t->canopy);
}

/* Bands 4 and 5: the crowns crossed on the way to the sun (the centre's),
 * over the solid verdict kept in out->sunlit. */
static ss_status trees_write(sweep_job *job, trees *t, shadow_out *out, const ss_sun_field *sun)
{
    ss_grid ground = job->dem.grid;
    ground.z = t->z;
    size_t n = (size_t)ground.width * (size_t)ground.height;
    unsigned char *crossed = malloc(n);
    float *klass = malloc(n * sizeof(float)), *fraction = malloc(n * sizeof(float));
    ss_status st = crossed && klass && fraction
                       ? ss_canopy_crossed(job->run.ctx, &ground, &t->canopy, &job->opt,
                                           sun->centre_grid_azimuth_deg,
                                           sun->centre.apparent_elevation_deg, crossed)
                       : ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
    if (st == SS_OK) {
        ss_canopy_classes(&t->canopy, n, out->sunlit, crossed, klass, fraction);
        for (size_t i = 0; i < n; ++i)
            t->shaded += klass[i] == 2.0f;
        st = ss_writer_rows(out->w, 4, 0, ground.height, klass);
    }
    if (st == SS_OK)
        st = ss_writer_rows(out->w, 5, 0, ground.height, fraction);
    free(crossed);
    free(klass);
    free(fraction);
    return st;
}

static void trees_metadata(ss_raster_writer *w, const shadow_settings *set, const trees *t)
{
    char buf[600];
    snprintf(buf, sizeof buf, "%s (heights %s%s)", set->canopy,
             set->canopy_heights ? "absolute, the DSM subtracted" : "above the ground",
             t->warped ? "; warped onto the DEM's grid, highest cell" : "");
    ss_writer_metadata(w, "CANOPY", buf);
    if (set->trunk)
        snprintf(buf, sizeof buf, "crown bottoms from %s (above the ground)", set->trunk);
    else
        snprintf(buf, sizeof buf, "crown bottoms at %.6g x the canopy height", set->trunk_ratio);
    ss_writer_metadata(w, "TRUNK", buf);
    snprintf(buf, sizeof buf, "%.6g", set->transmissivity);
    ss_writer_metadata(w, "TRANSMISSIVITY", buf);
    ss_writer_describe(w, 4, "shadow class: 0 lit, 1 solid shadow, 2 vegetation shadow", "1");
    ss_writer_describe(w, 5, "fraction of the beam that arrives: 1 lit, 0 solid, T through crowns",
                       "1");
}

/* Tree options without --canopy, and --trunk-ratio beside --trunk, are
 * refused rather than ignored. */
static int trees_options_alone(const opt_spec *const *tables, const shadow_settings *set)
{
    static const char *const needs[] = {"canopy-heights", "trunk", "trunk-ratio",
                                        "transmissivity"};
    for (size_t i = 0; !set->canopy && i < sizeof needs / sizeof *needs; ++i)
        if (!opt_at_default(opt_find(tables, needs[i]), set)) {
            char why[80];
            snprintf(why, sizeof why, "--%s needs --canopy", needs[i]);
            return run_usage_error("shadow", why);
        }
    if (set->trunk && !opt_at_default(opt_find(tables, "trunk-ratio"), set))
        return run_usage_error("shadow", "--trunk and --trunk-ratio are alternatives: give one");
    return -1;
}

int cmd_shadow(int argc, char **argv)
{
    shadow_settings set = {0};
    common_settings_init(&set.common);
    const opt_spec *tables[] = {tree_options, sun_options(), common_options(), NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("shadow", tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 2,
                       "skysweep shadow (--time ISO8601 | --sun-azimuth DEG --sun-elevation DEG) "
                       "[options] DEM... OUTPUT",
                       ss_product_named("shadow")->description,
                       &set.common.device);
    if (rc < 0)
        rc = trees_options_alone(tables, &set);
    if (rc >= 0)
        return rc;
    /* One horizon, along the sun's azimuth, and the planes facing the sun
     * and illumination that ss_shadow_rows holds a band of. */
    band_cost cost = {.cell_bytes = ss_horizon_band_cell_bytes(0) + 2.0 * sizeof(float),
                      .column_bytes = ss_horizon_column_bytes(),
                      .directions = 1};
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
        rc = job_plan(&job, &set.common, SS_PLAN_SHADOW, timed, timed ? &when : NULL,
                      SS_SHADOW_EXACT);
    if (rc >= 0) {
        job_close(&job);
        return rc;
    }
    ss_sun_field sun = {0};
    ss_band_stats bands = {0};
    trees tr = {0};
    ss_status st = set.canopy ? trees_open(&job, &set, &tr) : SS_OK;
    if (st == SS_OK)
        st = job_sun(&job, &set.common, &sun);
    int have_sun = st == SS_OK;
    size_t cells = (size_t)job.dem.grid.width * (size_t)job.dem.grid.height;
    shadow_out out = {NULL, job.dem.grid.width, 0, 0, NULL};
    if (st == SS_OK && set.canopy && !(out.sunlit = malloc(cells * sizeof(float))))
        st = ss_ctx_error(job.run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
    if (st == SS_OK)
        st = ss_writer_open(job.run.ctx, job.output, &job.dem, set.canopy ? 5 : 3,
                            set.common.format,
                            set.common.creation_options.items, &out.w);
    ss_raster_writer *w = out.w;
    double sun_az_true = sun.centre_grid_azimuth_deg + job.opt.grid_north_deg;
    shadow_sun ss = {&job, &sun};
    ss_source src = job_source(&job, &bands);
    if (st == SS_OK)
        st = ss_shadow_rows(job.run.ctx, &src, &job.opt, sun_rows, &ss, write_rows, &out);
    double trees_s = run_now();
    if (st == SS_OK && set.canopy)
        st = trees_write(&job, &tr, &out, &sun);
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
        if (set.canopy)
            trees_metadata(w, &set, &tr);
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
        if (set.canopy)
            printf("trees   %s (heights %s%s), transmissivity %.4g: %.1f %% of cells in "
                   "vegetation shadow (crowns swept on the host on %s lines, %.3f s)\n",
                   set.canopy, set.canopy_heights ? "absolute" : "above ground",
                   tr.warped ? ", warped onto the DEM's grid" : "", set.transmissivity,
                   valid ? 100.0 * tr.shaded / valid : 0.0,
                   job.opt.lines == SS_LINES_BOX ? "box" : "digital", trees_s);
        if (set.canopy && tr.below_ground)
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
