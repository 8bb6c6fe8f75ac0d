/* The effects planner: for each effect a scene where it must be on and one
 * where it must be off, with the reason quoting the scene's numbers; for
 * the off decisions, the effect forced on changes the result by no more
 * than the bound the plan states (every cell); and the work planned away is
 * not done (the library's counters). */
#include "config.h"

#include <math.h>
#include <string.h>

#include "accuracy_table.h"
#include "box_lines_table.h"
#include "box_march.h"
#include "shadow_table.h"
#include "skysweep_products.h"
#include "tap.h"
#include "testlib.h"

static const ss_plan_item *item(const ss_plan *p, const char *key)
{
    for (int i = 0; i < p->n_items; ++i)
        if (strcmp(p->items[i].key, key) == 0)
            return &p->items[i];
    return NULL;
}

static ss_plan_request request(ss_plan_kind kind)
{
    ss_plan_request r;
    memset(&r, 0, sizeof r);
    r.kind = kind;
    r.horizon_tolerance_deg = 0.05;
    r.svf_tolerance = 0.01;
    r.sun_tolerance_deg = 0.001;
    r.curvature = r.true_north = r.sun_per_cell = SS_AUTO;
    r.refraction_k = 0.13;
    return r;
}

static ss_place place_of(const ss_grid *g, double grid_north_deg, double lat)
{
    double w = g->width * g->cell_x_m, h = g->height * g->cell_y_m;
    ss_place p = {1, 0, 10.0, lat, grid_north_deg, grid_north_deg - 0.01, grid_north_deg + 0.01,
                  1e-6, sqrt(w * w + h * h), 6371000.0};
    return p;
}

static float *horizon(const ss_grid *g, double az, double radius)
{
    float *h = malloc(sizeof(float) * (size_t)g->width * g->height);
    char err[300];
    if (test_lib_horizon(NULL, g, az, radius, radius > 0 ? 0.13 : 0, SS_LINES_INTERPOLATED, h,
                         NULL, err, sizeof err) != SS_OK) {
        free(h);
        return NULL;
    }
    return h;
}

/* Curvature: off on a 234 m urban block (and the bound holds), on for a
 * 10 km spike seen from 50 km at a 0.01 degree tolerance. */
static void curvature(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_grid city = test_grid(234, 223, 1, 1);
    test_fill(&city, TERRAIN_PLATEAUS, 3, 40); /* blocks of buildings, sheer walls */
    ss_plan_request r = request(SS_PLAN_HORIZONS);
    ss_place pl = place_of(&city, 0.0, 57.7);
    ss_plan p;
    ss_status st = ss_plan_make(ctx, &city, &pl, &r, &p);
    const ss_plan_item *it = item(&p, "curvature");
    tap_ok(st == SS_OK && it && !it->on && strstr(it->reason, "0.323 km"),
           "curvature OFF on a 234 m x 223 m urban DSM: %s", it ? it->reason : ss_ctx_message(ctx));
    double worst = 0;
    for (double az = 10; az < 360 && it; az += 70) {
        float *flat_earth = horizon(&city, az, 0), *curved = horizon(&city, az, 6371000.0);
        for (size_t c = 0; flat_earth && curved && c < 234u * 223u; ++c)
            if (flat_earth[c] > -89)
                worst = fmax(worst, fabs(flat_earth[c] - curved[c]));
        free(flat_earth);
        free(curved);
    }
    tap_ok(it && worst <= it->bound, "... and forcing it on moves no horizon by more than the "
                                     "stated %.3g deg (worst %.3g deg, 6 azimuths, every cell)",
           it ? it->bound : NAN, worst);

    ss_grid plain = test_grid(600, 20, 100, 100);
    for (size_t c = 0; c < 600u * 20u; ++c)
        plain.z[c] = 0.0f;
    plain.z[10 * 600 + 5] = 10000.0f; /* a 10 km spike 50+ km from the far end */
    r.horizon_tolerance_deg = 0.01;
    pl = place_of(&plain, 0.0, 20.0);
    st = ss_plan_make(ctx, &plain, &pl, &r, &p);
    it = item(&p, "curvature");
    tap_ok(st == SS_OK && it && it->on && strstr(it->reason, "above the 0.01 deg"),
           "curvature ON for a 10 km spike seen across 60 km at 0.01 deg: %s",
           it ? it->reason : ss_ctx_message(ctx));
    float *flat_earth = horizon(&plain, 270, 0), *curved = horizon(&plain, 270, 6371000.0);
    size_t far = 10 * 600 + 595;
    tap_ok(flat_earth && curved && flat_earth[far] - curved[far] > 0.01,
           "... where leaving it off would raise the far horizon by %.3f deg",
           flat_earth && curved ? flat_earth[far] - curved[far] : NAN);
    free(flat_earth);
    free(curved);
    ss_grid_free(&city);
    ss_grid_free(&plain);
    ss_ctx_free(ctx);
}

/* True north: off on a UTM central meridian, on near a zone's edge. */
static void north(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_grid g = test_grid(100, 100, 30, 30);
    test_fill(&g, TERRAIN_SMOOTH, 4, 100);
    ss_plan_request r = request(SS_PLAN_SKY_VIEW);
    ss_plan p;
    ss_place centre = place_of(&g, 0.0012, 45.0), edge = place_of(&g, 2.1166, 45.0);
    ss_plan_make(ctx, &g, &centre, &r, &p);
    const ss_plan_item *it = item(&p, "true_north");
    tap_ok(it && !it->on && strstr(it->reason, "0.0012"),
           "true north OFF on the central meridian: %s", it ? it->reason : "");
    ss_plan_make(ctx, &g, &edge, &r, &p);
    it = item(&p, "true_north");
    tap_ok(it && it->on && p.true_north && strstr(it->reason, "2.1166"),
           "true north ON 3 degrees of longitude from the central meridian at 45 N: %s",
           it ? it->reason : "");
    ss_grid_free(&g);
    ss_ctx_free(ctx);
}

/* One sun for a city block, one per cell for a 300 km region. */
static void sun_per_cell(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_grid small = test_grid(234, 223, 1, 1), large = test_grid(300, 300, 1000, 1000);
    ss_plan_request r = request(SS_PLAN_SHADOW);
    r.sun_tolerance_deg = 0.01;
    ss_plan p;
    ss_place ps = place_of(&small, 0, 57.7), pl = place_of(&large, 0, 46);
    ss_plan_make(ctx, &small, &ps, &r, &p);
    const ss_plan_item *it = item(&p, "sun_per_cell");
    tap_ok(it && !it->on && it->bound < 0.01, "one sun for a 234 m block: %s",
           it ? it->reason : "");
    ss_plan_make(ctx, &large, &pl, &r, &p);
    it = item(&p, "sun_per_cell");
    tap_ok(it && it->on, "the sun per cell across 424 km: %s", it ? it->reason : "");
    ss_grid_free(&small);
    ss_grid_free(&large);
    ss_ctx_free(ctx);
}

typedef struct {
    double start;
} day_sun;

/* A sun crossing the sky from east to west over one day, low at the ends:
 * elevation 60 sin(pi t / 12) - 10 for t hours after start. */
static ss_status sun_at(ss_ctx *ctx, int k, ss_sun_step *step, void *user)
{
    (void)ctx;
    (void)user;
    double t = k + 0.5;
    memset(step, 0, sizeof *step);
    step->duration_h = 1;
    step->linke = 3;
    step->extraterrestrial_w_m2 = 1361;
    step->azimuth_deg = step->grid_azimuth_deg = 90 + 7.5 * t;
    step->elevation_deg = step->apparent_elevation_deg = 60 * sin(M_PI * t / 12) - 10;
    return SS_OK;
}

/* Work planned away is not done: the counters after an insolation run
 * equal the plan's counts of night steps and skipped shadow sweeps, and the
 * sweeps run equal the plan's estimate. */
static void skipped_work(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_grid g = test_grid(60, 60, 30, 30);
    test_fill(&g, TERRAIN_SMOOTH, 8, 20); /* gentle: the horizon bound is low */
    double bound = ss_horizon_bound_deg(&g, SS_LINES_INTERPOLATED, 0);
    int night = 0, high = 0;
    for (int k = 0; k < 24; ++k) {
        ss_sun_step s;
        sun_at(NULL, k, &s, NULL);
        night += s.elevation_deg <= 0;
        high += s.elevation_deg > 0 && s.apparent_elevation_deg > bound;
    }
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 8;
    ss_insolation_options io = {
        .albedo = 0.2, .shadow_mode = SS_SHADOW_EXACT};
    size_t n = 3600;
    ss_insolation_out out = {.global = malloc(n * 4),
                             .beam = malloc(n * 4),
                             .diffuse = malloc(n * 4),
                             .reflected = malloc(n * 4),
                             .sun_hours = malloc(n * 4)};
    ss_status st = ss_insolation(ctx, &g, &opt, &io, 24, sun_at, NULL, NULL, NULL, &out);
    ss_counters c = ss_ctx_counters(ctx);
    int sweeps_expected = 8 + (24 - night - high);
    tap_ok(st == SS_OK && (int)c.night_steps_skipped == night &&
               (int)c.shadow_sweeps_skipped == high && (int)c.sweeps == sweeps_expected &&
               night > 0 && high > 0,
           "night steps skipped %llu (want %d), shadow sweeps skipped %llu (want %d, sun above the "
           "%.1f deg bound), sweeps run %llu (want %d: 8 for the sky view + one per shaded step)",
           (unsigned long long)c.night_steps_skipped, night,
           (unsigned long long)c.shadow_sweeps_skipped, high, bound,
           (unsigned long long)c.sweeps, sweeps_expected);
    free(out.global);
    free(out.beam);
    free(out.diffuse);
    free(out.reflected);
    free(out.sun_hours);
    ss_grid_free(&g);
    ss_ctx_free(ctx);
}

/* The planner counts the same night steps from SPA at the DEM's centre. */
static void plan_counts(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_grid g = test_grid(60, 60, 30, 30);
    test_fill(&g, TERRAIN_SMOOTH, 8, 20);
    double instants[48];
    for (int k = 0; k < 48; ++k)
        instants[k] = 1782000000.0 + 10 * 3600 + (k + 0.5) * 1800; /* 21 June, Kilauea's day */
    ss_plan_request r = request(SS_PLAN_INSOLATION);
    r.n_steps = 48;
    r.step_unix_s = instants;
    ss_place pl = place_of(&g, 0, 19.4);
    pl.centre_lon_deg = -155.3;
    ss_plan p;
    ss_status st = ss_plan_make(ctx, &g, &pl, &r, &p);
    const ss_plan_item *it = item(&p, "night_steps");
    tap_ok(st == SS_OK && it && p.steps_night == 22 && strstr(it->reason, "22 of 48"),
           "planner: 22 of 48 half-hour steps of 21 June at Kilauea are night: %s",
           it ? it->reason : ss_ctx_message(ctx));
    ss_grid_free(&g);
    ss_ctx_free(ctx);
}

/* Directions: the fewest the accuracy table says meet --svf-tolerance, per
 * SVF definition (a looser tolerance never asks for more), the radiative
 * table for insolation's sky, 32 for digital lines (not tabulated), and a
 * request obeyed as given. */
static void directions(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_grid g = test_grid(64, 64, 30, 30);
    test_fill(&g, TERRAIN_SMOOTH, 4, 300);
    ss_place place = place_of(&g, 0, 45);
    for (int def = SS_SVF_DEF_GEOMETRIC; def <= SS_SVF_DEF_RADIATIVE; ++def) {
        int previous = 1 << 30, monotone = 1, agree = 1;
        for (double tol = 0.002; tol <= 0.05; tol *= 2) {
            ss_plan_request r = request(SS_PLAN_SKY_VIEW);
            r.svf_definition = (ss_svf_definition)def;
            r.svf_tolerance = tol;
            ss_plan p;
            double expected;
            int want = ss_directions_for_tolerance((ss_svf_definition)def, tol, &expected);
            agree &= ss_plan_make(ctx, &g, &place, &r, &p) == SS_OK && p.directions == want &&
                     item(&p, "directions") && item(&p, "directions")->bound == expected;
            monotone &= p.directions <= previous;
            previous = p.directions;
        }
        tap_ok(agree && monotone,
               "SVF definition %d: directions follow the accuracy table for tolerances 0.002 to "
               "0.05, never more for a looser one",
               def);
    }
    ss_plan_request r = request(SS_PLAN_INSOLATION);
    r.svf_definition = SS_SVF_DEF_GEOMETRIC; /* insolation's sky is radiative all the same */
    ss_plan p;
    int want = ss_directions_for_tolerance(SS_SVF_DEF_RADIATIVE, r.svf_tolerance, NULL);
    ss_status st = ss_plan_make(ctx, &g, &place, &r, &p);
    tap_ok(st == SS_OK && p.directions == want,
           "insolation: %d directions from the radiative SVF's table (want %d)", p.directions,
           want);
    r = request(SS_PLAN_SKY_VIEW);
    r.lines = SS_LINES_DIGITAL;
    st = ss_plan_make(ctx, &g, &place, &r, &p);
    tap_ok(st == SS_OK && p.directions == 32,
           "digital lines: the untabulated default of 32 directions (%d)", p.directions);
    r = request(SS_PLAN_SKY_VIEW);
    r.directions = 7;
    st = ss_plan_make(ctx, &g, &place, &r, &p);
    tap_ok(st == SS_OK && p.directions == 7 && strstr(item(&p, "directions")->reason, "as requested"),
           "7 directions requested: 7 planned (%s)", item(&p, "directions")->reason);
    ss_grid_free(&g);
    ss_ctx_free(ctx);
}

/* --device auto: a job too small for any device to pay its set-up runs the
 * C twin without looking for OpenCL; a large one weighs the devices found
 * (on a machine with OpenCL CPUs only, the C twin still wins: the model
 * gives PoCL no more speed, and 0.1 s to start). The context stays "auto"
 * after a plan is applied; a named device gets no "device" item. */
static void device_auto(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "auto");
    ss_grid g;
    ss_grid_alloc(ctx, &g, 64, 64, 10, 10);
    for (int i = 0; i < 64 * 64; ++i)
        g.z[i] = (float)(i % 7);
    ss_place pl = place_of(&g, 0, 45);
    ss_plan_request r = request(SS_PLAN_SKY_VIEW);
    r.directions = 16;
    ss_plan p;
    ss_status st = ss_plan_make(ctx, &g, &pl, &r, &p);
    const ss_plan_item *it = item(&p, "device");
    tap_ok(st == SS_OK && it && strcmp(p.device, "reference") == 0 &&
               strstr(it->reason, "none was looked for"),
           "a small job plans the C twin without looking for OpenCL (%s: %s)", p.device,
           it ? it->reason : "no device item");
    ss_ctx_apply_plan(ctx, &p);
    ss_grid big;
    ss_grid_alloc(ctx, &big, 1024, 1024, 10, 10);
    for (int i = 0; i < 1024 * 1024; ++i)
        big.z[i] = (float)(i % 7);
    ss_place big_place = place_of(&big, 0, 45);
    r.directions = 64;
    st = ss_plan_make(ctx, &big, &big_place, &r, &p);
    it = item(&p, "device");
    int devices = ss_list_devices(ctx, NULL, 0);
    tap_ok(st == SS_OK && it && !strstr(it->reason, "none was looked for") &&
               (devices > 0 ? strstr(it->reason, "(0:0)") != NULL
                            : strstr(it->reason, "no OpenCL device") != NULL),
           "64 directions on 1024^2, where a GPU could win: after a plan was applied the "
           "context is still auto, and the plan weighs the %d OpenCL device(s) found (%s: %s)",
           devices, p.device, it ? it->reason : "no device item");
    ss_grid_free(&big);
    ss_ctx_use_device(ctx, "reference");
    st = ss_plan_make(ctx, &g, &pl, &r, &p);
    tap_ok(st == SS_OK && !item(&p, "device") && strcmp(p.device, "reference") == 0,
           "a named device gets no device item, and the estimate is for it (%s)", p.device);
    ss_grid_free(&g);
    ss_ctx_free(ctx);
}

/* Lines: box lines where neighbouring cells step like walls (a city of
 * columns on 1 m cells), interpolated on hills sloping up to 45 deg; as
 * requested when asked; an unknown model is refused. */
static void lines(void)
{
    ss_grid city = box_march_city(120), hills = test_grid(120, 120, 30, 30);
    for (int r = 0; r < 120; ++r) /* slopes up to 45 deg */
        for (int c = 0; c < 120; ++c)
            hills.z[r * 120 + c] =
                (float)(400 * sin(2 * M_PI * c * 30 / 2500) * cos(2 * M_PI * r * 30 / 2500));
    ss_ctx *ctx = ss_ctx_new();
    ss_plan_request r = request(SS_PLAN_SHADOW);
    r.lines = SS_LINES_AUTO;
    ss_plan p_city, p_hills, p_asked;
    ss_place pc = place_of(&city, 0, 57), ph = place_of(&hills, 0, 57);
    int ok = ss_plan_make(ctx, &city, &pc, &r, &p_city) == SS_OK &&
             ss_plan_make(ctx, &hills, &ph, &r, &p_hills) == SS_OK;
    const ss_plan_item *ic = ok ? item(&p_city, "lines") : NULL;
    const ss_plan_item *ih = ok ? item(&p_hills, "lines") : NULL;
    tap_ok(ic && ih && p_city.lines == SS_LINES_BOX && p_hills.lines == SS_LINES_INTERPOLATED &&
               strstr(ic->reason, "walls") && strstr(ih->reason, "terrain"),
           "lines auto: box lines on a city of columns (%s), interpolated on hills (%s)",
           ic ? ic->reason : "-", ih ? ih->reason : "-");
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    if (ok)
        ss_plan_sweep_options(&p_city, &pc, 0.13, &opt);
    tap_ok(opt.lines == SS_LINES_BOX, "the sweep options obey the plan's lines (%s)",
           ss_line_model_name(opt.lines));
    r.radius_m = 50;
    ok = ss_plan_make(ctx, &city, &pc, &r, &p_asked) == SS_OK;
    tap_ok(ok && p_asked.lines == SS_LINES_INTERPOLATED,
           "lines auto with a radius: interpolated lines, which radius walks take (%s)",
           ss_line_model_name(p_asked.lines));
    r.radius_m = 0;
    /* The same city on cells three times as long as wide: box lines would
     * refuse them, so auto keeps interpolated lines and says why. */
    city.cell_y_m = 3 * city.cell_x_m;
    ss_place pl = place_of(&city, 0, 57);
    ok = ss_plan_make(ctx, &city, &pl, &r, &p_asked) == SS_OK;
    const ss_plan_item *il = ok ? item(&p_asked, "lines") : NULL;
    tap_ok(il && p_asked.lines == SS_LINES_INTERPOLATED && strstr(il->reason, "twice as long"),
           "lines auto on walls of cells 1 x 3: interpolated lines (%s)", il ? il->reason : "-");
    city.cell_y_m = city.cell_x_m;
    r.lines = SS_LINES_DIGITAL;
    ok = ss_plan_make(ctx, &city, &pc, &r, &p_asked) == SS_OK;
    tap_ok(ok && p_asked.lines == SS_LINES_DIGITAL,
           "lines asked for are kept, walls or not (%s)", ss_line_model_name(p_asked.lines));
    r.lines = (ss_line_model)7;
    ss_status st = ss_plan_make(ctx, &city, &pc, &r, &p_asked);
    tap_ok(st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), "line model"),
           "an unknown line model is refused: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    ss_grid_free(&city);
    ss_grid_free(&hills);
}

/* The smallest tabulated box-line count whose SVF error meets `tolerance`
 * on every row of the table, a count's error the larger of its own and
 * the next larger count's (the largest count where none does). */
static int box_lines_allowed(double tolerance)
{
    for (int i = 0; i < SS_BOX_LINES_N_COUNTS; ++i) {
        int meets = 1;
        for (int r = 0; r < ss_box_lines_n_rows; ++r)
            for (int j = i; j <= i + 1 && j < SS_BOX_LINES_N_COUNTS; ++j)
                meets &= ss_box_lines_rows[r].p95[j] <= tolerance;
        if (meets)
            return ss_box_lines_counts[i];
    }
    return ss_box_lines_counts[SS_BOX_LINES_N_COUNTS - 1];
}

/* Box lines per cell: for an SVF on a city, the fewest the measured table
 * allows at --svf-tolerance (fewer than the former fixed 32 at the default
 * 0.01), more for a tighter tolerance; a count asked for is kept; horizon
 * angles, which no table measures by the count, keep 32. */
static void box_line_counts(void)
{
    ss_grid city = box_march_city(120);
    ss_place pc = place_of(&city, 0, 57);
    ss_ctx *ctx = ss_ctx_new();
    ss_plan_request r = request(SS_PLAN_SKY_VIEW);
    r.lines = SS_LINES_AUTO;
    r.sky_walk = 1; /* svf's, as its registry entry asks */
    ss_plan p;
    /* The default: the sky view by each cell's own ray takes no lines. */
    int ok = ss_plan_make(ctx, &city, &pc, &r, &p) == SS_OK;
    const ss_plan_item *it = ok ? item(&p, "lines") : NULL;
    tap_ok(it && p.lines == SS_LINES_BOX && it->bound == 0 &&
               strstr(it->reason, "none for the sky view and horizons: each cell's own ray"),
           "svf on a city, --box-sky march (the default): no box lines for the sky view, no "
           "error expected (%s) [%.3g]",
           it ? it->reason : "-", it ? it->bound : NAN);
    r.box_sky = SS_BOX_SKY_LINES;
    ok = ss_plan_make(ctx, &city, &pc, &r, &p) == SS_OK;
    it = ok ? item(&p, "lines") : NULL;
    int allowed = box_lines_allowed(0.01);
    tap_ok(it && p.lines == SS_LINES_BOX && p.box_lines == allowed && allowed < 32 &&
               strstr(it->reason, "fewest") && it->bound > 0 && it->bound <= 0.01,
           "svf on a city, --box-sky lines, at the default 0.01: %d box lines, the fewest the "
           "table allows (%d) "
           "(%s) [%.3g]",
           p.box_lines, allowed, it ? it->reason : "-", it ? it->bound : NAN);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    if (ok)
        ss_plan_sweep_options(&p, &pc, 0.13, &opt);
    tap_ok(opt.box_lines == p.box_lines, "the sweep options obey the plan's box lines (%d)",
           opt.box_lines);

    int loose = p.box_lines;
    r.svf_tolerance = 0.2 * (it ? it->bound : 0.01);
    ok = ss_plan_make(ctx, &city, &pc, &r, &p) == SS_OK;
    it = ok ? item(&p, "lines") : NULL;
    tap_ok(it && p.box_lines > loose && p.box_lines == box_lines_allowed(r.svf_tolerance) &&
               it->bound > 0,
           "a tighter SVF tolerance (%.3g) takes more box lines: %d (%s)", r.svf_tolerance,
           p.box_lines, it ? it->reason : "-");

    r.svf_tolerance = 0.01;
    r.lines = SS_LINES_BOX;
    r.box_lines = 2;
    ok = ss_plan_make(ctx, &city, &pc, &r, &p) == SS_OK;
    it = ok ? item(&p, "lines") : NULL;
    tap_ok(it && p.box_lines == 2 && strstr(it->reason, "as requested"),
           "box lines asked for are kept: %d (%s)", p.box_lines, it ? it->reason : "-");

    r = request(SS_PLAN_HORIZONS);
    r.lines = SS_LINES_AUTO;
    ok = ss_plan_make(ctx, &city, &pc, &r, &p) == SS_OK;
    it = ok ? item(&p, "lines") : NULL;
    tap_ok(it && p.lines == SS_LINES_BOX && p.box_lines == 32 && strstr(it->reason, "no table"),
           "horizon angles keep 32 box lines (%s)", it ? it->reason : "-");
    /* Openness plans as horizons, yet its horizons are a sky walk: by each
     * cell's own ray it takes no box lines either (its registry entry says so). */
    double params[32] = {0}; /* the openness parameters' zeros: positive, no radius */
    r = request(SS_PLAN_HORIZONS);
    ss_product_named("openness")->request(params, 1.0, &r);
    r.lines = SS_LINES_AUTO;
    ok = r.sky_walk && ss_plan_make(ctx, &city, &pc, &r, &p) == SS_OK;
    it = ok ? item(&p, "lines") : NULL;
    tap_ok(it && p.lines == SS_LINES_BOX && strstr(it->reason, "none for the sky view"),
           "openness on a city: each cell's own ray, no box lines (%s)", it ? it->reason : "-");
    /* The horizon rasters are a horizon walk by each cell's own ray too. */
    r = request(SS_PLAN_HORIZONS);
    ss_product_named("horizon")->request(NULL, 1.0, &r);
    r.lines = SS_LINES_AUTO;
    ok = r.sky_walk && ss_plan_make(ctx, &city, &pc, &r, &p) == SS_OK;
    it = ok ? item(&p, "lines") : NULL;
    tap_ok(it && p.lines == SS_LINES_BOX && strstr(it->reason, "and horizons: each cell's own ray"),
           "horizon on a city: each cell's own ray, no box lines (%s)", it ? it->reason : "-");
    ss_ctx_free(ctx);
    ss_grid_free(&city);
}

/* A year of hourly weather records (instants only: the plan reads no
 * irradiance), for the shadow mode's choice. */
#define YEAR_HOURS 8760
static double year_hours[YEAR_HOURS];

static ss_plan_request weather_year(double tolerance_pct, int pv)
{
    for (int k = 0; k < YEAR_HOURS; ++k)
        year_hours[k] = 1767225600.0 + (k + 0.5) * 3600; /* 2026 */
    ss_plan_request r = request(SS_PLAN_INSOLATION);
    r.shadow_mode = SS_SHADOW_AUTO;
    r.lines = SS_LINES_AUTO;
    r.n_steps = YEAR_HOURS;
    r.step_unix_s = year_hours;
    r.weather = (ss_plan_weather){"a test year", 10.0, 1, 0, pv, tolerance_pct};
    return r;
}

/* The shadow table read as the planner reads it: where it covers a count,
 * it covers every larger one, and never expects more error from more
 * directions. */
static void shadow_table_monotone(void)
{
    int ok = 1, rows = 0;
    char where[120] = "";
    for (int scene = SS_SHADOW_SCENE_CITY; scene <= SS_SHADOW_SCENE_TERRAIN; ++scene)
        for (int mode = SS_SHADOW_INTERPOLATED; mode <= SS_SHADOW_CUMULATIVE; ++mode)
            for (int pv = 0; pv <= 1; ++pv) {
                double previous = NAN;
                for (int d = 1; d <= 1024; ++d) {
                    double e = ss_shadow_expected_error((ss_shadow_scene)scene,
                                                        (ss_shadow_mode)mode, d, pv);
                    int bad = isnan(e) ? !isnan(previous) && !(mode == SS_SHADOW_CUMULATIVE && pv)
                                       : e > previous || e < 0;
                    if (bad && ok)
                        snprintf(where, sizeof where, "scene %d mode %d pv %d at %d: %g after %g",
                                 scene, mode, pv, d, e, previous);
                    ok &= !bad;
                    rows += !isnan(e) && d == 256;
                    previous = isnan(e) ? previous : e;
                }
            }
    tap_ok(ok && rows > 0 && ss_shadow_mode_n_rows >= 4,
           "the shadow table's expected error never grows with the directions (%d rows) %s",
           ss_shadow_mode_n_rows, where);
    /* What the choice rests on, measured: on the city, interpolated shadows
     * err less at 128 directions than at 16. */
    double e16 = ss_shadow_expected_error(SS_SHADOW_SCENE_CITY, SS_SHADOW_INTERPOLATED, 16, 1);
    double e128 = ss_shadow_expected_error(SS_SHADOW_SCENE_CITY, SS_SHADOW_INTERPOLATED, 128, 1);
    tap_ok(e128 < e16, "city, PV: interpolated shadows %.3g %% at 16 directions, %.3g %% at 128",
           e16, e128);
}

/* Exact shadows of a year on box lines, modelled: each cell's own ray (the
 * default, box_shadow.h) costs about one sweep a record, the box lines'
 * own walks 1.8 per line per cell: the model, and so the choice of mode,
 * must tell them apart. */
static void box_shadow_costs(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    ss_grid city = box_march_city(120);
    ss_place place = place_of(&city, 0, 57.7);
    ss_plan march, lines;
    ss_plan_request r = weather_year(0.001, 1);
    r.sky_walk = 1;               /* insolation's, as its registry entry asks */
    r.box_sky = SS_BOX_SKY_LINES; /* below: the sky view on lines; at the end, by rays */
    ss_status st = ss_plan_make(ctx, &city, &place, &r, &march);
    double sky_lines_s = march.estimated_seconds;
    r.box_shadows = SS_BOX_SHADOWS_LINES;
    if (st == SS_OK)
        st = ss_plan_make(ctx, &city, &place, &r, &lines);
    tap_ok(st == SS_OK && march.lines == SS_LINES_BOX && march.sweeps == lines.sweeps &&
               march.estimated_seconds < lines.estimated_seconds / 10,
           "an exact PV year on a city: %d sweeps modelled at %.3g s by each cell's own ray, "
           "%.3g s by %d box lines' walks",
           march.sweeps, march.estimated_seconds, lines.estimated_seconds, lines.box_lines);
    /* Shadows by each cell's own ray leave the box lines to the sky view,
     * which takes its count from the SVF table; the lines' shadows keep 32. */
    int sky = ss_box_lines_for_tolerance(0.01, NULL);
    const ss_plan_item *it = item(&march, "lines");
    tap_ok(sky < SS_BOX_LINES_DEFAULT && march.sky_box_lines == sky &&
               march.box_lines == SS_BOX_LINES_DEFAULT && lines.sky_box_lines == 0 && it &&
               strstr(it->reason, "the sky view takes"),
           "... its sky view on %d box lines per cell (the table's %d), its shadows' lines %d; "
           "none of its own with the lines' shadows (%d): %s",
           march.sky_box_lines, sky, march.box_lines, lines.sky_box_lines,
           it ? it->reason : "no lines item");
    /* The march runs on the host whatever the device: an OpenCL device's
     * plan leaves the sky view the same lines (else its diffuse light
     * would differ from the C twin's by the two counts' SVF error). */
    ss_ctx *cl = ss_ctx_new();
    ss_ctx_use_device(cl, "Portable");
    ss_plan on_cl;
    r.box_shadows = SS_BOX_SHADOWS_MARCH;
    st = ss_plan_make(cl, &city, &place, &r, &on_cl);
    tap_ok(st == SS_OK && on_cl.sky_box_lines == sky && strcmp(on_cl.device, "opencl") == 0,
           "... on an OpenCL device (%s): its sky view on %d box lines per cell too",
           on_cl.device, on_cl.sky_box_lines);
    /* The march is modelled on the host whatever the device: --device
     * auto's modelled GPU (a set-up, a launch per sweep, its rate) does
     * not grow with the daylight steps marched. */
    ss_ctx *autoc = ss_ctx_new();
    ss_ctx_use_device(autoc, "auto");
    double gpu_s[2] = {NAN, NAN};
    const char *why = "";
    for (int half = 0; st == SS_OK && half < 2; ++half) {
        ss_plan a;
        r.n_steps = half ? YEAR_HOURS / 2 : YEAR_HOURS;
        st = ss_plan_make(autoc, &city, &place, &r, &a);
        const ss_plan_item *dev = st == SS_OK ? item(&a, "device") : NULL;
        const char *at = dev ? strstr(dev->reason, "and a GPU ") : NULL;
        if (!at || sscanf(at, "and a GPU %lf s", &gpu_s[half]) != 1)
            why = dev ? "no GPU time in the device's reason" : "no device item";
    }
    r.n_steps = YEAR_HOURS;
    tap_ok(st == SS_OK && !why[0] && gpu_s[0] == gpu_s[1],
           "... --device auto's modelled GPU: %.3g s for the year's sweeps, %.3g s for half of "
           "them (the march on the host either way)%s%s",
           gpu_s[0], gpu_s[1], why[0] ? ": " : "", why);
    ss_ctx_free(autoc);
    ss_ctx_free(cl);
    r.box_lines = 16;
    st = ss_plan_make(ctx, &city, &place, &r, &march);
    tap_ok(st == SS_OK && march.box_lines == 16 && march.sky_box_lines == 0,
           "... --box-lines 16 given: 16 for all, none of the sky view's own (%d)",
           march.sky_box_lines);
    /* --box-sky march (the default): the sky view and its horizons (Perez's
     * band) are each cell's own ray, modelled below the lines' cost; a
     * canopy's sky view keeps the table's count. */
    r.box_lines = 0;
    r.box_sky = SS_BOX_SKY_MARCH;
    ss_plan rays;
    st = ss_plan_make(ctx, &city, &place, &r, &rays);
    it = st == SS_OK ? item(&rays, "lines") : NULL;
    /* No output of a run without trees errs by the count: its error is
     * said, not bound. */
    tap_ok(it && rays.sky_box_lines == sky && rays.estimated_seconds < sky_lines_s &&
               strstr(it->reason, "the sky view, horizons and shadows are each cell's own ray") &&
               strstr(it->reason, "a canopy's sky view takes") && it->bound == 0,
           "... --box-sky march (the default): the sky view and Perez's band by each cell's own "
           "ray, modelled at %.3g s against %.3g s on their lines, a canopy's sky view on %d box "
           "lines, no error bound (%g): %s",
           rays.estimated_seconds, sky_lines_s, rays.sky_box_lines, it ? it->bound : NAN,
           it ? it->reason : "-");
    ss_grid_free(&city);
    ss_ctx_free(ctx);
}

/* --shadow auto: the cheapest mode whose tabulated error meets the
 * tolerance, PV included; exact shadows where none does, for per-step
 * bands, short runs and the clear sky; an explicit mode or count wins. */
static void shadow_modes(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_grid city = box_march_city(120);
    ss_place place = place_of(&city, 0, 57.7);
    ss_plan p;
    ss_plan_request r = weather_year(100, 1);
    ss_status st = ss_plan_make(ctx, &city, &place, &r, &p);
    const ss_plan_item *it = item(&p, "shadow_mode");
    double want = ss_shadow_expected_error(SS_SHADOW_SCENE_CITY, SS_SHADOW_INTERPOLATED,
                                           p.directions, 1);
    tap_ok(st == SS_OK && p.lines == SS_LINES_BOX && p.shadow_mode == SS_SHADOW_INTERPOLATED &&
               it && it->bound == want && it->bound <= 100 && strstr(it->reason, "PV yield") &&
               p.sweeps == 2 * p.directions,
           "a PV year on a city, 100 %% allowed: interpolated shadows, %d sweeps (%s) [%g %%]",
           p.sweeps, it ? it->reason : ss_ctx_message(ctx), it ? it->bound : NAN);
    int loose_sweeps = p.sweeps;
    r = weather_year(0.001, 1);
    st = ss_plan_make(ctx, &city, &place, &r, &p);
    it = item(&p, "shadow_mode");
    tap_ok(st == SS_OK && p.shadow_mode == SS_SHADOW_EXACT && it &&
               strstr(it->reason, "above the 0.001 % tolerance") && p.sweeps > loose_sweeps,
           "... 0.001 %% allowed: exact shadows, %d sweeps (%s)", p.sweeps, it ? it->reason : "-");
    /* A looser tolerance never costs more sweeps. */
    int previous = 1 << 30, monotone = 1;
    for (double tol = 0.01; tol <= 100; tol *= 1.5) {
        r = weather_year(tol, 1);
        monotone &= ss_plan_make(ctx, &city, &place, &r, &p) == SS_OK && p.sweeps <= previous &&
                    (p.shadow_mode == SS_SHADOW_EXACT || item(&p, "shadow_mode")->bound <= tol);
        previous = p.sweeps;
    }
    tap_ok(monotone, "tolerances 0.01 to 100 %%: the expected error within each, the sweeps "
                     "never more for a looser one");
    r = weather_year(100, 1);
    r.shadow_mode = SS_SHADOW_EXACT;
    st = ss_plan_make(ctx, &city, &place, &r, &p);
    it = item(&p, "shadow_mode");
    tap_ok(st == SS_OK && p.shadow_mode == SS_SHADOW_EXACT && it && strstr(it->reason, "requested"),
           "--shadow exact wins over a loose tolerance (%s)", it ? it->reason : "-");
    r = weather_year(100, 1);
    r.directions = 48;
    st = ss_plan_make(ctx, &city, &place, &r, &p);
    it = item(&p, "shadow_mode");
    want = ss_shadow_expected_error(SS_SHADOW_SCENE_CITY, SS_SHADOW_INTERPOLATED, 48, 1);
    tap_ok(st == SS_OK && p.directions == 48 && p.shadow_mode == SS_SHADOW_INTERPOLATED && it &&
               it->bound == want,
           "--directions 48 wins: interpolated at 48, the error read at the count below (%g %%)",
           want);
    r = weather_year(100, 1);
    r.weather.per_step = 1;
    st = ss_plan_make(ctx, &city, &place, &r, &p);
    it = item(&p, "shadow_mode");
    tap_ok(st == SS_OK && p.shadow_mode == SS_SHADOW_EXACT && it && strstr(it->reason, "per-step"),
           "per-step bands: exact shadows (%s)", it ? it->reason : "-");
    r = weather_year(100, 1);
    r.n_steps = 48;
    st = ss_plan_make(ctx, &city, &place, &r, &p);
    it = item(&p, "shadow_mode");
    tap_ok(st == SS_OK && p.shadow_mode == SS_SHADOW_EXACT && it && strstr(it->reason, "720"),
           "48 records: exact shadows, the table does not cover them (%s)", it ? it->reason : "-");
    /* Terrain, 64 directions asked for: without PV the cumulative sky (it
     * ties interpolated shadows in sweeps, and its per-cell work is per bin
     * of suns), with PV interpolated shadows (the cumulative sky gives no
     * PV yield). */
    ss_grid hills = test_grid(64, 64, 30, 30);
    test_fill(&hills, TERRAIN_SMOOTH, 4, 300);
    ss_place ph = place_of(&hills, 0, 45);
    ss_shadow_mode chosen[2];
    for (int pv = 0; pv <= 1; ++pv) {
        r = weather_year(100, pv);
        r.directions = 64;
        st = ss_plan_make(ctx, &hills, &ph, &r, &p);
        chosen[pv] = st == SS_OK && p.lines == SS_LINES_INTERPOLATED && p.directions == 64
                         ? p.shadow_mode
                         : SS_SHADOW_AUTO;
    }
    it = item(&p, "shadow_mode");
    tap_ok(chosen[0] == SS_SHADOW_CUMULATIVE && chosen[1] == SS_SHADOW_INTERPOLATED,
           "a year on terrain at 64 directions: the cumulative sky without PV, interpolated "
           "shadows with it (%s)",
           it ? it->reason : ss_ctx_message(ctx));
    r = weather_year(100, 0);
    r.weather.what = NULL;
    st = ss_plan_make(ctx, &hills, &ph, &r, &p);
    it = item(&p, "shadow_mode");
    tap_ok(st == SS_OK && p.shadow_mode == SS_SHADOW_EXACT && it && strstr(it->reason, "clear sky"),
           "the clear sky: exact shadows (%s)", it ? it->reason : "-");
    ss_grid_free(&hills);
    ss_grid_free(&city);
    ss_ctx_free(ctx);
}

int main(void)
{
    shadow_table_monotone();
    shadow_modes();
    box_shadow_costs();
    lines();
    box_line_counts();
    device_auto();
    directions();
    curvature();
    north();
    sun_per_cell();
    skipped_work();
    plan_counts();
    return tap_done();
}
