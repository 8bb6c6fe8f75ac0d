/* skysweep canopy: from a first-return DSM (ground, buildings and trees as
 * one surface), a bare-earth DTM and building footprints, the two rasters
 * the tree options take (doc/vegetation.md, "skysweep canopy"): a DSM of
 * buildings and ground, and a CDSM of the trees' heights above the ground
 * (UMEP's convention, 0 where there is none). The usual national-lidar
 * recipe: inside the footprints (grown by a buffer) the DSM is kept;
 * elsewhere the surface is the DTM, and what stands at least
 * --min-tree-height above it is vegetation, unless it is an isolated cell. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "footprint_mask.h"
#include "grid_warp.h"
#include "roofs_io.h"
#include "run.h"

/* A DTM above the DSM by more than this (m) is more than lidar noise ... */
#define DTM_ABOVE_TOLERANCE_M 0.5
/* ... and over more than this share of the cells, the two do not belong
 * together (another datum, unit or place): refused. */
#define DTM_ABOVE_MAX_SHARE 0.10

typedef struct {
    const char *buildings, *dtm, *cdsm;
    double min_tree_height_m, building_buffer_m;
    int min_tree_neighbours;
    int quiet;
} canopy_settings;

#define SET(field) offsetof(canopy_settings, field)
static const opt_spec canopy_options[] = {
    {"buildings", OPT_INPUT, SET(buildings), "FILE", NULL, 0, 0, NULL,
     "building footprints: any vector source OGR reads (Shapefile, GeoPackage, GeoJSON, ...), "
     "its first layer; reprojected to the DSM's CRS (required)"},
    {"dtm", OPT_INPUT, SET(dtm), "FILE", NULL, 0, 0, NULL,
     "bare-earth heights on the DSM's grid (warped onto it otherwise, the highest DTM cell over "
     "each DSM cell), in metres in the DSM's datum (required)"},
    {"cdsm", OPT_OUTPUT, SET(cdsm), "FILE", NULL, 0, 0, NULL,
     "the second output: the vegetation's height above the ground, 0 where there is none "
     "(UMEP's CDSM, for --canopy; required)"},
    {"min-tree-height", OPT_DOUBLE, SET(min_tree_height_m), "M", "2.5", 0.1, 100, NULL,
     "outside buildings, a cell this much or more above the DTM is vegetation; lower objects "
     "(cars, fences, hedges) become ground"},
    {"building-buffer", OPT_DOUBLE, SET(building_buffer_m), "M", "1", 0, 50, NULL,
     "footprints are grown by this much before their cells keep the DSM: eaves beyond the walls "
     "and footprints drawn a little off the lidar would otherwise become trees"},
    {"min-tree-neighbours", OPT_INT, SET(min_tree_neighbours), "N", "3", 0, 8, NULL,
     "a vegetation cell needs this many vegetation cells among its 8 neighbours, else it is "
     "ground: drops lamp posts, wires and slivers along walls (0: keep every cell)"},
    {"q", OPT_FLAG, SET(quiet), NULL, NULL, 0, 0, NULL, "quiet: no summary"},
    OPT_END};
#undef SET

/* What the recipe found, for the summary. */
typedef struct {
    size_t cells, nodata, building, trees, dropped, ground, dtm_holes, dtm_above, both_valid;
    double tallest_m;
} canopy_counts;

typedef struct {
    canopy_settings set;
    const char *dsm_path, *out_path;
    run_state run;
    ss_dem dem;
    ss_footprints fps;
    float *dtm; /* absolute heights, SS_NODATA at none */
    int dtm_warped;
    unsigned char *inside; /* 1: a building cell (buffered footprint) */
    float *out_dsm, *out_cdsm;
    canopy_counts counts;
} canopy_run;

static int has_value(float v)
{
    return isfinite(v) && v != SS_NODATA;
}

/* The DSM, the DTM on its grid, and the footprints' cells. */
static ss_status read_inputs(canopy_run *c)
{
    ss_ctx *ctx = c->run.ctx;
    ss_dem_read_options o = {0};
    ss_status st = ss_dem_read(ctx, &c->dsm_path, 1, &o, &c->dem);
    if (st != SS_OK)
        return st;
    size_t n = (size_t)c->dem.grid.width * (size_t)c->dem.grid.height;
    c->dtm = malloc(sizeof(float) * n);
    c->inside = malloc(n);
    c->out_dsm = malloc(sizeof(float) * n);
    c->out_cdsm = malloc(sizeof(float) * n);
    if (!c->dtm || !c->inside || !c->out_dsm || !c->out_cdsm)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for %zu cells", n);
    st = ss_raster_onto_dem(ctx, c->set.dtm, "DTM", &c->dem, c->dtm, &c->dtm_warped);
    if (st == SS_OK)
        st = ss_footprints_read(ctx, c->set.buildings, NULL, NULL, &c->dem, &c->fps);
    /* Footprints, none of them on the DSM, are a mistake (another place, an
     * undeclared CRS) that would make every building a tree; a layer of
     * none says that the DSM has no buildings. */
    if (st == SS_OK && c->fps.read > 0 && c->fps.n == 0)
        st = ss_ctx_error(ctx, SS_ERR_INPUT,
                          "no footprint of '%s' covers a cell of the DSM (%zu read: %zu outside "
                          "it, %zu empty, %zu invalid, %zu covering no cell centre): are they of "
                          "the DSM's place, and is their CRS declared? (For a DSM without "
                          "buildings, give a layer without features.)",
                          c->set.buildings, c->fps.read, c->fps.outside, c->fps.empty,
                          c->fps.invalid, c->fps.no_cell);
    if (st == SS_OK)
        st = ss_footprints_mask(ctx, &c->dem, &c->fps, c->set.building_buffer_m, c->inside);
    return st;
}

/* Vegetation cells among the 8 neighbours of (col, row) in cdsm (> 0). */
static int vegetated_neighbours(const float *cdsm, int width, int height, int col, int row)
{
    int n = 0;
    for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) {
            int cc = col + dc, rr = row + dr;
            if ((dc || dr) && cc >= 0 && rr >= 0 && cc < width && rr < height)
                n += cdsm[(size_t)rr * width + cc] > 0.0f;
        }
    return n;
}

/* One cell by the recipe: its output heights, counted. */
static void classify_cell(canopy_run *c, size_t i)
{
    canopy_counts *k = &c->counts;
    float z = c->dem.grid.z[i], ground = c->dtm[i];
    if (!isfinite(z)) { /* no DSM: nothing is known there */
        c->out_dsm[i] = c->out_cdsm[i] = SS_NODATA;
        k->nodata++;
        return;
    }
    double surface = (double)z + c->dem.grid.z_origin_m;
    if (has_value(ground)) {
        k->both_valid++;
        k->dtm_above += ground - surface > DTM_ABOVE_TOLERANCE_M;
    }
    if (c->inside[i]) {
        c->out_dsm[i] = (float)surface;
        c->out_cdsm[i] = 0.0f;
        k->building++;
    } else if (!has_value(ground)) { /* no ground to stand trees on */
        c->out_dsm[i] = c->out_cdsm[i] = SS_NODATA;
        k->dtm_holes++;
    } else {
        double above = surface - ground;
        c->out_dsm[i] = ground;
        c->out_cdsm[i] = above >= c->set.min_tree_height_m ? (float)above : 0.0f;
    }
}

/* Every cell classified, isolated vegetation cells (fewer vegetated
 * neighbours than --min-tree-neighbours, counted before any is dropped)
 * made ground. */
static ss_status apply_recipe(canopy_run *c)
{
    int w = c->dem.grid.width, h = c->dem.grid.height;
    size_t n = (size_t)w * (size_t)h;
    c->counts.cells = n;
    for (size_t i = 0; i < n; ++i)
        classify_cell(c, i);
    unsigned char *isolated = calloc(n, 1);
    if (!isolated)
        return ss_ctx_error(c->run.ctx, SS_ERR_MEMORY, "out of memory for %zu cells", n);
    for (int r = 0; r < h; ++r)
        for (int col = 0; col < w; ++col) {
            size_t i = (size_t)r * w + col;
            isolated[i] = c->out_cdsm[i] > 0.0f && vegetated_neighbours(c->out_cdsm, w, h, col, r) <
                                                       c->set.min_tree_neighbours;
        }
    canopy_counts *k = &c->counts;
    for (size_t i = 0; i < n; ++i) {
        if (isolated[i])
            c->out_cdsm[i] = 0.0f, k->dropped++;
        if (c->out_cdsm[i] > 0.0f)
            k->trees++, k->tallest_m = fmax(k->tallest_m, c->out_cdsm[i]);
    }
    free(isolated);
    k->ground = n - k->nodata - k->building - k->dtm_holes - k->trees;
    if (k->both_valid && (double)k->dtm_above > DTM_ABOVE_MAX_SHARE * (double)k->both_valid)
        return ss_ctx_error(c->run.ctx, SS_ERR_INPUT,
                            "the DTM '%s' lies more than %.1f m above the DSM '%s' on %.1f %% of "
                            "the cells (at most %.0f %% is lidar noise): are both in one datum and "
                            "unit, and of one place?",
                            c->set.dtm, DTM_ABOVE_TOLERANCE_M, c->dsm_path,
                            100.0 * (double)k->dtm_above / (double)k->both_valid,
                            100.0 * DTM_ABOVE_MAX_SHARE);
    return SS_OK;
}

/* The recipe and its thresholds, in both outputs' metadata. */
static void recipe_metadata(canopy_run *c, ss_raster_writer *w, const char *quantity)
{
    char buf[1200];
    const canopy_settings *s = &c->set;
    ss_writer_metadata(w, "SKYSWEEP_VERSION", ss_version());
    ss_writer_metadata(w, "SKYSWEEP_COMMAND", "canopy");
    ss_writer_metadata(w, "QUANTITY", quantity);
    snprintf(buf, sizeof buf,
             "footprints grown by %g m: the DSM kept, no vegetation; elsewhere the DTM, and "
             "vegetation where the DSM stands %g m or more above the DTM with at least %d "
             "vegetated neighbours of 8 (doc/vegetation.md, skysweep canopy)",
             s->building_buffer_m, s->min_tree_height_m, s->min_tree_neighbours);
    ss_writer_metadata(w, "RECIPE", buf);
    snprintf(buf, sizeof buf, "%.6g", s->min_tree_height_m);
    ss_writer_metadata(w, "MIN_TREE_HEIGHT_M", buf);
    snprintf(buf, sizeof buf, "%.6g", s->building_buffer_m);
    ss_writer_metadata(w, "BUILDING_BUFFER_M", buf);
    snprintf(buf, sizeof buf, "%d", s->min_tree_neighbours);
    ss_writer_metadata(w, "MIN_TREE_NEIGHBOURS", buf);
    ss_writer_metadata(w, "INPUT_DSM", c->dsm_path);
    snprintf(buf, sizeof buf, "%s%s", s->dtm,
             c->dtm_warped ? " (warped onto the DSM's grid, highest cell)" : "");
    ss_writer_metadata(w, "INPUT_DTM", buf);
    snprintf(buf, sizeof buf, "%s (%zu footprints on the DSM)", s->buildings, c->fps.n);
    ss_writer_metadata(w, "INPUT_BUILDINGS", buf);
}

/* Both outputs, each written to a temporary and renamed into place; the
 * second is not committed when the first fails, and neither is left
 * half-written. */
static ss_status write_outputs(canopy_run *c)
{
    ss_ctx *ctx = c->run.ctx;
    ss_raster_writer *w[2] = {NULL, NULL};
    const char *paths[2] = {c->out_path, c->set.cdsm};
    const float *data[2] = {c->out_dsm, c->out_cdsm};
    static const char *const quantity[2] = {
        "surface height of buildings and ground (the DTM outside buildings), metres in the "
        "inputs' vertical datum",
        "vegetation canopy height above the ground, metres (UMEP's CDSM: 0 where there is "
        "none)"};
    static const char *const band[2] = {"buildings and ground",
                                        "vegetation height above the ground"};
    ss_status st = SS_OK;
    for (int k = 0; k < 2 && st == SS_OK; ++k) {
        st = ss_writer_open(ctx, paths[k], &c->dem, 1, NULL, NULL, &w[k]);
        if (st == SS_OK) {
            recipe_metadata(c, w[k], quantity[k]);
            st = ss_writer_band(w[k], 1, data[k], band[k], "m");
        }
    }
    for (int k = 0; k < 2 && st == SS_OK; ++k) {
        st = run_commit(&c->run, w[k]);
        w[k] = NULL;
    }
    for (int k = 0; k < 2; ++k)
        ss_writer_abort(w[k]);
    return st;
}

static double share(size_t part, size_t whole)
{
    return whole ? 100.0 * (double)part / (double)whole : 0.0;
}

static void print_summary(const canopy_run *c)
{
    const canopy_counts *k = &c->counts;
    const canopy_settings *s = &c->set;
    const ss_footprints *f = &c->fps;
    printf("dsm       %s: %d x %d cells, %zu without a height\n", c->dsm_path, c->dem.grid.width,
           c->dem.grid.height, k->nodata);
    printf("dtm       %s%s: %zu cells without a height outside buildings (nodata in both "
           "outputs); above the DSM by more than %.1f m on %zu cells (%.2f %%)\n",
           s->dtm, c->dtm_warped ? " (warped onto the DSM's grid)" : "", k->dtm_holes,
           DTM_ABOVE_TOLERANCE_M, k->dtm_above, share(k->dtm_above, k->both_valid));
    printf("buildings %zu of %zu footprints read from '%s' on the DSM (%zu repaired, %zu "
           "skipped), grown by %g m: %zu cells (%.1f %%) keep the DSM\n",
           f->n, f->read, s->buildings, f->repaired, f->read - f->n, s->building_buffer_m,
           k->building, share(k->building, k->cells));
    printf("trees     %zu cells (%.1f %%) %g m or more above the DTM, up to %.2f m; %zu isolated "
           "cells (fewer than %d vegetated neighbours) made ground\n",
           k->trees, share(k->trees, k->cells), s->min_tree_height_m, k->tallest_m, k->dropped,
           s->min_tree_neighbours);
    printf("ground    %zu cells (%.1f %%) take the DTM\n", k->ground, share(k->ground, k->cells));
    printf("outputs   buildings and ground -> %s, vegetation heights (CDSM) -> %s\n", c->out_path,
           s->cdsm);
}

static void close_run(canopy_run *c)
{
    free(c->dtm);
    free(c->inside);
    free(c->out_dsm);
    free(c->out_cdsm);
    ss_footprints_free(&c->fps);
    ss_dem_free(&c->dem);
    run_end(&c->run);
}

int cmd_canopy(int argc, char **argv)
{
    canopy_run c;
    memset(&c, 0, sizeof c);
    const opt_spec *tables[] = {canopy_options, NULL};
    const char *pos[2];
    int n_pos = 0;
    int rc = run_parse(
        "canopy", tables, &c.set, argc, argv, pos, &n_pos, 2, 2,
        "skysweep canopy --buildings FOOTPRINTS --dtm DTM --cdsm OUT_CDSM.tif [options] DSM "
        "OUT_DSM.tif",
        "From a first-return DSM (ground, buildings and trees as one surface), a bare-earth DTM "
        "and\nbuilding footprints, the two rasters the tree options take: a DSM of buildings "
        "and ground\n(OUT_DSM), and the vegetation's height above the ground (--cdsm, UMEP's "
        "CDSM, for --canopy).\nInside the footprints the DSM is kept; elsewhere the surface is "
        "the DTM, and vegetation is\nwhat stands --min-tree-height or more above it "
        "(doc/vegetation.md).",
        NULL);
    if (rc >= 0)
        return rc;
    if (!c.set.buildings || !c.set.dtm || !c.set.cdsm)
        return run_usage_error("canopy", "--buildings FILE, --dtm FILE and --cdsm FILE are "
                                         "needed (the footprints, the ground, the CDSM "
                                         "written)");
    c.dsm_path = pos[0];
    c.out_path = pos[1];
    if ((rc = run_begin(&c.run, "canopy", NULL)))
        return rc;
    c.run.quiet = c.set.quiet;
    ss_status st = run_check_output(&c.run, c.out_path);
    if (st == SS_OK)
        st = run_check_output(&c.run, c.set.cdsm);
    if (st == SS_OK)
        st = read_inputs(&c);
    if (st == SS_OK)
        st = apply_recipe(&c);
    if (st == SS_OK)
        st = write_outputs(&c);
    rc = st == SS_OK ? 0 : run_fail(&c.run, st);
    if (st == SS_OK && !c.run.quiet)
        print_summary(&c);
    close_run(&c);
    return rc;
}
