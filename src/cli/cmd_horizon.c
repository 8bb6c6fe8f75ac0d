/* skysweep horizon: one band per azimuth with the horizon elevation angle,
 * optionally files with the distance to the horizon-casting point and its
 * ground height, and with trees (--canopy) the canopy horizon. Each direction's rows are written as soon as the library
 * has them (ss_horizon_rows), so memory stays a batch of directions' band
 * of rows, whether the DEM is held whole or read band by band. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "horizon_points.h"
#include "run.h"
#include "trees.h"

typedef struct {
    common_settings common;
    const char *distance_path;
    const char *cast_height_path;
    const char *canopy_horizon_path;
    horizon_point_settings pts;
    tree_settings trees;
} horizon_settings;

#define PTS(field) offsetof(horizon_settings, pts.field)
static const opt_spec horizon_options[] = {
    {"distance", OPT_OUTPUT, offsetof(horizon_settings, distance_path), "FILE", NULL, 0, 0,
     NULL, "also write the distance (m) to the horizon-casting point, one band per azimuth; 0 "
           "where no terrain lies ahead (box lines by each cell's own ray: the cell's own edge "
           "where nothing rises above its top)"},
    {"cast-height", OPT_OUTPUT, offsetof(horizon_settings, cast_height_path), "FILE", NULL, 0, 0,
     NULL, "also write the ground height (m, the DEM's datum) of the horizon-casting point, one "
           "band per azimuth; nodata where no terrain lies ahead (box lines by each cell's own "
           "ray: the cell's own height where nothing rises above its top)"},
    {"canopy-horizon", OPT_OUTPUT, offsetof(horizon_settings, canopy_horizon_path), "FILE", NULL,
     0, 0, NULL,
     "with --canopy: also write the canopy horizon, the higher of the solid horizon and the "
     "crowns' tops (degrees), one band per azimuth"},
    {"point", OPT_STRING, PTS(point), "LON,LAT", NULL, 0, 0, NULL,
     "horizon profile of one site instead of rasters (doc/pv-horizons.md); OUTPUT is then "
     "optional (standard output)"},
    {"points", OPT_INPUT, PTS(points), "FILE", NULL, 0, 0, NULL,
     "profiles of the sites in a CSV file with the columns id,lon,lat and optionally height"},
    {"point-crs", OPT_STRING, PTS(point_crs), "CRS", "EPSG:4326", 0, 0, NULL,
     "CRS of --point and --points coordinates: 'dem' for the DEM's own, or any CRS GDAL reads"},
    {"step", OPT_DOUBLE, PTS(step_deg), "DEG", "1", 0.00036, 360, NULL,
     "azimuth step of site profiles, from true north; 360 / step must be whole"},
    {"height", OPT_DOUBLE, PTS(height_m), "METRES", "0", 0, 1e6, NULL,
     "observer (e.g. PV module) height above the ground at the sites"},
    {"format", OPT_CHOICE, PTS(format), NULL, "csv", 0, 0, HORIZON_POINT_FORMATS,
     "site profile format; pvgis: the elevations at equal steps clockwise from north, "
     "comma-separated (PVGIS user horizon); pvsyst, pvsol (.hor), helioscope (SunEye CSV), "
     "sam (azimuth by altitude beam shading table): horizon files in each tool's own "
     "convention (doc/pv-horizons.md)"},
    {"horizon-of", OPT_CHOICE, PTS(horizon_of), NULL, "solid", 0, 0, HORIZON_OF_CHOICES,
     "the profile a PV format's file holds: solid (DSM and --far terrain), or with --canopy "
     "canopy, the higher of it and the crowns' tops (a PV tool takes one opaque horizon: "
     "canopy is the conservative one for leaf-on)"},
    {"far", OPT_INPUT, PTS(far), "DEM", NULL, 0, 0, NULL,
     "terrain DEM (any CRS and grid) for the far horizon of the sites, merged with the "
     "DEM's horizon by the larger elevation per azimuth; eyes at the same absolute height"},
    OPT_END};

typedef struct {
    ss_raster_writer *out[3]; /* angles, distances, casting heights (by SS_OUT_HORIZON_*) */
    /* --canopy-horizon: its writer, the trees, the crowns' horizon of the
     * direction last asked for (whole grid) and a band of rows. */
    ss_raster_writer *canopy_out;
    sweep_job *job;
    trees *trees;
    float *crown_deg, *rows;
    int crown_index;
} horizon_writers;

/* The canopy horizon's rows of direction `index`: the higher of the solid
 * horizon and the crowns' (computed for the whole grid when the direction
 * changes; bands bring each direction back once a band). */
static ss_status canopy_rows(horizon_writers *hw, int index, int row0, int n_rows,
                             const float *solid)
{
    sweep_job *job = hw->job;
    if (hw->crown_index != index) {
        ss_grid ground = trees_ground(job, hw->trees);
        double grid_az = ss_direction_azimuth(&job->opt, index) - job->opt.grid_north_deg;
        ss_status st = ss_canopy_top_horizon(job->run.ctx, &ground, &hw->trees->canopy, grid_az,
                                             hw->crown_deg);
        if (st != SS_OK)
            return st;
        hw->crown_index = index;
    }
    size_t n = (size_t)n_rows * (size_t)job->dem.grid.width;
    const float *crown = hw->crown_deg + (size_t)row0 * (size_t)job->dem.grid.width;
    for (size_t c = 0; c < n; ++c)
        hw->rows[c] = solid[c] == SS_NODATA ? SS_NODATA : fmaxf(solid[c], crown[c]);
    return ss_writer_rows(hw->canopy_out, index + 1, row0, n_rows, hw->rows);
}

static ss_status store_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    horizon_writers *hw = user;
    ss_status st = ss_writer_rows(hw->out[output], index + 1, row0, n_rows, values);
    if (st == SS_OK && hw->canopy_out && output == SS_OUT_HORIZON_ANGLE)
        st = canopy_rows(hw, index, row0, n_rows, values);
    return st;
}

/* Every direction's horizon, each direction's rows written as they come. */
static ss_status sweep(sweep_job *job, horizon_writers *hw, int want, ss_band_stats *bands)
{
    for (int i = 0; i < job->opt.directions; ++i) {
        char desc[64];
        snprintf(desc, sizeof desc, "azimuth %.10g", ss_direction_azimuth(&job->opt, i));
        for (int k = 0; k < 3; ++k)
            if (hw->out[k])
                ss_writer_describe(hw->out[k], i + 1, desc, k == 0 ? "deg" : "m");
        if (hw->canopy_out)
            ss_writer_describe(hw->canopy_out, i + 1, desc, "deg");
    }
    ss_source src = job_source(job, bands);
    return ss_horizon_rows(job->run.ctx, &src, &job->opt, want, store_rows, hw);
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
    opt_spec tree_opts[TREE_OPTIONS_MAX];
    const opt_spec *tables[] = {
        horizon_options,
        tree_options(offsetof(horizon_settings, trees), 0,
                     "the canopy horizon (--canopy-horizon), or for sites the columns "
                     "canopy_elevation_deg and crown_elevation_deg; trunks and transmissivity do "
                     "not change them",
                     tree_opts),
        common_options(), NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("horizon", tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 1,
                       "skysweep horizon [options] DEM... OUTPUT\n"
                       "       skysweep horizon --point LON,LAT | --points FILE [options] DEM... "
                       "[OUTPUT|-]",
                       ss_product_named("horizon")->description,
                       &set.common.device);
    if (rc < 0)
        rc = trees_options_alone("horizon", tables, &set, &set.trees);
    if (rc >= 0)
        return rc;
    if (!set.trees.canopy != !set.canopy_horizon_path && !set.pts.point && !set.pts.points)
        return run_usage_error("horizon", "--canopy and --canopy-horizon go together: the "
                                          "canopy horizon is written to --canopy-horizon");
    static const char *const top_only[] = {"trunk", "trunk-ratio", "transmissivity"};
    for (size_t i = 0; set.trees.canopy && i < sizeof top_only / sizeof *top_only; ++i)
        if (!opt_at_default(opt_find(tables, top_only[i]), &set)) {
            char why[120];
            snprintf(why, sizeof why, "--%s does not change the canopy horizon (the crowns' "
                     "tops): leave it out", top_only[i]);
            return run_usage_error("horizon", why);
        }
    if (set.pts.point || set.pts.points) {
        if (set.distance_path || set.cast_height_path || set.canopy_horizon_path)
            return run_usage_error("horizon", "--distance, --cast-height and --canopy-horizon "
                                              "are for raster output; site profiles carry "
                                              "them as columns");
        set.pts.trees = set.trees.canopy ? &set.trees : NULL;
        return horizon_points_run(&set.common, &set.pts, pos, n_pos);
    }
    if (set.pts.far)
        return run_usage_error("horizon", "--far is for site profiles (--point, --points)");
    if (!opt_at_default(opt_find(tables, "horizon-of"), &set))
        return run_usage_error("horizon", "--horizon-of is for site profiles (--point, "
                                          "--points)");
    if (n_pos < 2)
        return run_usage_error("horizon", "needs an input DEM and an output file");
    int want = (set.distance_path ? SS_HORIZON_DISTANCE : 0) |
               (set.cast_height_path ? SS_HORIZON_CAST_HEIGHT : 0);
    /* Swept whole, GDAL holds about a float per cell and output band as
     * the directions' rows arrive (measured: 50 bytes a cell for 4
     * directions with distances, doc/scale.md); --directions auto may
     * take up to 64. */
    int outputs = 1 + (set.distance_path != NULL) + (set.cast_height_path != NULL);
    int directions = set.common.sweep.directions ? set.common.sweep.directions : 64;
    band_cost cost = {.cell_bytes = ss_horizon_band_cell_bytes(want),
                      .column_bytes = ss_horizon_column_bytes(),
                      .output_bytes = 4.0 * (outputs + (set.trees.canopy != NULL)) * directions,
                      .grid_cell_bytes = (set.trees.canopy ? TREES_HORIZON_CELL_BYTES : 0.0) +
                                         run_box_sky_cell_bytes(&set.common),
                      /* each cell's own ray hands no hull on */
                      .hull_lines = run_box_sky_cell_bytes(&set.common) > 0};
    sweep_job job;
    if ((rc = job_open_banded(&job, "horizon", &set.common, pos, n_pos, cost)))
        return rc;
    if ((rc = job_plan(&job, &set.common, ss_product_named("horizon"), NULL, 0, NULL)) >= 0) {
        job_close(&job);
        return rc;
    }
    const char *extras[] = {set.distance_path, set.cast_height_path, set.canopy_horizon_path};
    for (int i = 0; i < 3; ++i) {
        ss_status bad = extras[i] ? run_check_output(&job.run, extras[i]) : SS_OK;
        if (bad != SS_OK) {
            rc = run_fail(&job.run, bad);
            job_close(&job);
            return rc;
        }
    }
    horizon_writers hw = {{NULL, NULL, NULL}, NULL, &job, NULL, NULL, NULL, -1};
    trees tr = {0};
    ss_status st = SS_OK;
    if (set.trees.canopy) {
        size_t cells = (size_t)job.dem.grid.width * (size_t)job.dem.grid.height;
        hw.trees = &tr;
        st = trees_open(&job, &set.trees, &tr);
        hw.crown_deg = malloc(cells * sizeof(float));
        hw.rows = malloc(cells * sizeof(float));
        if (st == SS_OK && (!hw.crown_deg || !hw.rows))
            st = ss_ctx_error(job.run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
        if (st == SS_OK)
            st = open_extra(&job, &set, set.canopy_horizon_path, &hw.canopy_out);
    }
    if (st == SS_OK)
        st = ss_writer_open(job.run.ctx, job.output, &job.dem, job.opt.directions,
                                  set.common.format, set.common.creation_options.items,
                                  &hw.out[SS_OUT_HORIZON_ANGLE]);
    if (st == SS_OK && set.distance_path)
        st = open_extra(&job, &set, set.distance_path, &hw.out[SS_OUT_HORIZON_DISTANCE]);
    if (st == SS_OK && set.cast_height_path)
        st = open_extra(&job, &set, set.cast_height_path, &hw.out[SS_OUT_HORIZON_CAST_HEIGHT]);
    ss_band_stats bands = {0};
    if (st == SS_OK)
        st = sweep(&job, &hw, want, &bands);
    static const char *const quantity[3] = {
        "horizon elevation angle, degrees above the horizontal; -90 where no terrain lies "
        "ahead",
        "distance along the azimuth to the horizon-casting point, metres; 0 where no terrain "
        "lies ahead",
        "ground height of the horizon-casting point, metres in the DEM's vertical datum; "
        "nodata where no terrain lies ahead"};
    /* Each cell's own ray (doc/model.md): a cell's own flat top is its
     * horizon where nothing rises above it, so none is ever -90. */
    static const char *const quantity_rays[3] = {
        "horizon elevation angle, degrees above the horizontal; 0 where nothing rises above "
        "the cell's own flat top",
        "distance along the azimuth to the horizon-casting point (where the ray enters the "
        "casting column), metres; where nothing rises above the cell's own top, the distance "
        "to its own edge",
        "ground height of the horizon-casting point, metres in the DEM's vertical datum; "
        "where nothing rises above the cell's own top, the cell's own height"};
    /* Box lines' horizons are never below a cell's own top either
     * (doc/model.md); their distances and casting heights are the lines'. */
    static const char *const angle_box_lines =
        "horizon elevation angle, degrees above the horizontal; 0 where nothing rises above "
        "the cell's own flat top";
    int rays = ss_ctx_counters(job.run.ctx).box_sky_directions > 0;
    int box = job.opt.lines == SS_LINES_BOX;
    for (int k = 0; k < 3 && st == SS_OK; ++k)
        if (hw.out[k]) {
            run_common_metadata(&job.run, hw.out[k], &job.opt, &job.frame);
            if (k == 0)
                job_plan_metadata(&job, hw.out[k]);
            ss_writer_metadata(hw.out[k], "QUANTITY",
                               rays                ? quantity_rays[k]
                               : box && k == 0 ? angle_box_lines
                                                   : quantity[k]);
        }
    if (st == SS_OK && hw.canopy_out) {
        run_common_metadata(&job.run, hw.canopy_out, &job.opt, &job.frame);
        ss_writer_metadata(hw.canopy_out, "QUANTITY",
                           job.opt.lines == SS_LINES_BOX
                               ? "canopy horizon elevation angle, degrees above the horizontal: "
                                 "the higher of the solid horizon (box lines: 0 at least, a "
                                 "cell's own flat top) and the crowns' tops (digital lines, the "
                                 "earth flat)"
                               : "canopy horizon elevation angle, degrees above the horizontal: "
                                 "the higher of the solid horizon and the crowns' tops (digital "
                                 "lines, the earth flat); -90 where nothing lies ahead");
        trees_metadata(hw.canopy_out, &set.trees, &tr);
    }
    /* Committed (closed, renamed into place) in turn; a file that fails
     * to commit, and those after it, are aborted: none is left half-written,
     * but files of an earlier run under the later names stay as they were
     * (the error names the file that failed). */
    for (int w = 0; w < 3 && st == SS_OK; ++w)
        if (hw.out[w]) {
            st = run_commit(&job.run, hw.out[w]);
            hw.out[w] = NULL;
        }
    if (st == SS_OK && hw.canopy_out) {
        st = run_commit(&job.run, hw.canopy_out);
        hw.canopy_out = NULL;
    }
    for (int w = 0; w < 3; ++w)
        ss_writer_abort(hw.out[w]);
    ss_writer_abort(hw.canopy_out);
    free(hw.crown_deg);
    free(hw.rows);
    trees_free(&tr);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        command_print_job_sweep(&job, &bands);
        printf("horizon %d bands (degrees) -> %s%s%s%s%s\n", job.opt.directions, job.output,
               set.distance_path ? ", distances -> " : "",
               set.distance_path ? set.distance_path : "",
               set.cast_height_path ? ", casting heights -> " : "",
               set.cast_height_path ? set.cast_height_path : "");
        if (set.trees.canopy)
            printf("trees   %s: canopy horizons -> %s\n", set.trees.canopy,
                   set.canopy_horizon_path);
    }
    job_close(&job);
    return rc;
}
