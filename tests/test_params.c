/* The parameter table (skysweep_params.h): every parameter well formed (a
 * name, a type, choices for a choice, a default that its own checks
 * accept), offsets inside their structs, and the calls that turn the
 * parameters into the products' options. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "skysweep_params.h"
#include "tap.h"

static const struct {
    const char *name;
    size_t size;
} tables[] = {{"sweep", sizeof(ss_sweep_params)},         {"sun", sizeof(ss_sun_params)},
              {"svf", sizeof(ss_svf_params)},             {"openness", sizeof(ss_openness_params)},
              {"hillshade", sizeof(ss_hillshade_params)}, {"insolation", sizeof(ss_insolation_params)}};

/* Whether word is one of the '|'-separated choices. */
static int among(const char *choices, const char *word)
{
    size_t n = strlen(word);
    for (const char *p = choices; p; p = strchr(p, '|') ? strchr(p, '|') + 1 : NULL)
        if (strncmp(p, word, n) == 0 && (p[n] == '|' || p[n] == '\0'))
            return 1;
    return 0;
}

static void well_formed(void)
{
    for (size_t t = 0; t < sizeof tables / sizeof tables[0]; ++t) {
        const ss_param_table *table = ss_param_table_named(tables[t].name);
        int n = 0, bad = 0;
        char why[200] = "";
        for (const ss_param *p = table ? table->params : NULL; p && p->name; ++p, ++n) {
            size_t width = p->type == SS_PARAM_DOUBLE ? sizeof(double)
                           : p->type == SS_PARAM_TEXT ? sizeof(char *)
                                                      : sizeof(int);
            const char *fault =
                !p->name[0] || !p->help || !p->help[0]           ? "no name or help"
                : (unsigned)p->type > SS_PARAM_FLAG              ? "no type"
                : p->offset + width > tables[t].size             ? "an offset outside its struct"
                : p->type == SS_PARAM_CHOICE && !p->choices      ? "a choice without choices"
                : p->type == SS_PARAM_CHOICE && (!p->default_text || !among(p->choices, p->default_text))
                    ? "a default that is not a choice"
                : (p->type == SS_PARAM_DOUBLE || p->type == SS_PARAM_INT) && p->default_text &&
                        !(atof(p->default_text) >= p->min && atof(p->default_text) <= p->max)
                    ? "a default outside its range"
                : (p->type == SS_PARAM_DOUBLE || p->type == SS_PARAM_INT) && !(p->min <= p->max)
                    ? "an empty range"
                    : NULL;
            if (fault && !bad++)
                snprintf(why, sizeof why, ": '%s' has %s", p->name, fault);
        }
        tap_ok(table && n > 0 && !bad, "table '%s': %d parameters well formed%s", tables[t].name, n,
               why);
    }
    tap_ok(!ss_param_table_named("nonsense") && !ss_param_table_named(NULL),
           "an unknown table is NULL");
}

static void choices(void)
{
    char word[32];
    tap_ok(!strcmp(ss_param_choice("svf", "definition", 1, word, sizeof word), "radiative") &&
               !strcmp(ss_param_choice("insolation", "shadow", 3, word, sizeof word),
                       "cumulative") &&
               !strcmp(ss_param_choice("svf", "definition", 7, word, sizeof word), "") &&
               !strcmp(ss_param_choice("svf", "nonsense", 0, word, sizeof word), ""),
           "choice words by index, '' beyond them");
    ss_svf_params svf = {1, 0};
    ss_openness_params open = {1, 0};
    tap_ok(ss_svf_params_term(&svf) == SS_SKY_SVF_RADIATIVE &&
               ss_openness_params_term(&open) == SS_SKY_OPENNESS_NEGATIVE,
           "svf's radiative is the tilted term, openness' negative its inverted term");
    ss_hillshade_params hs = {.azimuth_deg = 300, .alg = 1, .blend = 1, .blend_radius_cells = 10};
    ss_hillshade_options ho;
    ss_hillshade_params_options(&hs, 2.5, &ho);
    tap_ok(ho.zevenbergen_thorne && ho.vat && fabs(ho.radius_m - 25.0) < 1e-12 &&
               ho.azimuth_deg == 300,
           "hillshade: Zevenbergen-Thorne, VAT, a blend radius of 10 cells of 2.5 m is %g m",
           ho.radius_m);
    ss_hillshade_params plain = {.azimuth_deg = 315}, cast = {.cast_shadows = 1},
                        sky = {.sky_view = 0.3};
    tap_ok(ss_hillshade_params_plan_kind(&plain) == SS_PLAN_NO_SWEEP &&
               ss_hillshade_params_plan_kind(&cast) == SS_PLAN_SHADOW &&
               ss_hillshade_params_plan_kind(&sky) == SS_PLAN_SKY_VIEW &&
               ss_hillshade_params_plan_kind(&hs) == SS_PLAN_SKY_VIEW,
           "hillshade asks the planner for no sweep, the light's sweep, or the sky's sweep");
}

/* ss_hillshade_check: what the table's ranges cannot say (the VAT blend
 * alone), and the ranges again for callers that fill the options. */
static void hillshade_check(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_hillshade_options vat = {.azimuth_deg = 315, .altitude_deg = 35, .z_factor = 1, .vat = 1};
    ss_hillshade_options plain = {.azimuth_deg = 315, .altitude_deg = 45, .z_factor = 1,
                                  .cast_shadows = 1, .sky_view = 0.5, .multidirectional = 1};
    tap_ok(ss_hillshade_check(ctx, &vat) == SS_OK && ss_hillshade_check(ctx, &plain) == SS_OK,
           "the VAT blend alone, and plain shading with every layer, pass");
    const char *layer[] = {"cast_shadows", "sky_view", "multidirectional"};
    for (int i = 0; i < 3; ++i) {
        ss_hillshade_options both = vat;
        both.cast_shadows = i == 0;
        both.sky_view = i == 1 ? 0.5 : 0.0;
        both.multidirectional = i == 2;
        ss_status st = ss_hillshade_check(ctx, &both);
        tap_ok(st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), "--blend vat"),
               "the VAT blend with %s is refused: %s", layer[i], ss_ctx_message(ctx));
    }
    ss_hillshade_options high = plain;
    high.altitude_deg = 91;
    tap_ok(ss_hillshade_check(ctx, &high) == SS_ERR_ARGUMENT, "an altitude of 91 degrees is refused");
    unsigned char crossed[1] = {1};
    ss_hillshade_options trees = plain, no_cast = plain, opaque = plain;
    trees.crowns_crossed = crossed, trees.transmissivity = 0.03;
    no_cast = trees, no_cast.cast_shadows = 0;
    opaque = trees, opaque.transmissivity = 1.5;
    tap_ok(ss_hillshade_check(ctx, &trees) == SS_OK &&
               ss_hillshade_check(ctx, &no_cast) == SS_ERR_ARGUMENT &&
               strstr(ss_ctx_message(ctx), "--cast-shadows") &&
               ss_hillshade_check(ctx, &opaque) == SS_ERR_ARGUMENT,
           "crowns pass with cast shadows and a transmissivity in 0..1, else are refused: %s",
           ss_ctx_message(ctx));
    tap_ok(ss_hillshade_check(ctx, &plain) == SS_OK && ss_ctx_message(ctx)[0] == '\0',
           "a check that passes leaves no message behind");
    ss_ctx_free(ctx);
}

/* The sun given one way: an instant, or an azimuth with an elevation. */
static void sun(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_sun_params p;
    double when;
    struct {
        const char *time;
        double az, el;
        const char *says; /* NULL: accepted */
    } cases[] = {{"2026-06-21T12:00Z", NAN, NAN, NULL},
                 {NULL, 120, 30, NULL},
                 {"2026-06-21T12:00Z", 120, 30, "not both"},
                 {NULL, 120, NAN, "go together"},
                 {NULL, NAN, 30, "go together"},
                 {NULL, NAN, NAN, "no sun"},
                 {"midday", NAN, NAN, "time 'midday'"}};
    int right = 0, n = (int)(sizeof cases / sizeof cases[0]);
    for (int i = 0; i < n; ++i) {
        ss_sun_params_init(&p);
        p.time = cases[i].time;
        p.sun_azimuth_deg = cases[i].az;
        p.sun_elevation_deg = cases[i].el;
        ss_status st = ss_sun_params_check(ctx, &p, &when);
        int ok = cases[i].says ? st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), cases[i].says)
                 : cases[i].time ? st == SS_OK && when == 1782043200.0
                                 : st == SS_OK && isnan(when);
        right += ok;
        if (!ok)
            tap_diag("case %d: status %d, '%s'", i, st, ss_ctx_message(ctx));
    }
    tap_ok(right == n, "the sun's options: %d of %d cases accepted or refused as they should be",
           right, n);
    ss_ctx_free(ctx);
}

static void insolation(void)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_insolation_params p = {.linke = "2,2.5,3,3.5,4,4.5,5,4.5,4,3.5,3,2.5",
                              .albedo = 0.3,
                              .shadow = 2,
                              .sky_model = 1,
                              .surface = "35,170",
                              .pv = 1,
                              .losses_percent = 14,
                              .inverter_efficiency_percent = 96,
                              .dc_ac_ratio = 1.2};
    ss_insolation_options io;
    double linke[12];
    ss_status st = ss_insolation_params_options(ctx, &p, ss_insolation_params_shadow(&p), &io);
    tap_ok(st == SS_OK && io.shadow_mode == SS_SHADOW_INTERPOLATED &&
               io.sky_model == SS_SKY_MODEL_HAYDAVIES && io.surface.kind == SS_SURFACE_FIXED &&
               io.surface.tilt_deg == 35 && io.surface.azimuth_deg == 170 &&
               fabs(io.pv.losses - 0.14) < 1e-12 && fabs(io.pv.inverter_efficiency - 0.96) < 1e-12,
           "insolation's options: interpolated, Hay-Davies, a module 35 deg facing 170, losses "
           "and efficiency as fractions");
    st = ss_insolation_params_linke(ctx, &p, linke);
    tap_ok(st == SS_OK && linke[0] == 2 && linke[6] == 5 && linke[11] == 2.5,
           "twelve Linke turbidities, one per month");
    const char *surfaces[] = {"95,10", "30", "abc", "30,400"};
    int refused = 0;
    for (int i = 0; i < 4; ++i) {
        p.surface = surfaces[i];
        refused += ss_insolation_params_options(ctx, &p, SS_SHADOW_EXACT, &io) == SS_ERR_ARGUMENT;
    }
    p.linke = "3,4";
    st = ss_insolation_params_linke(ctx, &p, linke);
    tap_ok(refused == 4 && st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), "twelve"),
           "bad surfaces (4 of 4) and two turbidities are refused: %s", ss_ctx_message(ctx));
    p.linke = "3";
    st = ss_insolation_params_linke(ctx, &p, linke);
    tap_ok(st == SS_OK && ss_ctx_message(ctx)[0] == '\0',
           "the next call that succeeds leaves no message behind");
    ss_ctx_free(ctx);
}

/* Box lines not given (0): the provisional options take the default 32,
 * and memory is sized for the most a plan can take, never fewer than it
 * chooses (32 for horizons; more where a tight --svf-tolerance asks the
 * sky view for more); a count given is taken as it is. */
static void box_lines(void)
{
    ss_sweep_params p;
    memset(&p, 0, sizeof p);
    p.lines = SS_LINES_BOX + 1;
    p.svf_tolerance = 0.01;
    ss_sweep_options opt;
    ss_sweep_params_options(&p, NULL, &opt);
    int at_default = ss_sweep_params_box_lines_most(&p);
    p.svf_tolerance = 1e-6;
    int tight = ss_sweep_params_box_lines_most(&p);
    tap_ok(opt.box_lines == SS_BOX_LINES_DEFAULT && at_default == SS_BOX_LINES_DEFAULT &&
               tight == SS_BOX_LINES_MAX,
           "box lines not given: %d in the provisional options, memory sized for %d at an SVF "
           "tolerance of 0.01 and %d at 1e-6",
           opt.box_lines, at_default, tight);
    p.box_lines = 4;
    ss_sweep_params_options(&p, NULL, &opt);
    tap_ok(opt.box_lines == 4 && ss_sweep_params_box_lines_most(&p) == 4,
           "box lines given: %d in the options and the memory sizing", opt.box_lines);
}

int main(void)
{
    well_formed();
    box_lines();
    choices();
    hillshade_check();
    sun();
    insolation();
    return tap_done();
}
