/* skysweep svf: sky-view factor GeoTIFF from a DEM. */
#include "config.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "run.h"

typedef struct {
    common_settings common; /* first: common_options' offsets are relative to it */
    int definition;
} svf_settings;

static const char *const definition_names[] = {"geometric", "radiative", "horizontal"};
/* Choice order above -> library definition. */
static const ss_svf_definition definition_of_choice[] = {
    SS_SVF_DEF_GEOMETRIC, SS_SVF_DEF_TILTED, SS_SVF_DEF_HORIZONTAL};

static const opt_spec svf_options[] = {
    {"definition", OPT_CHOICE, offsetof(svf_settings, definition), NULL, "geometric", 0, 0,
     "geometric|radiative|horizontal",
     "geometric: 1 - mean sin h (Zaksek/RVT); radiative: cosine-weighted sky seen by the "
     "sloping cell (Dozier & Frew); horizontal: cosine-weighted, horizontal surface"},
    OPT_END};

int cmd_svf(int argc, char **argv)
{
    svf_settings set = {0};
    const opt_spec *tables[] = {svf_options, common_options, NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    char err[512];
    int r = opt_parse(tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, err,
                      sizeof err);
    if (r < 0)
        return run_usage_error("svf", err);
    if (r > 0) {
        opt_print_help(tables, "skysweep svf [options] DEM... OUTPUT",
                       "Sky-view factor of every cell (0..1), from exact horizons in evenly "
                       "spaced azimuths.\nSeveral DEM tiles are mosaicked first.");
        return 0;
    }
    if (set.common.device && strcmp(set.common.device, "list") == 0)
        return command_list_devices();
    if (n_pos < 2)
        return run_usage_error("svf", "needs an input DEM and an output file");

    run_state run;
    int rc = run_begin(&run, "svf", &set.common);
    if (rc)
        return rc;
    const char *output = pos[n_pos - 1];
    int n_in = n_pos - 1;
    ss_dem dem;
    ss_sweep_options opt;
    run_sweep_options(&set.common, &opt);
    ss_svf_definition def = definition_of_choice[set.definition];
    ss_raster_writer *w = NULL;
    float *svf = NULL;
    ss_status st = run_check_output(&run, output, pos, n_in);
    if (st != SS_OK) {
        run_end(&run);
        return st;
    }
    st = ss_sweep_options_check(run.ctx, &opt);
    if (st == SS_OK)
        st = run_read_dem(&run, pos, n_in, &set.common, &dem);
    if (st != SS_OK) {
        rc = run_fail(&run, st);
        run_end(&run);
        return rc;
    }
    st = ss_writer_open(run.ctx, output, &dem, 1, set.common.format,
                        set.common.creation_options.items, &w);
    size_t n = (size_t)dem.grid.width * (size_t)dem.grid.height;
    if (st == SS_OK) {
        svf = malloc(n * sizeof *svf);
        if (!svf)
            st = command_out_of_memory(&run);
    }
    if (st == SS_OK)
        st = ss_svf(run.ctx, &dem.grid, &opt, def, svf);
    if (st == SS_OK) {
        run_common_metadata(&run, w, &opt);
        ss_writer_metadata(w, "SVF_DEFINITION", definition_names[set.definition]);
        st = ss_writer_band(w, 1, svf, "sky-view factor", "1");
    }
    if (st == SS_OK)
        st = run_commit(&run, w);
    else
        ss_writer_abort(w);
    if (st != SS_OK) {
        rc = run_fail(&run, st);
    } else if (!run.quiet) {
        double lo, mean, hi;
        run_stats(svf, n, &lo, &mean, &hi);
        run_print_dem(&run, &dem);
        command_print_sweep(&run, &opt, dem.grid.width, dem.grid.height);
        printf("svf     %s, min %.4f mean %.4f max %.4f -> %s\n",
               definition_names[set.definition], lo, mean, hi, output);
    }
    free(svf);
    ss_dem_free(&dem);
    run_end(&run);
    return rc;
}
