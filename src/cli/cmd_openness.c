/* skysweep openness: positive or negative topographic openness GeoTIFF. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include "commands.h"
#include "sky_job.h"
#include "run.h"

typedef struct {
    common_settings common;  /* first: common_options()' offsets are relative to it */
    ss_openness_params open; /* the library's "openness" table */
} openness_settings;

int cmd_openness(int argc, char **argv)
{
    openness_settings set = {0};
    opt_spec openness_options[8];
    opt_from_params("openness", offsetof(openness_settings, open), openness_options, 8);
    const opt_spec *tables[] = {openness_options, common_options(), NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("openness", tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1,
                       2, "skysweep openness [options] DEM... OUTPUT",
                       "Topographic openness in degrees (Yokoyama et al. 2002), from horizons in "
                       "evenly spaced azimuths.\nSeveral DEM tiles are mosaicked first.",
                       &set.common.device);
    if (rc >= 0)
        return rc;
    sweep_job job;
    band_cost cost = {.cell_bytes = ss_sky_band_cell_bytes(SS_SKY_OPENNESS_POSITIVE),
                      .halo_m = set.open.radius_m};
    if ((rc = job_open_banded(&job, "openness", &set.common, pos, n_pos, cost)))
        return rc;
    job.radius_m = set.open.radius_m;
    if ((rc = job_plan(&job, &set.common, SS_PRODUCT_HORIZON, 0, NULL, SS_SHADOW_EXACT)) >= 0) {
        job_close(&job);
        return rc;
    }
    ss_raster_writer *w = NULL;
    ss_status st = job_open_output(&job, 1, &set.common, &w);
    double lo = NAN, mean = NAN, hi = NAN;
    ss_band_stats bands = {0};
    if (st == SS_OK)
        st = job_sky_product(&job, ss_openness_params_term(&set.open), set.open.radius_m, w,
                             &bands, &lo, &mean, &hi);
    char kind[32];
    ss_param_choice("openness", "kind", set.open.kind, kind, sizeof kind);
    if (st == SS_OK && w) {
        char radius[32];
        snprintf(radius, sizeof radius, "%g", set.open.radius_m);
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        char band[48];
        snprintf(band, sizeof band, "%s openness", kind);
        ss_writer_metadata(w, "OPENNESS_KIND", kind);
        ss_writer_metadata(w, "OPENNESS_RADIUS_M", set.open.radius_m > 0 ? radius : "unlimited");
        ss_writer_describe(w, 1, band, "deg");
    }
    if (st == SS_OK && w)
        st = run_commit(&job.run, w);
    else if (w)
        ss_writer_abort(w);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        command_print_job_sweep(&job, &bands);
        printf("openness %s, min %.2f mean %.2f max %.2f deg -> %s\n", kind, lo, mean, hi,
               job.output);
    }
    job_close(&job);
    return rc;
}
