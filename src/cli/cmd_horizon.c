/* skysweep horizon: one band per azimuth with the horizon elevation angle,
 * optionally a second file with the distance to the casting cell. Bands
 * are written as their directions finish, so memory stays one grid. */
#include "config.h"

#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "run.h"

typedef struct {
    common_settings common;
    const char *distance_path;
} horizon_settings;

static const opt_spec horizon_options[] = {
    {"distance", OPT_STRING, offsetof(horizon_settings, distance_path), "FILE", NULL, 0, 0,
     NULL, "also write the distance (m) to the horizon-casting cell, one band per azimuth"},
    OPT_END};

typedef struct {
    ss_raster_writer *angle, *dist;
    ss_status status;
    double min, max;
} horizon_sink_state;

static int store_direction(int index, double azimuth_deg, const float *angle_deg,
                           const float *dist_m, void *user)
{
    horizon_sink_state *hs = user;
    char desc[64];
    snprintf(desc, sizeof desc, "azimuth %.10g", azimuth_deg);
    hs->status = ss_writer_band(hs->angle, index + 1, angle_deg, desc, "deg");
    if (hs->status == SS_OK && hs->dist)
        hs->status = ss_writer_band(hs->dist, index + 1, dist_m, desc, "m");
    return hs->status == SS_OK;
}

int cmd_horizon(int argc, char **argv)
{
    horizon_settings set = {0};
    const opt_spec *tables[] = {horizon_options, common_options, NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    char err[512];
    int r = opt_parse(tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, err,
                      sizeof err);
    if (r < 0)
        return run_usage_error("horizon", err);
    if (r > 0) {
        opt_print_help(tables, "skysweep horizon [options] DEM... OUTPUT",
                       "Horizon elevation angle (degrees above the horizontal; -90 where no "
                       "terrain lies ahead)\nof every cell, one band per azimuth, exact at "
                       "unlimited distance.");
        return 0;
    }
    if (set.common.device && strcmp(set.common.device, "list") == 0)
        return command_list_devices();
    if (n_pos < 2)
        return run_usage_error("horizon", "needs an input DEM and an output file");

    run_state run;
    int rc = run_begin(&run, "horizon", &set.common);
    if (rc)
        return rc;
    const char *output = pos[n_pos - 1];
    int n_in = n_pos - 1;
    ss_sweep_options opt;
    run_sweep_options(&set.common, &opt);
    ss_status st = run_check_output(&run, output, pos, n_in);
    if (st == SS_OK && set.distance_path)
        st = run_check_output(&run, set.distance_path, pos, n_in);
    if (st == SS_OK && set.distance_path && strcmp(set.distance_path, output) == 0)
        st = run_usage_error("horizon", "--distance must name a file other than OUTPUT");
    if (st != SS_OK) {
        run_end(&run);
        return st;
    }
    ss_dem dem;
    horizon_sink_state hs = {NULL, NULL, SS_OK, 0, 0};
    st = ss_sweep_options_check(run.ctx, &opt);
    if (st == SS_OK)
        st = run_read_dem(&run, pos, n_in, &set.common, &dem);
    if (st != SS_OK) {
        rc = run_fail(&run, st);
        run_end(&run);
        return rc;
    }
    st = ss_writer_open(run.ctx, output, &dem, opt.directions, set.common.format,
                        set.common.creation_options.items, &hs.angle);
    if (st == SS_OK && set.distance_path)
        st = ss_writer_open(run.ctx, set.distance_path, &dem, opt.directions, set.common.format,
                            set.common.creation_options.items, &hs.dist);
    if (st == SS_OK) {
        st = ss_horizon(run.ctx, &dem.grid, &opt, set.distance_path != NULL, store_direction,
                        &hs);
        if (hs.status != SS_OK)
            st = hs.status;
    }
    if (st == SS_OK) {
        run_common_metadata(&run, hs.angle, &opt);
        ss_writer_metadata(hs.angle, "QUANTITY",
                           "horizon elevation angle, degrees above the horizontal; -90 where "
                           "no terrain lies ahead");
        if (hs.dist) {
            run_common_metadata(&run, hs.dist, &opt);
            ss_writer_metadata(hs.dist, "QUANTITY",
                               "distance along the azimuth to the horizon-casting cell, "
                               "metres; 0 where no terrain lies ahead");
        }
        st = run_commit(&run, hs.angle);
        hs.angle = NULL;
    }
    if (st == SS_OK && hs.dist) {
        st = run_commit(&run, hs.dist);
        hs.dist = NULL;
    }
    ss_writer_abort(hs.angle);
    ss_writer_abort(hs.dist);
    if (st != SS_OK) {
        rc = run_fail(&run, st);
    } else if (!run.quiet) {
        run_print_dem(&run, &dem);
        command_print_sweep(&run, &opt, dem.grid.width, dem.grid.height);
        printf("horizon %d bands (degrees) -> %s%s%s\n", opt.directions, output,
               set.distance_path ? ", distances -> " : "",
               set.distance_path ? set.distance_path : "");
    }
    ss_dem_free(&dem);
    run_end(&run);
    return rc;
}
