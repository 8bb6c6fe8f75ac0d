/* Insolation against an independent integration of the clear-sky model
 * (ESRA as restated in reference/physics.md sec. 4.3, written out again
 * here in double precision), and its conservation and limit properties:
 * - a flat open plane gets exactly the horizontal beam + diffuse summed at
 *   the same instants, and at 30-minute steps the day's total is within
 *   0.5 % of a 1-minute integration;
 * - a steep north-facing slope in northern winter gets no beam;
 * - the per-step bands add up to the total;
 * - the two shadow modes converge to each other as directions grow;
 * - weather records without light that shadows could change skip their
 *   shadow sweeps and change no output. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "skysweep_sun.h"
#include "ss_sky_diffuse.h"
#include "tap.h"
#include "testlib.h"

typedef struct {
    double lat, lon, start, step_s, linke;
    int n;
} sun_setup;

static ss_status sun_at(ss_ctx *ctx, int k, ss_sun_step *step, void *user)
{
    const sun_setup *su = user;
    ss_spa_params p;
    ss_spa_params_default(&p);
    p.delta_t_s = 69;
    ss_spa_result r;
    ss_status st = ss_spa(ctx, su->start + (k + 0.5) * su->step_s, su->lat, su->lon, &p, &r);
    memset(step, 0, sizeof *step);
    step->duration_h = su->step_s / 3600.0;
    step->linke = su->linke;
    step->extraterrestrial_w_m2 = 1367.0 / (r.earth_sun_distance_au * r.earth_sun_distance_au);
    step->azimuth_deg = step->grid_azimuth_deg = r.azimuth_deg;
    step->elevation_deg = r.elevation_deg;
    step->apparent_elevation_deg = r.apparent_elevation_deg;
    return st;
}

/* Global irradiance on a horizontal surface, W/m^2 (physics.md 4.3). */
static double esra_horizontal(double g0, double linke, double h0_rad, double z_m)
{
    if (h0_rad <= 0)
        return 0;
    double dh = 0.061359 * (0.1594 + 1.123 * h0_rad + 0.065656 * h0_rad * h0_rad) /
                (1 + 28.9344 * h0_rad + 277.3971 * h0_rad * h0_rad);
    double href = h0_rad + dh;
    double m = exp(-z_m / 8434.5) / (sin(href) + 0.50572 * pow(href * 180 / M_PI + 6.07995, -1.6364));
    double dr = m <= 20 ? 1 / (6.6296 + 1.7513 * m - 0.1202 * m * m + 0.0065 * m * m * m -
                               0.00013 * m * m * m * m)
                        : 1 / (10.4 + 0.718 * m);
    double beam = g0 * sin(h0_rad) * exp(-0.8662 * linke * m * dr);
    double tn = -0.015843 + 0.030543 * linke + 0.0003797 * linke * linke;
    double a1 = 0.26463 - 0.061581 * linke + 0.0031408 * linke * linke;
    if (a1 * tn < 0.0022)
        a1 = 0.0022 / tn;
    double a2 = 2.04020 + 0.018945 * linke - 0.011161 * linke * linke;
    double a3 = -1.3025 + 0.039231 * linke + 0.0085079 * linke * linke;
    double s = sin(h0_rad);
    return beam + g0 * tn * (a1 + a2 * s + a3 * s * s);
}

static double integrate_day(const sun_setup *su, double z_m)
{
    ss_ctx *ctx = ss_ctx_new();
    double total = 0;
    for (int k = 0; k < su->n; ++k) {
        ss_sun_step st;
        sun_at(ctx, k, &st, (void *)su);
        total += esra_horizontal(st.extraterrestrial_w_m2, su->linke,
                                 st.elevation_deg * M_PI / 180, z_m) *
                 st.duration_h;
    }
    ss_ctx_free(ctx);
    return total;
}

typedef struct {
    double sum;
    size_t cell;
} band_sum;

static int add_band(int index, const float *global, void *user)
{
    (void)index;
    band_sum *b = user;
    b->sum += global[b->cell];
    return 1;
}

static ss_status run(ss_grid *g, sun_setup *su, int directions, ss_shadow_mode mode,
                     ss_insolation_out *out, ss_step_sink sink, void *sink_user, char *err)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = directions;
    ss_insolation_options io = {.albedo = 0.2, .shadow_mode = mode};
    ss_status st = ss_insolation(ctx, g, &opt, &io, su->n, sun_at, su, sink, sink_user, out);
    if (st != SS_OK)
        snprintf(err, 300, "%s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st;
}

static ss_insolation_out alloc_out(size_t n)
{
    ss_insolation_out o = {0};
    o.global = malloc(n * sizeof(float));
    o.beam = malloc(n * sizeof(float));
    o.diffuse = malloc(n * sizeof(float));
    o.reflected = malloc(n * sizeof(float));
    o.sun_hours = malloc(n * sizeof(float));
    return o;
}

static void free_out(ss_insolation_out *o)
{
    free(o->global);
    free(o->beam);
    free(o->diffuse);
    free(o->reflected);
    free(o->sun_hours);
}

static void flat_plane(void)
{
    ss_grid g = test_grid(30, 30, 30, 30);
    const double z = 1200.0;
    for (int k = 0; k < 900; ++k)
        g.z[k] = 0.0f;
    g.z_origin_m = z;
    /* Kilauea, 21 June (UTC-10): 00:00 local is 10:00 UTC. */
    double start = 1782000000.0 + 10 * 3600.0;
    sun_setup fine = {19.4, -155.3, start, 60, 3.0, 1440};
    sun_setup coarse = {19.4, -155.3, start, 1800, 3.0, 48};
    double want_same = integrate_day(&coarse, z), want_fine = integrate_day(&fine, z);
    ss_insolation_out o = alloc_out(900);
    char err[300] = "";
    band_sum bands = {0, 15 * 30 + 15};
    ss_status st = run(&g, &coarse, 16, SS_SHADOW_EXACT, &o, add_band, &bands, err);
    size_t c = 15 * 30 + 15;
    tap_ok(st == SS_OK && fabs(o.global[c] - want_same) <= 1e-4 * want_same &&
               o.reflected[c] == 0.0f,
           "flat open plane at 1200 m, 21 June, Kilauea: global %.2f Wh/m2 == the ESRA "
           "horizontal sum at the same 48 instants %.2f (reflected %.3f) %s",
           st == SS_OK ? o.global[c] : NAN, want_same, st == SS_OK ? o.reflected[c] : NAN, err);
    tap_ok(st == SS_OK && fabs(o.global[c] - want_fine) <= 5e-3 * want_fine,
           "... and within 0.5 %% of a 1-minute integration of the day (%.2f Wh/m2)", want_fine);
    tap_ok(st == SS_OK && fabs(bands.sum - o.global[c]) <= 1e-5 * o.global[c],
           "per-step bands sum to the total (%.3f vs %.3f Wh/m2)", bands.sum,
           st == SS_OK ? o.global[c] : NAN);
    int nan = 0;
    for (int k = 0; st == SS_OK && k < 900; ++k)
        nan += !isfinite(o.global[k]) || !isfinite(o.sun_hours[k]);
    /* Hours of sun count whole 30-minute steps whose middle is sunlit: within
     * one step of the day's length from SPA's sunrise and sunset (which take
     * the sun's upper limb, so they are a few minutes longer). */
    ss_ctx *ctx = ss_ctx_new();
    ss_spa_params p;
    ss_spa_params_default(&p);
    ss_sun_day day;
    ss_sun_rise_set(ctx, start, 19.4, -155.3, &p, &day);
    double day_h = (day.sunset_unix_s - day.sunrise_unix_s) / 3600.0;
    ss_ctx_free(ctx);
    tap_ok(st == SS_OK && nan == 0 && fabs(o.sun_hours[c] - day_h) <= 0.5,
           "no NaN anywhere; %.2f hours of sun at the summer solstice at 19.4 N, day length %.2f h",
           st == SS_OK ? o.sun_hours[c] : NAN, day_h);
    free_out(&o);
    ss_grid_free(&g);
}

/* A 60-degree slope facing north at 45 N on 21 December: the sun never
 * climbs above 21.6 degrees, so it never shines on the slope. */
static void north_slope_winter(void)
{
    const int n = 40;
    ss_grid g = test_grid(n, n, 10, 10);
    double t = tan(60 * M_PI / 180);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            g.z[(size_t)r * n + c] = (float)(t * r * 10); /* rises southward: faces north */
    sun_setup su = {45.0, 10.0, 1797811200.0 - 3600.0 * 0, 1800, 3.0, 48}; /* 2026-12-21 */
    ss_insolation_out o = alloc_out((size_t)n * n);
    char err[300] = "";
    ss_status st = run(&g, &su, 16, SS_SHADOW_EXACT, &o, NULL, NULL, err);
    double beam = 0, diffuse = 0;
    for (int r = 5; st == SS_OK && r < n - 5; ++r)
        for (int c = 5; c < n - 5; ++c) {
            beam = fmax(beam, o.beam[(size_t)r * n + c]);
            diffuse += o.diffuse[(size_t)r * n + c];
        }
    tap_ok(st == SS_OK && beam == 0.0 && diffuse > 0,
           "60-degree north-facing slope at 45 N on 21 December: no beam (max %.3f Wh/m2), "
           "some diffuse %s",
           beam, err);
    free_out(&o);
    ss_grid_free(&g);
}

/* On rough terrain with tall relief, interpolated shadows approach the
 * exact ones as the stored directions grow. */
static void shadow_modes_converge(void)
{
    ss_grid g = test_grid(80, 80, 30, 30);
    test_fill(&g, TERRAIN_SMOOTH, 5, 400);
    sun_setup su = {46.8, 10.9, 1782000000.0 + 4 * 3600.0, 3600, 3.0, 16};
    size_t n = 80 * 80;
    ss_insolation_out exact = alloc_out(n);
    char err[300] = "";
    ss_status st = run(&g, &su, 16, SS_SHADOW_EXACT, &exact, NULL, NULL, err);
    double prev = INFINITY;
    int shrinking = st == SS_OK;
    char trail[200] = "";
    for (int d = 8; d <= 128 && shrinking; d *= 4) {
        ss_insolation_out interp = alloc_out(n);
        /* Same sky view (16 directions) in both runs: only shadows differ. */
        st = run(&g, &su, d, SS_SHADOW_INTERPOLATED, &interp, NULL, NULL, err);
        ss_insolation_out exact_d = alloc_out(n);
        if (st == SS_OK)
            st = run(&g, &su, d, SS_SHADOW_EXACT, &exact_d, NULL, NULL, err);
        double diff = 0;
        for (size_t c = 0; st == SS_OK && c < n; ++c)
            diff += fabs(interp.beam[c] - exact_d.beam[c]) / n;
        size_t len = strlen(trail);
        snprintf(trail + len, sizeof trail - len, " D=%d: %.2f", d, diff);
        shrinking = st == SS_OK && diff < prev;
        prev = diff;
        free_out(&interp);
        free_out(&exact_d);
    }
    tap_ok(shrinking && prev < 20,
           "interpolated shadows converge to exact ones (mean |beam difference| Wh/m2:%s) %s",
           trail, err);
    free_out(&exact);
    ss_grid_free(&g);
}

/* A weather record over sun_at's clear-sky sun: GHI = DHI = 150 W/m^2
 * and the given DNI. */
typedef struct {
    sun_setup su;
    double dni;
} record_setup;

static ss_status record_at(ss_ctx *ctx, int k, ss_sun_step *step, void *user)
{
    const record_setup *r = user;
    ss_status st = sun_at(ctx, k, step, (void *)&r->su);
    step->real_sky = 1;
    step->ghi_w_m2 = step->dhi_w_m2 = 150.0;
    step->dni_w_m2 = r->dni;
    step->albedo = NAN;
    step->temp_air_c = step->wind_speed_m_s = NAN;
    step->month = 6;
    return st;
}

/* Records without beam (and Hay-Davies' circumsolar part, which follows
 * it) need no shadow sweep: their outputs are those of records whose beam
 * is too faint to add anything but which are swept (1e-30 W/m^2: every
 * sum but the beam's is the same to the bit, the beam's is below 1e-28).
 * Perez's circumsolar part does not follow the beam: the same records
 * under Perez's sky are swept wherever it has one. */
static void unshaded_records(void)
{
    ss_grid g = test_grid(60, 60, 30, 30);
    test_fill(&g, TERRAIN_SMOOTH, 7, 600);
    size_t n = 60 * 60;
    ss_insolation_out out[3] = {alloc_out(n), alloc_out(n), alloc_out(n)};
    ss_counters c[3];
    ss_status st = SS_OK;
    sun_setup su = {46.8, 10.9, 1782000000.0 + 4 * 3600.0, 3600, 3.0, 14};
    for (int i = 0; i < 3 && st == SS_OK; ++i) {
        record_setup r = {su, i == 1 ? 1e-30 : 0};
        ss_ctx *ctx = ss_ctx_new();
        ss_sweep_options opt;
        ss_sweep_options_default(&opt);
        opt.directions = 16;
        ss_insolation_options io = {.albedo = 0.2, .shadow_mode = SS_SHADOW_EXACT,
                                    .sky_model = i < 2 ? SS_SKY_MODEL_HAYDAVIES
                                                       : SS_SKY_MODEL_PEREZ};
        st = ss_insolation(ctx, &g, &opt, &io, r.su.n, record_at, &r, NULL, NULL, &out[i]);
        c[i] = ss_ctx_counters(ctx);
        ss_ctx_free(ctx);
    }
    /* Perez's circumsolar part of each record, at each step's sun. */
    int perez_unshaded = 0;
    ss_ctx *ctx = ss_ctx_new();
    for (int k = 0; k < su.n; ++k) {
        ss_sun_step s;
        sun_at(ctx, k, &s, &su);
        float z = (float)((90.0 - s.elevation_deg) * M_PI / 180.0);
        perez_unshaded += s.elevation_deg > 0 &&
                          !(ss_sky_parts_of(SS_SKY_PEREZ, 150.0f, 0.0f,
                                            (float)s.extraterrestrial_w_m2, z)
                                .circumsolar > 0.0f);
    }
    ss_ctx_free(ctx);
    tap_ok(st == SS_OK && (int)c[2].shadow_sweeps_unshaded == perez_unshaded &&
               perez_unshaded < (int)c[0].shadow_sweeps_unshaded,
           "under Perez's sky the same records skip %llu sweeps, those without circumsolar "
           "light (%d), against Hay-Davies' %llu",
           (unsigned long long)c[2].shadow_sweeps_unshaded, perez_unshaded,
           (unsigned long long)c[0].shadow_sweeps_unshaded);
    int same = 1;
    double beam = 0;
    for (size_t k = 0; st == SS_OK && k < n; ++k) {
        same &= out[0].global[k] == out[1].global[k] && out[0].diffuse[k] == out[1].diffuse[k] &&
                out[0].reflected[k] == out[1].reflected[k] &&
                out[0].sun_hours[k] == out[1].sun_hours[k] && out[0].beam[k] == 0.0f;
        beam = fmax(beam, out[1].beam[k]);
    }
    tap_ok(st == SS_OK && same && beam < 1e-28 && c[0].shadow_sweeps_unshaded > 0 &&
               c[1].shadow_sweeps_unshaded == 0 && c[0].sweeps < c[1].sweeps,
           "records without beam skip their %llu shadow sweeps (%llu sweeps against %llu) and "
           "give the swept outputs (%s; beam %.1e)",
           (unsigned long long)c[0].shadow_sweeps_unshaded, (unsigned long long)c[0].sweeps,
           (unsigned long long)c[1].sweeps, same ? "the same" : "they differ", beam);
    for (int i = 0; i < 3; ++i)
        free_out(&out[i]);
    ss_grid_free(&g);
}

int main(void)
{
    flat_plane();
    north_slope_winter();
    shadow_modes_converge();
    unshaded_records();
    return tap_done();
}
