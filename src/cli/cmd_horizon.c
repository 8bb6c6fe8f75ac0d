/* skysweep horizon: one band per azimuth with the horizon elevation angle,
 * optionally files with the distance to the horizon-casting point and its
 * ground height. Bands are written as their directions finish, so memory
 * stays one grid per file; a DEM whose sweep does not fit in --memory is
 * swept in bands of rows (ss_horizon_banded), each direction's rows
 * written as each band finishes them. */
#include "config.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "horizon_points.h"
#include "run.h"

typedef struct {
    common_settings common;
    const char *distance_path;
    const char *cast_height_path;
    horizon_point_settings pts;
} horizon_settings;

#define PTS(field) offsetof(horizon_settings, pts.field)
static const opt_spec horizon_options[] = {
    {"distance", OPT_STRING, offsetof(horizon_settings, distance_path), "FILE", NULL, 0, 0,
     NULL, "also write the distance (m) to the horizon-casting point, one band per azimuth"},
    {"cast-height", OPT_STRING, offsetof(horizon_settings, cast_height_path), "FILE", NULL, 0, 0,
     NULL, "also write the ground height (m, the DEM's datum) of the horizon-casting point, one "
           "band per azimuth; nodata where no terrain lies ahead"},
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
    ss_raster_writer *angle, *dist, *cast;
    ss_status status;
    sweep_job *job;      /* the DEM: its size; in banded runs its rows and origin */
    float *cast_scratch; /* banded runs: a band of casting heights with the origin added */
} horizon_sink_state;

static int store_direction(int index, double azimuth_deg, const float *angle_deg,
                           const float *dist_m, const float *cast_height_m, void *user)
{
    (void)azimuth_deg;
    horizon_sink_state *hs = user;
    int height = hs->job->dem.grid.height;
    hs->status = ss_writer_rows(hs->angle, index + 1, 0, height, angle_deg);
    if (hs->status == SS_OK && hs->dist)
        hs->status = ss_writer_rows(hs->dist, index + 1, 0, height, dist_m);
    if (hs->status == SS_OK && hs->cast)
        hs->status = ss_writer_rows(hs->cast, index + 1, 0, height, cast_height_m);
    return hs->status == SS_OK;
}

static ss_status read_band_rows(void *user, int row0, int n_rows, float *z)
{
    horizon_sink_state *hs = user;
    return job_read_rows(hs->job, row0, n_rows, z);
}

static ss_status store_band_rows(void *user, int direction, int row0, int n_rows,
                                 const float *angle_deg, const float *dist_m,
                                 const float *cast_height_m)
{
    horizon_sink_state *hs = user;
    ss_status st = ss_writer_rows(hs->angle, direction + 1, row0, n_rows, angle_deg);
    if (st == SS_OK && hs->dist)
        st = ss_writer_rows(hs->dist, direction + 1, row0, n_rows, dist_m);
    if (st == SS_OK && hs->cast) {
        /* The band's heights are relative to the DEM's origin, as read. */
        size_t n = (size_t)n_rows * (size_t)hs->job->dem.grid.width;
        for (size_t c = 0; c < n; ++c)
            hs->cast_scratch[c] = cast_height_m[c] == SS_NODATA
                                      ? SS_NODATA
                                      : (float)(hs->job->dem.grid.z_origin_m + cast_height_m[c]);
        st = ss_writer_rows(hs->cast, direction + 1, row0, n_rows, hs->cast_scratch);
    }
    return st;
}

/* Every direction's horizon, on the whole grid or band by band. */
static ss_status sweep(horizon_sink_state *hs, int want, ss_band_stats *bands)
{
    sweep_job *job = hs->job;
    const ss_grid *g = &job->dem.grid;
    ss_raster_writer *writers[] = {hs->angle, hs->dist, hs->cast};
    for (int i = 0; i < job->opt.directions; ++i) {
        char desc[64];
        snprintf(desc, sizeof desc, "azimuth %.10g", ss_direction_azimuth(&job->opt, i));
        for (int k = 0; k < 3; ++k)
            if (writers[k])
                ss_writer_describe(writers[k], i + 1, desc, k == 0 ? "deg" : "m");
    }
    if (!job->source) {
        ss_status st = ss_horizon(job->run.ctx, g, &job->opt, want, store_direction, hs);
        return hs->status != SS_OK ? hs->status : st;
    }
    if (hs->cast && !(hs->cast_scratch = malloc(sizeof(float) * (size_t)job->band_rows *
                                                (size_t)g->width)))
        return ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for a band");
    ss_horizon_band_io io = {g->width, g->height, g->cell_x_m, g->cell_y_m, job->band_rows,
                             read_band_rows, store_band_rows, hs, 0, NULL, -90.0f, bands, NULL};
    ss_status st = ss_horizon_banded(job->run.ctx, &io, &job->opt, want);
    free(hs->cast_scratch);
    hs->cast_scratch = NULL;
    return st;
}

/* Opens one more horizon output (distance or casting height); its name
 * was checked against the inputs and the other outputs before. */
static ss_status open_extra(sweep_job *job, const horizon_settings *set, const char *path,
                            ss_raster_writer **w)
{
    return ss_writer_open(job->run.ctx, path, &job->dem, job->opt.directions, set->common.format,
                          set->common.creation_options.items, w);
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
        if (set.distance_path || set.cast_height_path)
            return run_usage_error("horizon", "--distance and --cast-height are for raster "
                                              "output; site profiles carry both");
        return horizon_points_run(&set.common, &set.pts, pos, n_pos);
    }
    if (n_pos < 2)
        return run_usage_error("horizon", "needs an input DEM and an output file");
    if ((set.distance_path && ss_same_output(set.distance_path, pos[n_pos - 1])) ||
        (set.cast_height_path && ss_same_output(set.cast_height_path, pos[n_pos - 1])) ||
        (set.distance_path && set.cast_height_path &&
         ss_same_output(set.distance_path, set.cast_height_path)))
        return run_usage_error("horizon", "OUTPUT, --distance and --cast-height must name "
                                          "different files");
    int want = (set.distance_path ? SS_HORIZON_DISTANCE : 0) |
               (set.cast_height_path ? SS_HORIZON_CAST_HEIGHT : 0);
    band_cost cost = {ss_horizon_band_cell_bytes(want), ss_horizon_column_bytes(), 0};
    sweep_job job;
    if ((rc = job_open_banded(&job, "horizon", &set.common, pos, n_pos, cost)))
        return rc;
    if ((rc = job_plan(&job, &set.common, SS_PRODUCT_HORIZON, 0, NULL, SS_SHADOW_EXACT)) >= 0) {
        job_close(&job);
        return rc;
    }
    /* run_check_output prints its own one-line error. */
    const char *extras[] = {set.distance_path, set.cast_height_path};
    for (int i = 0; i < 2; ++i) {
        ss_status bad = extras[i] ? run_check_output(&job.run, extras[i], job.inputs, job.n_inputs)
                                  : SS_OK;
        if (bad != SS_OK) {
            job_close(&job);
            return bad;
        }
    }
    horizon_sink_state hs = {NULL, NULL, NULL, SS_OK, &job, NULL};
    ss_status st = ss_writer_open(job.run.ctx, job.output, &job.dem, job.opt.directions,
                                  set.common.format, set.common.creation_options.items, &hs.angle);
    if (st == SS_OK && set.distance_path)
        st = open_extra(&job, &set, set.distance_path, &hs.dist);
    if (st == SS_OK && set.cast_height_path)
        st = open_extra(&job, &set, set.cast_height_path, &hs.cast);
    ss_band_stats bands = {0};
    if (st == SS_OK)
        st = sweep(&hs, want, &bands);
    if (st == SS_OK) {
        run_common_metadata(&job.run, hs.angle, &job.opt, &job.frame);
        job_plan_metadata(&job, hs.angle);
        ss_writer_metadata(hs.angle, "QUANTITY",
                           "horizon elevation angle, degrees above the horizontal; -90 where "
                           "no terrain lies ahead");
        if (hs.dist) {
            run_common_metadata(&job.run, hs.dist, &job.opt, &job.frame);
            ss_writer_metadata(hs.dist, "QUANTITY",
                               "distance along the azimuth to the horizon-casting point, "
                               "metres; 0 where no terrain lies ahead");
        }
        if (hs.cast) {
            run_common_metadata(&job.run, hs.cast, &job.opt, &job.frame);
            ss_writer_metadata(hs.cast, "QUANTITY",
                               "ground height of the horizon-casting point, metres in the "
                               "DEM's vertical datum; nodata where no terrain lies ahead");
        }
    }
    /* Committed (closed, renamed into place) in turn; a file that fails
     * to commit, and those after it, are aborted: none is left half-written,
     * but files of an earlier run under the later names stay as they were
     * (the error names the file that failed). */
    ss_raster_writer **writers[] = {&hs.angle, &hs.dist, &hs.cast};
    for (int w = 0; w < 3 && st == SS_OK; ++w)
        if (*writers[w]) {
            st = run_commit(&job.run, *writers[w]);
            *writers[w] = NULL;
        }
    for (int w = 0; w < 3; ++w)
        ss_writer_abort(*writers[w]);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        command_print_job_sweep(&job, &bands);
        printf("horizon %d bands (degrees) -> %s%s%s%s%s\n", job.opt.directions, job.output,
               set.distance_path ? ", distances -> " : "",
               set.distance_path ? set.distance_path : "",
               set.cast_height_path ? ", casting heights -> " : "",
               set.cast_height_path ? set.cast_height_path : "");
    }
    job_close(&job);
    return rc;
}
