/* The one translation of a product's parameters into a run
 * (skysweep_products.h, ss_product_prepare): the plan request, the plan,
 * the sweep options that obey it and the device it chose. The CLI's
 * commands (src/cli/job_plan.c) and the Python package call it. */
#include "config.h"

#include <math.h>
#include <stddef.h>

#include "skysweep_products.h"

/* A grid without a place (an array): the grid's diagonal, the sweep's
 * earth radius or the mean one, grid azimuths. */
static ss_place placeless(const ss_grid *grid, const ss_sweep_params *sweep)
{
    ss_place place = {0};
    place.diagonal_m = hypot(grid->width * grid->cell_x_m, grid->height * grid->cell_y_m);
    place.earth_radius_m = sweep->earth_radius_m > 0 ? sweep->earth_radius_m
                                                     : SS_EARTH_RADIUS_MEAN_M;
    return place;
}

ss_status ss_product_prepare(ss_ctx *ctx, const ss_product_info *product, const void *params,
                             const ss_grid *grid, const ss_product_job *job,
                             ss_sweep_options *opt, ss_plan *plan)
{
    ss_place own = placeless(grid, job->sweep);
    const ss_place *place = job->place ? job->place : &own;
    ss_plan_request req = {.weather = job->weather, .shadow_mode = SS_SHADOW_EXACT};
    ss_sweep_params_request(job->sweep, job->sun, &req);
    product->request(params, sqrt(grid->cell_x_m * grid->cell_y_m), &req);
    req.n_steps = job->n_steps;
    req.step_unix_s = job->step_unix_s;
    ss_status st = ss_plan_make(ctx, grid, place, &req, plan);
    if (st != SS_OK)
        return st;
    /* Obey the plan: what it leaves off is not computed. */
    ss_sweep_params_options(job->sweep, place, opt);
    ss_plan_sweep_options(plan, place, job->sweep->refraction_k, opt);
    st = ss_sweep_options_check(ctx, opt);
    return st == SS_OK ? ss_ctx_apply_plan(ctx, plan) : st;
}
