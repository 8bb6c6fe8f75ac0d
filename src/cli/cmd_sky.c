/* skysweep svf and skysweep openness: a sky product of the registry
 * (skysweep_products.h) into one band, from the DEM held whole or read in
 * bands (job_open_banded), alone or shared between MPI processes
 * (mpi_share.h). Each is one entry of the registry; this file reads it. */
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
} sky_settings;

typedef struct {
    ss_raster_writer *w; /* rank 0's */
    int width;
    run_tally tally; /* of the finished rows */
} sky_rows;

static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)output, (void)index;
    sky_rows *k = user;
    if (!k->w) /* another process's rows: rank 0 writes */
        return SS_OK;
    run_tally_add(&k->tally, values, (size_t)n_rows * (size_t)k->width);
    return ss_writer_rows(k->w, 1, row0, n_rows, values);
}

/* The product into band 1 of w (rank 0's writer; NULL on other MPI ranks);
 * stats gets the hulls handed on between bands, min, mean and max the
 * product's (rank 0). */
static ss_status sky_product(sweep_job *job, const ss_product_info *product,
                             const sky_params *params, ss_raster_writer *w, ss_band_stats *stats,
                             double *min, double *mean, double *max)
{
    sky_rows k = {w, job->dem.grid.width, {0, 0, 0, 0}};
    ss_source src = job_source(job, stats);
    share_reducer reducer;
    ss_share share = share_of(&reducer, &job->run, job_bands(job));
    ss_status st = product->run(job->run.ctx, &src, &job->opt, params, 0, &share, write_rows, &k);
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

int cmd_sky(int argc, char **argv)
{
    const ss_product_info *product = ss_product_named(argv[0]);
    sky_settings set = {0};
    opt_spec own_options[8];
    opt_from_params(product->own_table, offsetof(sky_settings, sky), own_options, 8);
    const opt_spec *tables[] = {own_options, common_options(), NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    char usage[96];
    snprintf(usage, sizeof usage, "skysweep %s [options] DEM... OUTPUT", product->name);
    int rc = run_parse(product->name, tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1,
                       2, usage, product->description, &set.common.device);
    if (rc >= 0)
        return rc;
    sweep_job job;
    band_cost cost = {.cell_bytes = product->cell_bytes(&set.sky, 0),
                      .halo_m = product->halo_m(&set.sky, NAN)};
    if ((rc = job_open_banded(&job, product->name, &set.common, pos, n_pos, cost)))
        return rc;
    ss_plan_request req = {0};
    product->request(&set.sky, &req);
    job.svf_definition = req.svf_definition;
    job.radius_m = req.radius_m;
    if ((rc = job_plan(&job, &set.common, req.kind, 0, NULL, SS_SHADOW_EXACT)) >= 0) {
        job_close(&job);
        return rc;
    }
    ss_raster_writer *w = NULL;
    ss_status st = job_open_output(&job, 1, &set.common, &w);
    double lo = NAN, mean = NAN, hi = NAN;
    ss_band_stats bands = {0};
    if (st == SS_OK)
        st = sky_product(&job, product, &set.sky, w, &bands, &lo, &mean, &hi);
    char term[32];
    ss_param_choice(product->own_table, ss_param_table_named(product->own_table)->params->name,
                    set.sky.term, term, sizeof term);
    if (st == SS_OK && w) {
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        sky_metadata(w, product, &set.sky, term);
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
    }
    job_close(&job);
    return rc;
}
