/* Runs the effects planner for a command and makes the job obey it. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "run.h"

int job_plan(sweep_job *job, const common_settings *common, const ss_product_info *product,
             const void *params, int n_steps, const double *step_unix_s)
{
    ss_place place = run_place(common, &job->frame);
    if (!job->frame.georeferenced) {
        double w = job->dem.grid.width * job->dem.grid.cell_x_m;
        double h = job->dem.grid.height * job->dem.grid.cell_y_m;
        place.diagonal_m = sqrt(w * w + h * h);
    }
    /* The device the plan picks is set up here, its kernels built too:
     * the build is counted apart (run_print_phases). */
    double t = run_now(), built = ss_ctx_counters(job->run.ctx).build_seconds;
    ss_product_job with = {&common->sweep, &common->sun, &place, n_steps, step_unix_s,
                           job->weather};
    memory_mark before = job_memory_mark();
    ss_status st = ss_product_prepare(job->run.ctx, product, params, &job->dem.grid, &with,
                                      &job->opt, &job->plan);
    if (st == SS_OK)
        st = job_memory_replan(job, before);
    if (st != SS_OK)
        return job_finish(job, st);
    const ss_plan *p = &job->plan;
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
