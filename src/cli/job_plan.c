/* Runs the effects planner for a command and makes the job obey it. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "run.h"

int job_plan(sweep_job *job, const common_settings *common, ss_plan_kind kind, int n_steps,
             const double *step_unix_s, ss_shadow_mode shadow_mode)
{
    const ss_dem_frame *f = &job->frame;
    ss_place place = {f->georeferenced, f->geographic, f->centre_lon_deg, f->centre_lat_deg,
                      f->grid_north_deg, f->grid_north_min_deg, f->grid_north_max_deg,
                      f->cell_variation, f->diagonal_m, run_earth_radius(common, f)};
    if (!f->georeferenced) {
        double w = job->dem.grid.width * job->dem.grid.cell_x_m;
        double h = job->dem.grid.height * job->dem.grid.cell_y_m;
        place.diagonal_m = sqrt(w * w + h * h);
    }
    /* The device the plan picks is set up here, its kernels built too:
     * the build is counted apart (run_print_phases). */
    double t = run_now(), built = ss_ctx_counters(job->run.ctx).build_seconds;
    ss_plan_request req = {.weather = job->weather};
    ss_sweep_params_request(&common->sweep, &common->sun, &req);
    req.kind = kind;
    req.svf_definition = job->svf_definition;
    req.radius_m = job->radius_m;
    req.shadow_mode = shadow_mode;
    req.n_steps = n_steps;
    req.step_unix_s = step_unix_s;
    ss_status st = ss_plan_make(job->run.ctx, &job->dem.grid, &place, &req, &job->plan);
    if (st == SS_OK)
        st = ss_ctx_apply_plan(job->run.ctx, &job->plan);
    if (st != SS_OK)
        return job_finish(job, st);
    /* Obey the plan: what it leaves off is not computed. */
    const ss_plan *p = &job->plan;
    ss_plan_sweep_options(p, &place, common->sweep.refraction_k, &job->opt);
    size_t len = ss_plan_format(p, common->plan_json, NULL, 0) + 1;
    char *text = malloc(len);
    if (!text)
        return job_finish(job, ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory"));
    ss_plan_format(p, common->plan_json, text, len);
    job->run.phases.plan_s +=
        run_now() - t - (ss_ctx_counters(job->run.ctx).build_seconds - built);
    if (common->plan_only) {
        fputs(text, stdout);
        free(text);
        return 0;
    }
    if (!job->run.quiet)
        printf("plan\n%s", text);
    free(text);
    return -1;
}

void job_plan_metadata(sweep_job *job, ss_raster_writer *w)
{
    size_t len = ss_plan_format(&job->plan, 1, NULL, 0) + 1;
    char *json = malloc(len);
    if (!json)
        return;
    ss_plan_format(&job->plan, 1, json, len);
    ss_writer_metadata(w, "PLAN", json);
    free(json);
}
