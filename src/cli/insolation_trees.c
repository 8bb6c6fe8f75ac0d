/* Trees in `skysweep insolation` (insolation_trees.h). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include "insolation_trees.h"

#define SET(field) offsetof(insolation_tree_settings, field)
static const opt_spec season_table[] = {
    {"transmissivity-leaf-off", OPT_DOUBLE, SET(transmissivity_leaf_off), "T", "0.5", 0, 1,
     NULL, "fraction of the light that crosses a crown with the leaves off (UMEP's 0.5)"},
    {"leaf-on", OPT_STRING, SET(leaf_on), "DAY", NULL, 0, 0, NULL,
     "the day the leaves come out, a day of the year (1-366) or MM-DD: UMEP's day 98 (leaves on "
     "after its firstdayleaf 97), half a year later where the DSM's centre lies south of the "
     "equator"},
    {"leaf-off", OPT_STRING, SET(leaf_off), "DAY", NULL, 0, 0, NULL,
     "the day the leaves fall, likewise: UMEP's lastdayleaf 300, half a year later in the south"},
    {"crown-lines", OPT_CHOICE, SET(crown_lines), NULL, "auto", 0, 0, "auto|digital",
     "how each step's crowns are met: auto, on the solid sweep's line model (on city DSMs "
     "box lines, by each cell's own ray under --box-shadows march); digital, on digital "
     "lines whatever the solid's (its beam classes' error in doc/vegetation.md)"},
    OPT_END};
#undef SET

void insolation_tree_options(size_t base, opt_spec trees_out[TREE_OPTIONS_MAX],
                             opt_spec seasons_out[INSOLATION_TREE_OPTIONS_MAX])
{
    tree_options(base + offsetof(insolation_tree_settings, trees), 1,
                 "tree shade to every band: the beam and circumsolar light through crowns keep "
                 "the transmissivity of the step's leaf season",
                 trees_out);
    int n = 0;
    for (const opt_spec *o = season_table; o->name; ++o, ++n) {
        seasons_out[n] = *o;
        seasons_out[n].offset += base;
    }
    seasons_out[n] = (opt_spec)OPT_END;
}

int insolation_trees_usage(const opt_spec *const *tables, const void *settings,
                           const insolation_tree_settings *set)
{
    int rc = trees_options_alone("insolation", tables, settings, &set->trees);
    static const char *const needs[] = {"transmissivity-leaf-off", "leaf-on", "leaf-off",
                                        "crown-lines"};
    for (size_t i = 0; rc < 0 && !set->trees.canopy && i < sizeof needs / sizeof *needs; ++i) {
        const opt_spec *o = opt_find(tables, needs[i]);
        if (o && !opt_at_default(o, settings)) {
            char why[80];
            snprintf(why, sizeof why, "--%s needs --canopy", needs[i]);
            rc = run_usage_error("insolation", why);
        }
    }
    const char *dates[2] = {set->leaf_on, set->leaf_off}, *names[2] = {"leaf-on", "leaf-off"};
    for (int i = 0; rc < 0 && i < 2; ++i) {
        if (dates[i] && !ss_leaf_date_valid(dates[i])) {
            char why[200];
            snprintf(why, sizeof why,
                     "--%s '%.60s' is neither a day of the year (1-366) nor a date MM-DD",
                     names[i], dates[i]);
            rc = run_usage_error("insolation", why);
        }
    }
    return rc;
}

/* Each step's season by its local date at the DEM's centre. */
static void seasons_of_steps(const sweep_job *job, const insolation_tree_settings *set,
                             const double *mid_s, int n, insolation_trees *it)
{
    ss_leaf_season season;
    ss_leaf_seasons(set->leaf_on, set->leaf_off, job->frame.centre_lat_deg,
                    job->frame.centre_lon_deg, mid_s, n, it->leaf_off, &season);
    it->south = season.south;
    it->on_day = season.on_day;
    it->off_day = season.off_day;
    it->leaf_off_steps = season.leaf_off_steps;
}

ss_status insolation_trees_open(sweep_job *job, const insolation_tree_settings *set,
                                const double *mid_s, int n, insolation_trees *it)
{
    ss_status st = trees_open(job, &set->trees, &it->t);
    size_t cells = (size_t)job->dem.grid.width * (size_t)job->dem.grid.height;
    if (st == SS_OK) {
        it->sky_hidden = malloc(cells * sizeof(float));
        it->leaf_off = malloc(n > 0 ? (size_t)n : 1);
        if (!it->sky_hidden || !it->leaf_off)
            st = ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
    }
    if (st != SS_OK)
        return st;
    it->ground = trees_ground(job, &it->t);
    /* The sky a horizontal surface sees through the crowns, cosine-weighted
     * as its diffuse light (SOLWEIG's svf - svfbuveg = this x (1 - T)). */
    double t0 = run_now();
    st = ss_canopy_sky(job->run.ctx, &it->ground, &it->t.canopy, &job->opt,
                       SS_SVF_DEF_HORIZONTAL, (ss_trunk_gaps)set->trees.trunk_gaps, NULL,
                       it->sky_hidden);
    it->sky_seconds = run_now() - t0;
    seasons_of_steps(job, set, mid_s, n, it);
    it->lib = (ss_insolation_trees){&it->ground,
                                    &it->t.canopy,
                                    it->sky_hidden,
                                    set->transmissivity_leaf_off,
                                    it->leaf_off,
                                    set->crown_lines == 1,
                                    (ss_trunk_gaps)set->trees.trunk_gaps,
                                    set->light.beer_lambert ? set->light.leaf_area_density : 0.0,
                                    set->light.extinction};
    return st;
}

void insolation_trees_free(insolation_trees *it)
{
    trees_free(&it->t);
    free(it->sky_hidden);
    free(it->leaf_off);
}

/* "leaves on from day 98 to day 299 (UMEP's), ..." */
static void describe_season(const insolation_tree_settings *set, const insolation_trees *it,
                            char *buf, size_t size)
{
    char on[40], off[40];
    if (set->leaf_on)
        snprintf(on, sizeof on, "%s (given)", set->leaf_on);
    else
        snprintf(on, sizeof on, "day %d", it->on_day);
    if (set->leaf_off)
        snprintf(off, sizeof off, "%s (given)", set->leaf_off);
    else
        snprintf(off, sizeof off, "day %d", it->off_day);
    char leaf_on[60];
    if (set->light.beer_lambert)
        snprintf(leaf_on, sizeof leaf_on, "Beer-Lambert (CROWN_LIGHT)");
    else
        snprintf(leaf_on, sizeof leaf_on, "%.4g", set->trees.transmissivity);
    snprintf(buf, size,
             "leaves on from %s until %s (off from that day), by each step's local date (mean "
             "solar time at the DEM's centre); defaults UMEP's firstdayleaf 97, lastdayleaf "
             "300%s; transmissivity %s leaf on, %.4g leaf off",
             on, off,
             it->south ? ", shifted by 183 days: the DEM's centre lies south of the equator" : "",
             leaf_on, set->transmissivity_leaf_off);
}

/* The light through crowns: constant, or Beer-Lambert in leaf-on steps. */
static void describe_light(const insolation_tree_settings *set, char *buf, size_t size)
{
    char light[300];
    crown_light_describe(&set->light, set->trees.transmissivity, light, sizeof light);
    if (set->light.beer_lambert)
        snprintf(buf, size,
                 "%s, for the beam, circumsolar light and hours of sun of leaf-on steps, and "
                 "their sky through crowns by its mean over the directions the crowns hide; "
                 "leaf-off steps the constant %.6g",
                 light, set->transmissivity_leaf_off);
    else
        snprintf(buf, size, "%s leaf on, %.6g leaf off", light, set->transmissivity_leaf_off);
}

/* The lines each step's crowns are swept on. */
static const char *crown_lines_of(const insolation_tree_settings *set,
                                  const ss_sweep_options *opt)
{
    return trees_crown_lines(opt, set->crown_lines || set->light.beer_lambert);
}

void insolation_trees_metadata(ss_raster_writer *w, const insolation_tree_settings *set,
                               const insolation_trees *it, const ss_sweep_options *opt)
{
    trees_metadata(w, &set->trees, &it->t);
    char buf[600];
    snprintf(buf, sizeof buf, "%.6g", set->transmissivity_leaf_off);
    ss_writer_metadata(w, "TRANSMISSIVITY_LEAF_OFF", buf);
    describe_season(set, it, buf, sizeof buf);
    ss_writer_metadata(w, "SEASON", buf);
    ss_writer_metadata(w, "TRUNK_GAPS", set->trees.trunk_gaps ? "open" : "ignore");
    ss_writer_metadata(w, "CROWN_LINES", crown_lines_of(set, opt));
    describe_light(set, buf, sizeof buf);
    crown_light_metadata(w, &set->light, buf);
}

void insolation_trees_print(const insolation_tree_settings *set, const insolation_trees *it,
                            const ss_sweep_options *opt, int n_steps, int shadows_forced,
                            int cumulative)
{
    char described[400], season[600];
    trees_describe(&set->trees, &it->t, described, sizeof described);
    describe_season(set, it, season, sizeof season);
    printf("trees   %s (leaf off %.4g); crowns met on the host: their sky %.3f s, %s: %s\n",
           described, set->transmissivity_leaf_off, it->sky_seconds,
           cumulative ? "each sun bin's direction and elevation at its mean sun"
                      : "each step's sun after its solid shadow",
           crown_lines_of(set, opt));
    printf("season  %s; %d of %d steps leaf off\n", season, it->leaf_off_steps, n_steps);
    if (set->light.beer_lambert) {
        describe_light(set, season, sizeof season);
        printf("trees   light through crowns: %s\n", season);
    }
    if (shadows_forced)
        printf("trees   shadows exact: with --canopy the planner does not choose interpolated or "
               "cumulative shadows\n");
    if (it->t.below_ground)
        printf("trees   %zu absolute crown tops below the DSM taken as no tree\n",
               it->t.below_ground);
}
