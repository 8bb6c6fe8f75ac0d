/* skysweep horizon: one band per azimuth with the horizon elevation angle,
 * optionally a second file with the distance to the casting cell. Bands
 * are written as their directions finish, so memory stays one grid. */
#include "config.h"

#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "horizon_points.h"
#include "run.h"

typedef struct {
    common_settings common;
    const char *distance_path;
    horizon_point_settings pts;
} horizon_settings;

#define PTS(field) offsetof(horizon_settings, pts.field)
static const opt_spec horizon_options[] = {
    {"distance", OPT_STRING, offsetof(horizon_settings, distance_path), "FILE", NULL, 0, 0,
     NULL, "also write the distance (m) to the horizon-casting cell, one band per azimuth"},
    {"point", OPT_STRING, PTS(point), "LON,LAT", NULL, 0, 0, NULL,
     "horizon profile of one site instead of rasters (doc/pv-horizons.md); OUTPUT is then "
     "optional (standard output)"},
    {"points", OPT_STRING, PTS(points), "FILE", NULL, 0, 0, NULL,
     "profiles of the sites in a CSV file with the columns id,lon,lat and optionally height"},
    {"point-crs", OPT_STRING, PTS(point_crs), "CRS", "EPSG:4326", 0, 0, NULL,
     "CRS of --point and --points coordinates: 'dem' for the DEM's own, or any CRS GDAL reads"},
    {"step", OPT_DOUBLE, PTS(step_deg), "DEG", "1", 0.00036, 360, NULL,
     "azimuth step of site profiles, from true north; 360 / step must be whole"},
    {"height", OPT_DOUBLE, PTS(height_m), "METRES", "0", 0, 1e6, NULL,
     "observer (e.g. PV module) height above the ground at the sites"},
    {"format", OPT_CHOICE, PTS(format), NULL, "csv", 0, 0, HORIZON_POINT_FORMATS,
     "site profile format; pvgis: the elevations at equal steps clockwise from north, "
     "comma-separated (PVGIS user horizon)"},
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
    int rc = run_parse("horizon", tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 1,
                       "skysweep horizon [options] DEM... OUTPUT\n"
                       "       skysweep horizon --point LON,LAT | --points FILE [options] DEM... "
                       "[OUTPUT|-]",
                       "Horizon elevation angle (degrees above the horizontal; -90 where no "
                       "terrain lies ahead)\nof every cell, one band per azimuth, exact at "
                       "unlimited distance; or the horizon profiles of sites.",
                       &set.common.device);
    if (rc >= 0)
        return rc;
    if (set.pts.point || set.pts.points) {
        if (set.distance_path)
            return run_usage_error("horizon", "--distance is for raster output; site profiles "
                                              "carry their distances");
        return horizon_points_run(&set.common, &set.pts, pos, n_pos);
    }
    if (n_pos < 2)
        return run_usage_error("horizon", "needs an input DEM and an output file");
    if (set.distance_path && strcmp(set.distance_path, pos[n_pos - 1]) == 0)
        return run_usage_error("horizon", "--distance must name a file other than OUTPUT");
    sweep_job job;
    if ((rc = job_open(&job, "horizon", &set.common, pos, n_pos)))
        return rc;
    if ((rc = job_plan(&job, &set.common, SS_PRODUCT_HORIZON, 0, NULL, SS_SHADOW_EXACT)) >= 0) {
        job_close(&job);
        return rc;
    }
    ss_status st = set.distance_path ? run_check_output(&job.run, set.distance_path, job.inputs,
                                                        job.n_inputs)
                                     : SS_OK;
    if (st != SS_OK) {
        job_close(&job);
        return st;
    }
    horizon_sink_state hs = {NULL, NULL, SS_OK, 0, 0};
    st = ss_writer_open(job.run.ctx, job.output, &job.dem, job.opt.directions, set.common.format,
                        set.common.creation_options.items, &hs.angle);
    if (st == SS_OK && set.distance_path)
        st = ss_writer_open(job.run.ctx, set.distance_path, &job.dem, job.opt.directions,
                            set.common.format, set.common.creation_options.items, &hs.dist);
    if (st == SS_OK) {
        st = ss_horizon(job.run.ctx, &job.dem.grid, &job.opt, set.distance_path != NULL,
                        store_direction, &hs);
        if (hs.status != SS_OK)
            st = hs.status;
    }
    if (st == SS_OK) {
        run_common_metadata(&job.run, hs.angle, &job.opt, &job.frame);
        job_plan_metadata(&job, hs.angle);
        ss_writer_metadata(hs.angle, "QUANTITY",
                           "horizon elevation angle, degrees above the horizontal; -90 where "
                           "no terrain lies ahead");
        if (hs.dist) {
            run_common_metadata(&job.run, hs.dist, &job.opt, &job.frame);
            ss_writer_metadata(hs.dist, "QUANTITY",
                               "distance along the azimuth to the horizon-casting cell, "
                               "metres; 0 where no terrain lies ahead");
        }
        st = run_commit(&job.run, hs.angle);
        hs.angle = NULL;
    }
    if (st == SS_OK && hs.dist) {
        st = run_commit(&job.run, hs.dist);
        hs.dist = NULL;
    }
    ss_writer_abort(hs.angle);
    ss_writer_abort(hs.dist);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        command_print_sweep(&job.run, &job.opt, job.dem.grid.width, job.dem.grid.height);
        printf("horizon %d bands (degrees) -> %s%s%s\n", job.opt.directions, job.output,
               set.distance_path ? ", distances -> " : "",
               set.distance_path ? set.distance_path : "");
    }
    job_close(&job);
    return rc;
}
