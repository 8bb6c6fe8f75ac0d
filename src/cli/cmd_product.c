/* skysweep PRODUCT for a registry product (skysweep_products.h) that has a
 * run call and no command written for it (main.c lists each such product):
 * its own table's options and the sweep's, the DEM held whole or read in
 * bands, the plan from ss_product_prepare, and its first output written
 * as the entry declares it (bands, band names, unit). Its optional outputs
 * are not written: a product that has some needs a command of its own. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "mpi_share.h"
#include "run.h"

enum { OWN_OPTIONS_MAX = 32 };

typedef struct {
    common_settings common; /* first: common_options()' offsets are relative to it */
    double params[64];      /* the product's own table's struct (aligned; params_size checked) */
} product_settings;

typedef struct {
    ss_raster_writer *w; /* rank 0's */
    int width;
    run_tally tally;
} product_rows;

static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    product_rows *k = user;
    if (!k->w || output != 0) /* another process's rows, or an optional output */
        return SS_OK;
    run_tally_add(&k->tally, values, (size_t)n_rows * (size_t)k->width);
    return ss_writer_rows(k->w, index + 1, row0, n_rows, values);
}

/* Band i's description: the i-th of the '|'-separated names, or with one
 * band per direction the pattern with DEG as the direction's azimuth. */
static void band_name(const ss_product_output *out, const ss_sweep_options *opt, int i,
                      char *buf, size_t size)
{
    const char *names = out->band_names;
    if (out->bands == 0) {
        const char *deg = strstr(names, "DEG");
        if (deg)
            snprintf(buf, size, "%.*s%.10g%s", (int)(deg - names), names,
                     ss_direction_azimuth(opt, i), deg + 3);
        else
            snprintf(buf, size, "%s %d", names, i + 1);
        return;
    }
    for (int k = 0; k < i && strchr(names, '|'); ++k)
        names = strchr(names, '|') + 1;
    const char *end = strchr(names, '|');
    snprintf(buf, size, "%.*s", end ? (int)(end - names) : (int)strlen(names), names);
}

static ss_status run_product(sweep_job *job, const ss_product_info *product, const void *params,
                             ss_raster_writer *w, ss_band_stats *stats, double *min,
                             double *mean, double *max)
{
    product_rows k = {w, job->dem.grid.width, {0, 0, 0, 0}};
    ss_source src = job_source(job, stats);
    share_reducer reducer;
    ss_share share = share_of(&reducer, &job->run, job_bands(job));
    ss_status st =
        product->run(job->run.ctx, &src, &job->opt, params, NULL, 0, &share, write_rows, &k);
    st = share_end(&reducer, st);
    run_tally_result(&k.tally, NAN, min, mean, max);
    return st;
}

int cmd_product(int argc, char **argv)
{
    const ss_product_info *product = ss_product_named(argv[0]);
    if (product->params_size > sizeof ((product_settings *)0)->params) {
        fprintf(stderr, "skysweep %s: its parameters do not fit the generic command\n",
                product->name);
        return SS_ERR_INTERNAL;
    }
    product_settings set = {0};
    opt_spec own_options[OWN_OPTIONS_MAX];
    const opt_spec *tables[] = {common_options(), NULL, NULL};
    if (product->own_table) {
        opt_from_params(product->own_table, offsetof(product_settings, params), own_options,
                        OWN_OPTIONS_MAX);
        tables[0] = own_options;
        tables[1] = common_options();
    }
    const void *params = product->own_table ? (const void *)set.params : NULL;
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    char usage[96];
    snprintf(usage, sizeof usage, "skysweep %s [options] DEM... OUTPUT", product->name);
    int rc = run_parse(product->name, tables, &set, argc, argv, pos, &n_pos,
                       COMMAND_MAX_INPUTS + 1, 2, usage, product->description,
                       &set.common.device);
    if (rc >= 0)
        return rc;
    sweep_job job;
    band_cost cost = {.cell_bytes = product->cell_bytes(params, 0),
                      .halo_m = product->halo_m(params, NAN)};
    if ((rc = job_open_banded(&job, product->name, &set.common, pos, n_pos, cost)))
        return rc;
    if ((rc = job_plan(&job, &set.common, product, params, 0, NULL)) >= 0) {
        job_close(&job);
        return rc;
    }
    const ss_product_output *out = &product->outputs[0];
    int n_bands = out->bands ? out->bands : job.opt.directions;
    ss_raster_writer *w = NULL;
    ss_status st = job_open_output(&job, n_bands, &set.common, &w);
    double lo = NAN, mean = NAN, hi = NAN;
    ss_band_stats bands = {0};
    if (st == SS_OK)
        st = run_product(&job, product, params, w, &bands, &lo, &mean, &hi);
    if (st == SS_OK && w) {
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        for (int i = 0; i < n_bands; ++i) {
            char name[128];
            band_name(out, &job.opt, i, name, sizeof name);
            ss_writer_describe(w, i + 1, name, out->unit);
        }
    }
    if (st == SS_OK && w)
        st = run_commit(&job.run, w);
    else if (w)
        ss_writer_abort(w);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        command_print_job_sweep(&job, &bands);
        printf("%-7s %d band%s, min %.4g mean %.4g max %.4g%s%s -> %s\n", product->name,
               n_bands, n_bands == 1 ? "" : "s", lo, mean, hi, out->unit[0] ? " " : "",
               out->unit, job.output);
    }
    job_close(&job);
    return rc;
}
