/* The product registry (skysweep_products.h): every entry well formed (a
 * name, summary, title, group and description; parameter tables that
 * exist; outputs with a unit and their bands, OUTPUT first, every other
 * output optional and named by its option), found by index and by name,
 * asking the planner for its own product at the parameters' defaults, and
 * running through its run call (every built-in product has one; shadow and
 * insolation with one sun): every row of its first output delivered;
 * and prepared (ss_product_prepare) into options that obey their plan;
 * products registered at run time (ss_product_register) found, bad ones refused.
 * `test_registry --list` prints each product's name and outputs, one
 * product a line, for tests/test_registry.sh (the front ends' faces). */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "skysweep_products.h"
#include "tap.h"

static void list(void)
{
    for (int i = 0; i < ss_product_count(); ++i) {
        const ss_product_info *p = ss_product_at(i);
        printf("%s", p->name);
        for (const ss_product_output *o = p->outputs; o->name; ++o)
            printf(" %s", o->name);
        printf("\n");
    }
}

/* What is wrong with output o (index k) of a product, or NULL. */
static const char *output_fault(const ss_product_output *o, int k)
{
    int names = 1;
    for (const char *c = o->band_names ? o->band_names : ""; *c; ++c)
        names += *c == '|';
    return !o->unit || !o->band_names || !o->band_names[0] ? "no unit or band names"
           : o->bands < 0                                  ? "a negative band count"
           : o->bands > 0 && names != o->bands             ? "band names not one per band"
           : k == 0 && (o->option || o->optional)          ? "an OUTPUT that is optional"
           : k > 0 && (!o->option || !o->optional)         ? "an optional output with no option"
                                                           : NULL;
}

static const char *product_fault(const ss_product_info *p)
{
    if (!p->name || !p->summary || !p->title || !p->description || !p->name[0] || !p->summary[0] ||
        !p->title[0] || !p->description[0])
        return "no name, summary, title or description";
    if (!p->group || (strcmp(p->group, "Terrain") != 0 && strcmp(p->group, "Sun") != 0))
        return "a group that is neither Terrain nor Sun";
    if (p->own_table ? !ss_param_table_named(p->own_table) || !p->params_size : p->params_size != 0)
        return "an own table that does not exist, or a struct size without one";
    for (const char *const *t = p->tables; *t; ++t)
        if (!ss_param_table_named(*t))
            return "a shared table that does not exist";
    if (!p->outputs || !p->outputs[0].name)
        return "no outputs";
    if (!p->request || !p->cell_bytes || !p->halo_m)
        return "no request, cell cost or halo";
    return NULL;
}

static void well_formed(void)
{
    tap_ok(ss_product_count() >= 6, "the registry holds %d products", ss_product_count());
    for (int i = 0; i < ss_product_count(); ++i) {
        const ss_product_info *p = ss_product_at(i);
        const char *fault = product_fault(p);
        char why[160] = "";
        int k = 0;
        for (const ss_product_output *o = p->outputs; !fault && o->name; ++o, ++k)
            if ((fault = output_fault(o, k)))
                snprintf(why, sizeof why, " (output '%s')", o->name);
        tap_ok(!fault, "%s: well formed, %d outputs%s%s%s", p->name, k, fault ? ": " : "",
               fault ? fault : "", why);
    }
}

static void found(void)
{
    int bad = 0;
    for (int i = 0; i < ss_product_count(); ++i) {
        const ss_product_info *p = ss_product_at(i);
        bad += ss_product_named(p->name) != p;
        for (int j = 0; j < i; ++j)
            bad += strcmp(ss_product_at(j)->name, p->name) == 0;
    }
    tap_ok(!bad && !ss_product_at(-1) && !ss_product_at(ss_product_count()) &&
               !ss_product_named("nothing") && !ss_product_named(NULL),
           "each product found by index and by name, once; none past the ends");
}

/* At the parameters' zeros (the defaults of what decides the planner's
 * product: no cast shadows, sky view or blend), each asks for its own. */
static void plans(void)
{
    for (int i = 0; i < ss_product_count(); ++i) {
        const ss_product_info *p = ss_product_at(i);
        double params[32] = {0}; /* room for any parameter struct, aligned */
        ss_plan_request req = {0};
        req.kind = (ss_plan_kind)-1;
        p->request(p->params_size ? params : NULL, 1.0, &req);
        tap_ok(p->params_size <= sizeof params && req.kind == p->plans_as,
               "%s: its request asks the planner for product %d (declared %d)", p->name,
               (int)req.kind, (int)p->plans_as);
    }
}

typedef struct {
    int rows[4]; /* per output, summed over bands */
} row_count;

static ss_status count_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)index, (void)row0, (void)values;
    row_count *c = user;
    if (output >= 0 && output < 4)
        c->rows[output] += n_rows;
    return SS_OK;
}

/* One sun for every row: south-east, 30 degrees up, a clear hour. */
static ss_status one_sun(ss_ctx *ctx, int index, int row0, int n_rows, ss_sun_step *step,
                         void *user)
{
    (void)ctx, (void)index, (void)row0, (void)n_rows, (void)user;
    *step = (ss_sun_step){.duration_h = 1, .linke = 3, .extraterrestrial_w_m2 = 1361,
                          .unix_s = 1.7e9, .azimuth_deg = 135, .grid_azimuth_deg = 135,
                          .elevation_deg = 30, .apparent_elevation_deg = 30};
    return SS_OK;
}

/* A small cone: every product has terrain to see, and runs through its
 * entry, a product of the "Sun" group with the sun of one step. */
static void runs(void)
{
    enum { W = 24, H = 20, DIRECTIONS = 8 };
    static float z[W * H];
    for (int r = 0; r < H; ++r)
        for (int c = 0; c < W; ++c)
            z[r * W + c] = (float)(100.0 - 3.0 * hypot(c - W / 2.0, r - H / 2.0));
    ss_source src = {.width = W, .height = H, .cell_x_m = 10, .cell_y_m = 10, .z = z};
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = DIRECTIONS;
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    for (int i = 0; i < ss_product_count(); ++i) {
        const ss_product_info *p = ss_product_at(i);
        if (!p->run) {
            tap_ok(0, "%s: no run call", p->name);
            continue;
        }
        double params[32] = {0};
        if (strcmp(p->name, "hillshade") == 0) { /* a light above the horizon, no exaggeration */
            ss_hillshade_params *light = (ss_hillshade_params *)params;
            light->altitude_deg = 45;
            light->z_factor = 1;
        }
        if (strcmp(p->name, "insolation") == 0) /* the cells' own slopes, some ground light */
            *(ss_insolation_params *)params =
                (ss_insolation_params){.albedo = 0.2, .surface = "cell"};
        ss_product_sun sun = {.n_steps = 1, .sun_rows = one_sun};
        row_count c = {{0}};
        ss_status st = p->run(ctx, &src, &opt, p->params_size ? params : NULL,
                              strcmp(p->group, "Sun") == 0 ? &sun : NULL, 0, NULL, count_rows, &c);
        int want = p->outputs[0].bands ? p->outputs[0].bands * H : DIRECTIONS * H;
        tap_ok(st == SS_OK && c.rows[0] == want && c.rows[1] == 0,
               "%s: its run delivers %d rows of OUTPUT (want %d), none of the optional outputs "
               "not asked for (status %d: %s)",
               p->name, c.rows[0], want, (int)st, ss_ctx_message(ctx));
    }
    /* Insolation's optional output 1, each step's global, asked for. */
    ss_insolation_params clear = {.albedo = 0.2, .surface = "cell"};
    ss_product_sun sun = {.n_steps = 1, .sun_rows = one_sun};
    row_count c = {{0}};
    ss_status st = ss_product_named("insolation")->run(ctx, &src, &opt, &clear, &sun, 2u, NULL,
                                                       count_rows, &c);
    tap_ok(st == SS_OK && c.rows[0] == 5 * H && c.rows[1] == H,
           "insolation: with its steps asked for, %d rows of OUTPUT's 5 bands and %d of the "
           "one step's (want %d and %d)",
           c.rows[0], c.rows[1], 5 * H, H);
    ss_ctx_free(ctx);
}

/* The one translation (ss_product_prepare) of each product's parameters
 * on a grid without a place: options that obey the plan it makes, the
 * directions and offset asked kept, grid azimuths, curvature as asked
 * where the product sweeps, and the plan's request from the registry
 * entry; an option out of range refused. */
static void prepared(void)
{
    enum { W = 24, H = 20 };
    static float z[W * H];
    for (int i = 0; i < W * H; ++i)
        z[i] = (float)(i % W);
    ss_grid grid = {W, H, 10, 10, 0, z};
    ss_sweep_params sweep = {.directions = 12, .offset_deg = 5, .curvature = SS_CHOICE_ON,
                             .refraction_k = 0.13, .north = SS_NORTH_AUTO,
                             .horizon_tolerance_deg = 0.05, .svf_tolerance = 0.01,
                             .sun_tolerance_deg = 0.1};
    double steps[1] = {1.7e9};
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    for (int i = 0; i < ss_product_count(); ++i) {
        const ss_product_info *p = ss_product_at(i);
        double params[32] = {0};
        int timed = p->plans_as == SS_PLAN_SHADOW || p->plans_as == SS_PLAN_INSOLATION;
        int sweeps = p->plans_as != SS_PLAN_NO_SWEEP; /* else no curvature to plan */
        ss_product_job job = {.sweep = &sweep, .n_steps = timed, .step_unix_s = steps};
        ss_sweep_options opt;
        ss_plan plan;
        ss_status st = ss_product_prepare(ctx, p, p->params_size ? params : NULL, &grid, &job,
                                          &opt, &plan);
        tap_ok(st == SS_OK && opt.directions == 12 && plan.directions == 12 &&
                   opt.offset_deg == 5 && opt.lines == plan.lines &&
                   opt.box_lines == plan.box_lines && opt.grid_north_deg == 0 &&
                   opt.earth_radius_m == (sweeps ? SS_EARTH_RADIUS_MEAN_M : 0) &&
                   opt.refraction_k == (sweeps ? 0.13 : 0),
               "%s: prepared, its options obey its plan (%d directions, offset %g, lines %d of "
               "%d, earth radius %g; status %d: %s)",
               p->name, opt.directions, opt.offset_deg, (int)opt.lines, (int)plan.lines,
               opt.earth_radius_m, (int)st, ss_ctx_message(ctx));
    }
    sweep.directions = 0;
    sweep.curvature = SS_CHOICE_OFF;
    ss_product_job job = {.sweep = &sweep};
    ss_sweep_options opt;
    ss_plan plan;
    ss_svf_params svf = {0};
    ss_status st = ss_product_prepare(ctx, ss_product_named("svf"), &svf, &grid, &job, &opt, &plan);
    tap_ok(st == SS_OK && plan.directions > 0 && opt.directions == plan.directions &&
               opt.earth_radius_m == 0 && opt.refraction_k == 0,
           "svf: the planner's %d directions, curvature off as asked (status %d)",
           opt.directions, (int)st);
    sweep.offset_deg = 400; /* out of range: the options' check refuses it */
    st = ss_product_prepare(ctx, ss_product_named("svf"), &svf, &grid, &job, &opt, &plan);
    tap_ok(st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), "--offset"),
           "an offset out of range is refused: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
}

/* Products added at run time: after the built-in ones, found by name;
 * a taken name, an incomplete entry and a ninth one refused. */
static void registered(void)
{
    int built_in = ss_product_count();
    static ss_product_info extra[9];
    static char names[9][16];
    ss_product_info taken = *ss_product_named("svf"), bare = taken;
    bare.name = "bare";
    bare.outputs = NULL;
    tap_ok(ss_product_register(&taken) == SS_ERR_ARGUMENT &&
               ss_product_register(&bare) == SS_ERR_ARGUMENT &&
               ss_product_register(NULL) == SS_ERR_ARGUMENT &&
               ss_product_count() == built_in,
           "a taken name, an entry without outputs and none are refused; the registry unchanged");
    int ok = 0;
    for (int i = 0; i < 9; ++i) {
        extra[i] = taken;
        snprintf(names[i], sizeof names[i], "extra%d", i);
        extra[i].name = names[i];
        ok += ss_product_register(&extra[i]) == (i < 8 ? SS_OK : SS_ERR_MEMORY);
    }
    tap_ok(ok == 9 && ss_product_count() == built_in + 8 &&
               ss_product_at(built_in) == &extra[0] && ss_product_named("extra7") == &extra[7] &&
               !ss_product_named("extra8"),
           "8 products registered after the %d built-in ones and found; a ninth refused (%d of 9 "
           "as expected)",
           built_in, ok);
}

int main(int argc, char **argv)
{
    if (argc == 2 && strcmp(argv[1], "--list") == 0) {
        list();
        return 0;
    }
    well_formed();
    found();
    plans();
    runs();
    prepared();
    registered(); /* last: the other checks walk the built-in products */
    return tap_done();
}
