/* skysweep svf: sky-view factor GeoTIFF from a DEM. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include "commands.h"
#include "sky_job.h"
#include "run.h"

typedef struct {
    common_settings common; /* first: common_options()' offsets are relative to it */
    ss_svf_params svf;      /* the library's "svf" table */
} svf_settings;

int cmd_svf(int argc, char **argv)
{
    svf_settings set = {0};
    opt_spec svf_options[8];
    opt_from_params("svf", offsetof(svf_settings, svf), svf_options, 8);
    const opt_spec *tables[] = {svf_options, common_options(), NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("svf", tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 2,
                       "skysweep svf [options] DEM... OUTPUT",
                       "Sky-view factor of every cell (0..1), from exact horizons in evenly "
                       "spaced azimuths.\nSeveral DEM tiles are mosaicked first.",
                       &set.common.device);
    if (rc >= 0)
        return rc;
    sweep_job job;
    ss_sky_term term = ss_svf_params_term(&set.svf);
    band_cost cost = {.cell_bytes = ss_sky_band_cell_bytes(term), .halo_m = set.svf.radius_m};
    if ((rc = job_open_banded(&job, "svf", &set.common, pos, n_pos, cost)))
        return rc;
    job.svf_definition = (ss_svf_definition)term;
    job.radius_m = set.svf.radius_m;
    if ((rc = job_plan(&job, &set.common, SS_PRODUCT_SVF, 0, NULL, SS_SHADOW_EXACT)) >= 0) {
        job_close(&job);
        return rc;
    }
    ss_raster_writer *w = NULL;
    ss_status st = job_open_output(&job, 1, &set.common, &w);
    double lo = NAN, mean = NAN, hi = NAN;
    ss_band_stats bands = {0};
    if (st == SS_OK)
        st = job_sky_product(&job, term, set.svf.radius_m, w, &bands, &lo, &mean, &hi);
    char definition[32];
    ss_param_choice("svf", "definition", set.svf.definition, definition, sizeof definition);
    if (st == SS_OK && w) {
        char radius[32];
        snprintf(radius, sizeof radius, "%g", set.svf.radius_m);
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        ss_writer_metadata(w, "SVF_DEFINITION", definition);
        ss_writer_metadata(w, "SVF_RADIUS_M", set.svf.radius_m > 0 ? radius : "unlimited");
        ss_writer_describe(w, 1, "sky-view factor", "1");
    }
    if (st == SS_OK && w)
        st = run_commit(&job.run, w);
    else if (w)
        ss_writer_abort(w);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        command_print_job_sweep(&job, &bands);
        printf("svf     %s, min %.4f mean %.4f max %.4f -> %s\n", definition, lo, mean, hi,
               job.output);
    }
    job_close(&job);
    return rc;
}
