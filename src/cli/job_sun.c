/* The sun for a sweeping command: given directly (--sun-azimuth,
 * --sun-elevation) or as an instant (--time, SPA at the DEM), one for the
 * whole DEM or one per cell (--sun-per-cell). */
#include "config.h"

#include <math.h>
#include <stdio.h>

#include "skysweep_sun.h"
#include "run.h"
#include "sun_field.h"

ss_status job_sun(sweep_job *job, const common_settings *common, ss_sun_field *field)
{
    ss_ctx *ctx = job->run.ctx;
    double unix_s;
    ss_status st = ss_sun_params_check(ctx, &common->sun, &unix_s);
    if (st != SS_OK)
        return st;
    if (!common->sun.time) {
        double az = common->sun.sun_azimuth_deg;
        /* In the grid frame the sun is given in grid azimuths. */
        if (common->sweep.north == SS_NORTH_GRID)
            az += job->frame.grid_north_deg;
        ss_sun_field_fixed(&job->frame, job->dem.grid.width, job->dem.grid.height, az,
                           common->sun.sun_elevation_deg, field);
        return SS_OK;
    }
    ss_spa_params p;
    ss_sun_params_spa(&common->sun, &p);
    /* The plan decided whether the sun is needed per cell. A DEM left in
     * its files gets the lattice only; the bands fill their rows. */
    if (job->source) {
        ss_sun_nodes nodes = {0};
        if (job->plan.sun_per_cell)
            st = ss_sun_nodes_make(ctx, &job->dem, &job->frame, job_rows_reader, job, &nodes);
        if (st == SS_OK)
            st = ss_sun_field_lattice(ctx, &job->dem, &job->frame, unix_s, &p,
                                      job->plan.sun_per_cell, 0, job->dem.grid.height, &nodes,
                                      field);
        ss_sun_nodes_free(&nodes);
        return st;
    }
    return ss_sun_field_compute(ctx, &job->dem, &job->frame, unix_s, &p, job->plan.sun_per_cell,
                                field);
}
