/* skysweep svf and skysweep openness: a sky product of the registry
 * (skysweep_products.h) into one band, from the DEM held whole or read in
 * bands (job_open_banded), alone or shared between MPI processes
 * (mpi_share.h). Each is one entry of the registry; this file reads it.
 * svf takes trees (--canopy, doc/vegetation.md): two bands more. */
#include "config.h"

#include <ctype.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "mpi_share.h"
#include "run.h"
#include "trees.h"

/* Both sky tables ("svf", "openness") hold the choice of term, then the
 * radius: one layout serves both. */
typedef struct {
    int term;        /* "definition" or "kind" */
    double radius_m; /* 0: unlimited */
} sky_params;
_Static_assert(offsetof(ss_svf_params, radius_m) == offsetof(sky_params, radius_m) &&
                   offsetof(ss_openness_params, radius_m) == offsetof(sky_params, radius_m) &&
                   sizeof(ss_svf_params) == sizeof(sky_params) &&
                   sizeof(ss_openness_params) == sizeof(sky_params),
               "the sky products' parameter structs share one layout");

typedef struct {
    common_settings common; /* first: common_options()' offsets are relative to it */
    sky_params sky;         /* the product's own table */
    tree_settings trees;    /* svf's */
} sky_settings;

typedef struct {
    ss_raster_writer *w; /* rank 0's */
    int width;
    run_tally tally; /* of the finished rows */
    float *kept;     /* with trees, the whole band kept for them; else NULL */
} sky_rows;

static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)output, (void)index;
    sky_rows *k = user;
    if (!k->w) /* another process's rows: rank 0 writes */
        return SS_OK;
    size_t n = (size_t)n_rows * (size_t)k->width;
    run_tally_add(&k->tally, values, n);
    if (k->kept)
        memcpy(k->kept + (size_t)row0 * (size_t)k->width, values, n * sizeof(float));
    return ss_writer_rows(k->w, 1, row0, n_rows, values);
}

/* The product into band 1 of w (rank 0's writer; NULL on other MPI ranks);
 * stats gets the hulls handed on between bands, min, mean and max the
 * product's (rank 0). */
static ss_status sky_product(sweep_job *job, const ss_product_info *product,
                             const sky_params *params, ss_raster_writer *w, float *kept,
                             ss_band_stats *stats, double *min, double *mean, double *max)
{
    sky_rows k = {w, job->dem.grid.width, {0, 0, 0, 0}, kept};
    ss_source src = job_source(job, stats);
    share_reducer reducer;
    ss_share share = share_of(&reducer, &job->run, job_bands(job));
    ss_status st =
        product->run(job->run.ctx, &src, &job->opt, params, NULL, 0, &share, write_rows, &k);
    st = share_end(&reducer, st);
    run_tally_result(&k.tally, NAN, min, mean, max);
    return st;
}

/* "SVF_DEFINITION": the product's name and a parameter's, upper case, '-' as '_'. */
static void metadata_key(char *buf, size_t size, const char *product, const char *param)
{
    snprintf(buf, size, "%s_%s", product, param);
    for (char *c = buf; *c; ++c)
        *c = *c == '-' ? '_' : (char)toupper((unsigned char)*c);
}

/* The metadata of the run: the term chosen and the radius. */
static void sky_metadata(ss_raster_writer *w, const ss_product_info *product,
                         const sky_params *params, const char *term)
{
    const ss_param *term_param = ss_param_table_named(product->own_table)->params;
    char key[64], radius[32];
    metadata_key(key, sizeof key, product->name, term_param->name);
    ss_writer_metadata(w, key, term);
    metadata_key(key, sizeof key, product->name, "radius-m");
    snprintf(radius, sizeof radius, "%g", params->radius_m);
    ss_writer_metadata(w, key, params->radius_m > 0 ? radius : "unlimited");
    /* The band's name: "KIND" stands for the term chosen. */
    const ss_product_output *out = &product->outputs[0];
    const char *kind = strstr(out->band_names, "KIND");
    char band[96];
    if (kind)
        snprintf(band, sizeof band, "%.*s%s%s", (int)(kind - out->band_names), out->band_names,
                 term, kind + 4);
    else
        snprintf(band, sizeof band, "%s", out->band_names);
    ss_writer_describe(w, 1, band, out->unit);
}

/* The trees of an svf run (rank 0's): bands 2 and 3 from band 1 kept
 * whole (doc/vegetation.md, "svf"). */
typedef struct {
    trees t;
    float *svf;                  /* band 1 */
    double veg_mean, total_mean; /* bands 2 and 3's */
    double seconds;              /* the crowns' sweep and bands */
} sky_trees;

/* Band 2, svfveg: 1 less the share of the sky that crowns hide above the
 * solid horizon; band 3, svfbuveg: SOLWEIG's svf - (1 - svfveg)(1 - T). */
static ss_status sky_trees_write(sweep_job *job, const tree_settings *set,
                                 ss_svf_definition definition, sky_trees *s, ss_raster_writer *w)
{
    double started = run_now();
    ss_grid ground = trees_ground(job, &s->t);
    size_t n = (size_t)ground.width * (size_t)ground.height;
    float *veg = malloc(n * sizeof(float)), *total = malloc(n * sizeof(float));
    ss_status st = veg && total
                       ? ss_canopy_sky(job->run.ctx, &ground, &s->t.canopy, &job->opt, definition,
                                       (ss_trunk_gaps)set->trunk_gaps, NULL, veg)
                       : ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
    if (st == SS_OK)
        ss_canopy_svf_bands(n, s->svf, veg, set->transmissivity, veg, total);
    run_tally tv = {0}, tt = {0};
    double lo, hi;
    if (st == SS_OK) {
        run_tally_add(&tv, veg, n);
        run_tally_add(&tt, total, n);
        run_tally_result(&tv, NAN, &lo, &s->veg_mean, &hi);
        run_tally_result(&tt, NAN, &lo, &s->total_mean, &hi);
        st = ss_writer_rows(w, 2, 0, ground.height, veg);
    }
    if (st == SS_OK)
        st = ss_writer_rows(w, 3, 0, ground.height, total);
    free(veg);
    free(total);
    s->seconds = run_now() - started;
    return st;
}

static void sky_trees_metadata(ss_raster_writer *w, const tree_settings *set, const sky_trees *s)
{
    trees_metadata(w, set, &s->t);
    ss_writer_metadata(w, "TRUNK_GAPS",
                       set->trunk_gaps == SS_TRUNK_GAPS_OPEN
                           ? "open: the sky seen under the crowns"
                           : "ignore: each crown taken down to the ground");
    ss_writer_describe(w, 2, "svfveg: 1 - the share of the sky crowns hide above the solid horizon",
                       "1");
    ss_writer_describe(w, 3, "svfbuveg: svf - (1 - svfveg) x (1 - transmissivity)", "1");
}

/* svf --canopy: refused with the radiative definition and with a radius,
 * which the crowns' sweep does not take. */
static int sky_trees_refused(const sky_settings *set, const ss_plan_request *req)
{
    if (!set->trees.canopy)
        return -1;
    if (req->svf_definition == SS_SVF_DEF_RADIATIVE)
        return run_usage_error("svf", "--canopy takes --definition geometric or horizontal, not "
                                      "radiative");
    if (req->radius_m > 0)
        return run_usage_error("svf", "--canopy takes no --radius");
    return -1;
}

int cmd_sky(int argc, char **argv)
{
    const ss_product_info *product = ss_product_named(argv[0]);
    sky_settings set = {0};
    opt_spec own_options[8], tree_opts[TREE_OPTIONS_MAX];
    opt_from_params(product->own_table, offsetof(sky_settings, sky), own_options, 8);
    int takes_trees = strcmp(product->name, "svf") == 0;
    const opt_spec *tables[] = {own_options, common_options(), NULL, NULL};
    if (takes_trees) { /* after the product's own options, before the common ones */
        tables[2] = tables[1];
        tables[1] = tree_options(offsetof(sky_settings, trees), 1,
                                 "bands 2 (svfveg) and 3 (svfbuveg)", tree_opts);
    }
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    char usage[96];
    snprintf(usage, sizeof usage, "skysweep %s [options] DEM... OUTPUT", product->name);
    int rc = run_parse(product->name, tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1,
                       2, usage, product->description, &set.common.device);
    ss_plan_request req = {0};
    product->request(&set.sky, NAN, &req);
    if (rc < 0 && takes_trees)
        rc = trees_options_alone(product->name, tables, &set, &set.trees);
    if (rc < 0)
        rc = sky_trees_refused(&set, &req);
    if (rc >= 0)
        return rc;
    sweep_job job;
    int radius_free = !(product->halo_m(&set.sky, NAN) > 0.0);
    band_cost cost = {.cell_bytes = product->cell_bytes(&set.sky, 0),
                      .halo_m = product->halo_m(&set.sky, NAN),
                      .grid_cell_bytes = (set.trees.canopy ? TREES_SKY_CELL_BYTES : 0.0) +
                                         (radius_free ? run_box_sky_cell_bytes(&set.common) : 0.0),
                      /* each cell's own ray hands no hull on */
                      .hull_lines = radius_free && run_box_sky_cell_bytes(&set.common) > 0};
    if ((rc = job_open_banded(&job, product->name, &set.common, pos, n_pos, cost)))
        return rc;
    if ((rc = job_plan(&job, &set.common, product, &set.sky, 0, NULL)) >= 0) {
        job_close(&job);
        return rc;
    }
    ss_raster_writer *w = NULL;
    int with_trees = set.trees.canopy != NULL;
    ss_status st = job_open_output(&job, with_trees ? 3 : 1, &set.common, &w);
    sky_trees tr = {0};
    int tree_rank = with_trees && w; /* rank 0 sweeps the crowns */
    if (st == SS_OK && tree_rank)
        st = trees_open(&job, &set.trees, &tr.t);
    size_t cells = (size_t)job.dem.grid.width * (size_t)job.dem.grid.height;
    if (st == SS_OK && tree_rank && !(tr.svf = malloc(cells * sizeof(float))))
        st = ss_ctx_error(job.run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
    double lo = NAN, mean = NAN, hi = NAN;
    ss_band_stats bands = {0};
    if (st == SS_OK)
        st = sky_product(&job, product, &set.sky, w, tr.svf, &bands, &lo, &mean, &hi);
    if (st == SS_OK && tree_rank)
        st = sky_trees_write(&job, &set.trees, req.svf_definition, &tr, w);
    char term[32];
    ss_param_choice(product->own_table, ss_param_table_named(product->own_table)->params->name,
                    set.sky.term, term, sizeof term);
    if (st == SS_OK && w) {
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        sky_metadata(w, product, &set.sky, term);
        if (with_trees)
            sky_trees_metadata(w, &set.trees, &tr);
    }
    if (st == SS_OK && w)
        st = run_commit(&job.run, w);
    else if (w)
        ss_writer_abort(w);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        command_print_job_sweep(&job, &bands);
        /* A fraction to four places; degrees to two, named. */
        int degrees = strcmp(product->outputs[0].unit, "deg") == 0;
        printf("%-7s %s, min %.*f mean %.*f max %.*f%s -> %s\n", product->name, term,
               degrees ? 2 : 4, lo, degrees ? 2 : 4, mean, degrees ? 2 : 4, hi,
               degrees ? " deg" : "", job.output);
        char described[400];
        if (tree_rank)
            trees_describe(&set.trees, &tr.t, described, sizeof described);
        if (tree_rank)
            printf("trees   %s: svfveg mean %.4f, svfbuveg mean %.4f (trunk gaps %s; "
                   "crowns swept on the host on digital lines, %.3f s)\n",
                   described, tr.veg_mean, tr.total_mean,
                   set.trees.trunk_gaps == SS_TRUNK_GAPS_OPEN ? "open" : "ignored", tr.seconds);
        if (tree_rank && tr.t.below_ground)
            printf("trees   %zu absolute crown tops below the DSM taken as no tree\n",
                   tr.t.below_ground);
    }
    free(tr.svf);
    trees_free(&tr.t);
    job_close(&job);
    return rc;
}
