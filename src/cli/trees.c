/* Trees on the command line (trees.h, doc/vegetation.md). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grid_warp.h"
#include "trees.h"

#define SET(field) offsetof(tree_settings, field)
static const opt_spec tree_table[] = {
    {"canopy", OPT_INPUT, SET(canopy), "FILE", NULL, 0, 0, NULL,
     "trees (doc/vegetation.md): crown tops on the DSM's grid (warped onto it otherwise), 0 "
     "where no tree; adds "},
    {"canopy-heights", OPT_CHOICE, SET(canopy_heights), NULL, "above-ground", 0, 0,
     "above-ground|absolute",
     "--canopy's heights: above the ground (UMEP's), or above the datum (the DSM is "
     "subtracted where they are above 0)"},
    {"trunk", OPT_INPUT, SET(trunk), "FILE", NULL, 0, 0, NULL,
     "crown bottoms above the ground (a raster like --canopy), instead of --trunk-ratio"},
    {"trunk-ratio", OPT_DOUBLE, SET(trunk_ratio), "R", "0.25", 0, 1, NULL,
     "crown bottoms at R x the canopy height"},
    {"transmissivity", OPT_DOUBLE, SET(transmissivity), "T", "0.03", 0, 1, NULL,
     "fraction of the light that crosses a crown (leaf on)"},
    {"trunk-gaps", OPT_CHOICE, SET(trunk_gaps), NULL, "open", 0, 0, "ignore|open",
     "the sky under crowns: open sees it between the ground and the trunk height; ignore takes "
     "each crown down to the ground, about half the crowns' time (its error: "
     "doc/vegetation.md)"},
    OPT_END};
#undef SET

const opt_spec *tree_options(size_t base, int sky, const char *bands,
                             opt_spec out[TREE_OPTIONS_MAX])
{
    /* One help per distinct `bands`: --help-json builds every command's
     * options in one process. */
    static char canopy_help[8][400];
    static const char *help_bands[8];
    size_t slot = 0;
    while (slot < 7 && help_bands[slot] && strcmp(help_bands[slot], bands) != 0)
        ++slot;
    help_bands[slot] = bands;
    int n = 0;
    for (const opt_spec *o = tree_table; o->name; ++o) {
        if (!sky && strcmp(o->name, "trunk-gaps") == 0)
            continue;
        out[n] = *o;
        out[n].offset += base;
        ++n;
    }
    snprintf(canopy_help[slot], sizeof canopy_help[0], "%s%s", tree_table[0].help, bands);
    out[0].help = canopy_help[slot];
    out[n] = (opt_spec)OPT_END;
    return out;
}

int trees_options_alone(const char *command, const opt_spec *const *tables, const void *settings,
                        const tree_settings *set)
{
    static const char *const needs[] = {"canopy-heights", "trunk", "trunk-ratio", "transmissivity",
                                        "trunk-gaps"};
    for (size_t i = 0; !set->canopy && i < sizeof needs / sizeof *needs; ++i) {
        const opt_spec *o = opt_find(tables, needs[i]);
        if (o && !opt_at_default(o, settings)) {
            char why[80];
            snprintf(why, sizeof why, "--%s needs --canopy", needs[i]);
            return run_usage_error(command, why);
        }
    }
    if (set->trunk && !opt_at_default(opt_find(tables, "trunk-ratio"), settings))
        return run_usage_error(command, "--trunk and --trunk-ratio are alternatives: give one");
    return -1;
}

void trees_free(trees *t)
{
    free(t->height);
    free(t->trunk);
    if (t->z_owned)
        free(t->z);
}

ss_grid trees_ground(const sweep_job *job, const trees *t)
{
    ss_grid ground = job->dem.grid;
    ground.z = t->z;
    return ground;
}

/* Nodata in a tree raster is no tree (0); absolute tops become heights
 * above the DSM, those below it no tree. */
static void trees_heights(const ss_dem *dem, const tree_settings *set, trees *t, size_t n)
{
    for (size_t i = 0; i < n; ++i) {
        float *h = &t->height[i];
        if (*h == SS_NODATA || isnan(*h))
            *h = 0.0f;
        if (set->canopy_heights == 1 && *h > 0.0f) {
            double above = isfinite(t->z[i]) ? *h - (t->z[i] + dem->grid.z_origin_m) : 0.0;
            t->below_ground += above < 0.0;
            *h = above > 0.0 ? (float)above : 0.0f;
        }
        if (t->trunk && (t->trunk[i] == SS_NODATA || isnan(t->trunk[i])))
            t->trunk[i] = 0.0f;
    }
}

/* Neither file can be the output: both are declared inputs, refused as
 * outputs when the options are parsed. */
ss_status trees_open(sweep_job *job, const tree_settings *set, trees *t)
{
    const ss_grid *g = &job->dem.grid;
    size_t n = (size_t)g->width * (size_t)g->height;
    t->z = g->z;
    if (!t->z) {
        t->z = malloc(n * sizeof(float));
        t->z_owned = 1;
        if (!t->z)
            return ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
        ss_status st = job_read_rows(job, 0, g->height, t->z);
        if (st != SS_OK)
            return st;
    }
    return trees_read(job->run.ctx, &job->dem, t->z, set, t);
}

ss_status trees_read(ss_ctx *ctx, const ss_dem *dem, float *z, const tree_settings *set,
                     trees *t)
{
    const ss_grid *g = &dem->grid;
    size_t n = (size_t)g->width * (size_t)g->height;
    t->z = z;
    t->height = malloc(n * sizeof(float));
    t->trunk = set->trunk ? malloc(n * sizeof(float)) : NULL;
    if (!t->height || (set->trunk && !t->trunk))
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for the trees");
    int warped = 0;
    ss_status st = ss_raster_onto_dem(ctx, set->canopy, "canopy", dem, t->height, &t->warped);
    if (st == SS_OK && set->trunk)
        st = ss_raster_onto_dem(ctx, set->trunk, "trunk raster", dem, t->trunk, &warped);
    if (st != SS_OK)
        return st;
    t->warped |= warped;
    trees_heights(dem, set, t, n);
    t->canopy = (ss_canopy){t->height, t->trunk, set->trunk_ratio, set->transmissivity};
    ss_grid ground = *g;
    ground.z = t->z;
    return ss_canopy_check(ctx, &ground, &t->canopy);
}

void trees_metadata(ss_raster_writer *w, const tree_settings *set, const trees *t)
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
}

const char *trees_crown_lines(const ss_sweep_options *opt, int digital)
{
    if (digital || opt->lines != SS_LINES_BOX)
        return "digital";
    return opt->box_shadows == SS_BOX_SHADOWS_MARCH ? "box, each cell's own ray" : "box lines";
}

void trees_describe(const tree_settings *set, const trees *t, char *buf, size_t size)
{
    snprintf(buf, size, "%s (heights %s%s), transmissivity %.4g", set->canopy,
             set->canopy_heights ? "absolute" : "above ground",
             t->warped ? ", warped onto the DEM's grid" : "", set->transmissivity);
}
