/* Trees in insolation's light (doc/vegetation.md, "insolation"), against
 * closed forms computed here:
 * - Perez's horizon band through crowns: an infinite hedge on flat ground
 *   beside a surface tilted toward it takes the share of the band the
 *   hedge hides x (1 - T) off the band's diffuse, the share integrated
 *   here over the azimuths (weighted by the cosine of incidence as the
 *   band is) and the band's radiance from Perez's coefficients written
 *   out again; leaf-off records by the leaf-off transmissivity, in exact
 *   steps and in the cumulative sky alike; a surface turned away from the
 *   hedge loses nothing.
 * - Beer-Lambert crowns: under a cylindrical crown each cell's beam and
 *   hours of sun are exp(-G LAD L) x the open cell's, L the path inside
 *   crowns found by brute force on the same digital lines (every cell
 *   against every crown cell ahead: tree_brute_paths), and the paths' sum
 *   within 5 % of the closed form of the cylinder's chords; the sky through
 *   crowns takes the mean of exp(-G LAD L) over the directions they hide,
 *   that mean matching a brute-force path march over the same lines (the
 *   sky's and Perez's band's) on hills with crowns; a huge leaf area
 *   density gives transmissivity 0's output byte for byte; a leaf-off step
 *   keeps the constant leaf-off transmissivity on the same cells. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lines.h"
#include "products_internal.h"
#include "ss_sun.h"
#include "tap.h"
#include "testlib.h"
#include "tree_scenes.h"

static double rad(double deg)
{
    return deg * M_PI / 180.0;
}

/* ---- the scene: a hedge along a column of flat ground ---------------------- */

enum { WIDTH = 81, HEIGHT = 801, HEDGE_COL = 40, ROW = HEIGHT / 2 };
#define BAND_DEG 6.5

/* Weather records: the sun at grid azimuth 150 (its rays from the cells
 * east of the hedge go away from it), elevation 40 (or the sun_pos given),
 * DNI 700 and DHI 100 W/m^2, an hour each. */
#define SUN_AZ 150.0
#define SUN_EL 40.0
#define DNI 700.0
#define DHI 100.0
#define EXTRA 1367.0

typedef struct {
    double azimuth_deg, elevation_deg;
} sun_pos;

static ss_status record_at(ss_ctx *ctx, int k, ss_sun_step *step, void *user)
{
    (void)ctx;
    const sun_pos *at = user;
    memset(step, 0, sizeof *step);
    step->duration_h = 1.0;
    step->linke = 3.0;
    step->extraterrestrial_w_m2 = EXTRA;
    step->unix_s = 1781956800.0 + 3600.0 * k; /* 2026-06-20T12:00Z */
    step->azimuth_deg = step->grid_azimuth_deg = at ? at->azimuth_deg : SUN_AZ;
    step->elevation_deg = step->apparent_elevation_deg = at ? at->elevation_deg : SUN_EL;
    step->real_sky = 1;
    step->dni_w_m2 = DNI;
    step->dhi_w_m2 = DHI;
    step->ghi_w_m2 = DHI + DNI * sin(rad(SUN_EL));
    step->albedo = NAN;
    step->temp_air_c = step->wind_speed_m_s = NAN;
    step->month = 6;
    return SS_OK;
}

/* Perez et al. (1990)'s horizon-band radiance DHI x F2 of the records
 * above, all-sites composite coefficients (table 6), the air mass Kasten
 * and Young's (1989). */
static double perez_band_radiance(void)
{
    static const double f2[8][3] = {{-0.060, 0.072, -0.022}, {-0.019, 0.066, -0.029},
                                    {0.055, -0.064, -0.026}, {0.109, -0.152, -0.014},
                                    {0.226, -0.462, 0.001},  {0.288, -0.823, 0.056},
                                    {0.264, -1.127, 0.131},  {0.156, -1.377, 0.251}};
    static const double upper[7] = {1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2};
    double z = rad(90.0 - SUN_EL), zd = 90.0 - SUN_EL;
    double air_mass = 1.0 / (cos(z) + 0.50572 * pow(96.07995 - zd, -1.6364));
    double kz3 = 1.041 * z * z * z;
    double eps = ((DHI + DNI) / DHI + kz3) / (1.0 + kz3);
    int bin = 0;
    while (bin < 7 && eps >= upper[bin])
        ++bin;
    double delta = DHI * air_mass / EXTRA;
    return DHI * (f2[bin][0] + f2[bin][1] * delta + f2[bin][2] * z);
}

/* The share of the band (0 to 6.5 degrees) a hedge of crowns from
 * `bottom` to `top` metres hides from a surface facing it squarely, d
 * metres across: the direction phi from the hedge's normal meets it at
 * d / cos phi, where the crown spans the elevations atan(bottom cos phi /
 * d) to atan(top cos phi / d); each direction weighs cos phi (its
 * incidence on the surface), the directions behind the surface none. */
static double hedge_band_share(double bottom, double top, double d)
{
    const int n = 20000;
    double sum = 0.0, weight = 0.0, band = rad(BAND_DEG);
    for (int k = 0; k < n; ++k) {
        double phi = -M_PI / 2 + (k + 0.5) * M_PI / n, c = cos(phi);
        double lo = fmax(atan(bottom * c / d), 0.0), hi = fmin(atan(top * c / d), band);
        sum += c * (hi > lo ? (hi - lo) / band : 0.0);
        weight += c;
    }
    return sum / weight;
}

typedef struct {
    float *global, *beam, *diffuse, *reflected, *hours;
} outputs;

static outputs outputs_new(size_t n)
{
    outputs o = {malloc(n * sizeof(float)), malloc(n * sizeof(float)), malloc(n * sizeof(float)),
                 malloc(n * sizeof(float)), malloc(n * sizeof(float))};
    return o;
}

static void outputs_free(outputs *o)
{
    free(o->global), free(o->beam), free(o->diffuse), free(o->reflected), free(o->hours);
}

/* One insolation run of n_steps records (the sun at `at`, or the hedge's)
 * over g: the options' trees where `trees` is given, the surface `surface`. */
static int run_with(const ss_grid *g, ss_insolation_trees *trees, ss_shadow_mode mode,
                    int n_steps, ss_surface surface, int directions, sun_pos *at, outputs *o)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = directions;
    ss_insolation_options io = {.albedo = 0.2,
                                .shadow_mode = mode,
                                .sky_model = SS_SKY_MODEL_PEREZ,
                                .elevation_step_deg = 1.0,
                                .surface = surface,
                                .trees = trees};
    ss_insolation_out out = {o->global, o->beam, o->diffuse, o->reflected, o->hours,
                             NULL,      NULL,    NULL};
    ss_status st = ss_insolation(ctx, g, &opt, &io, n_steps, record_at, at, NULL, NULL, &out);
    if (st != SS_OK)
        tap_diag("insolation: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st == SS_OK;
}

/* One run over the hedge scene: n_steps records, the surface tilted
 * `tilt` degrees toward azimuth `facing`, trees where cn is given (the
 * crowns' isotropic sky is left out: sky_hidden NULL, so that the band
 * alone changes the diffuse light). */
static int run(const ss_grid *g, const ss_canopy *cn, ss_trunk_gaps gaps,
               const unsigned char *leaf_off, double T_off, ss_shadow_mode mode, int n_steps,
               double tilt, double facing, outputs *o)
{
    ss_insolation_trees trees = {g, cn, NULL, T_off, leaf_off, 0, gaps, 0.0, 0.0};
    ss_surface surface = {SS_SURFACE_FIXED, tilt, facing};
    return run_with(g, cn ? &trees : NULL, mode, n_steps, surface, 180, NULL, o);
}

/* The hedge's band share the run's diffuse light gives at the cell d east
 * of the hedge: the diffuse lost over the band's radiance x (1 - T) x
 * sin(tilt), summed over the records by their T. */
static double band_share_got(const outputs *open, const outputs *trees, int d, double lost_wh,
                             double tilt)
{
    size_t c = (size_t)ROW * WIDTH + HEDGE_COL + d;
    return (open->diffuse[c] - trees->diffuse[c]) / (lost_wh * sin(rad(tilt)));
}

static void horizon_band(void)
{
    ss_grid g = test_grid(WIDTH, HEIGHT, 1, 1);
    size_t n = (size_t)WIDTH * HEIGHT;
    float *height = malloc(n * sizeof(float));
    const double top = 2.0, tilt = 60.0;
    tree_hedge(&g, height, HEDGE_COL, top);
    double band_wh = perez_band_radiance(); /* an hour of it */
    tap_diag("Perez's horizon band: %.4f W/m^2", band_wh);
    static const int ds[] = {10, 20, 30};
    outputs open = outputs_new(n), o = outputs_new(n);
    /* Crowns from the ground (trunk 0) and a crown from half its height
     * with the gaps under it open: the band's share closed form between
     * the hedge's centre line d and its face d - 1/2 (digital lines take
     * cells up to half a cell beside the ray; where the band clips the
     * crown the face's share may be the smaller), 0.002 spared for the
     * directions' sampling and the grid's end. */
    for (int k = 0; k < 2; ++k) {
        double ratio = k ? 0.5 : 0.0, T = 0.2;
        ss_trunk_gaps gaps = k ? SS_TRUNK_GAPS_OPEN : SS_TRUNK_GAPS_IGNORE;
        ss_canopy cn = {height, NULL, ratio, T};
        int ok = run(&g, NULL, gaps, NULL, 0.5, SS_SHADOW_EXACT, 1, tilt, 270.0, &open) &&
                 run(&g, &cn, gaps, NULL, 0.5, SS_SHADOW_EXACT, 1, tilt, 270.0, &o);
        int within = ok;
        for (size_t j = 0; ok && j < sizeof ds / sizeof *ds; ++j) {
            double got = band_share_got(&open, &o, ds[j], band_wh * (1.0 - T), tilt);
            double centre = hedge_band_share(ratio * top, top, ds[j]),
                   face = hedge_band_share(ratio * top, top, ds[j] - 0.5);
            within &= got >= fmin(centre, face) - 0.002 && got <= fmax(centre, face) + 0.002;
            tap_diag("trunk %.1f m, gaps %s, d = %d m: the band's diffuse gives a share %.5f, "
                     "closed form %.5f (centre line) to %.5f (face)",
                     ratio * top, k ? "open" : "ignore", ds[j], got, centre, face);
        }
        /* West of the hedge the surface faces away from it. */
        size_t west = (size_t)ROW * WIDTH + HEDGE_COL - 10;
        tap_ok(within && open.diffuse[west] == o.diffuse[west],
               "a hedge %.0f m tall, trunk %.1f m, --trunk-gaps %s, T %.1f: a surface tilted "
               "%.0f degrees toward it loses (1 - T) x the band's share it hides at 10, 20 and "
               "30 m, one facing away nothing",
               top, ratio * top, k ? "open" : "ignore", T, tilt);
    }
    /* Two records, the second leaf off: the band loses (1 - 0.2) of the
     * first's hidden share and (1 - 0.6) of the second's, in exact steps
     * and in the cumulative sky. */
    const unsigned char leaf_off[2] = {0, 1};
    ss_canopy cn = {height, NULL, 0.0, 0.2};
    double lost = band_wh * ((1.0 - 0.2) + (1.0 - 0.6)), want = hedge_band_share(0, top, 20);
    for (int m = 0; m < 2; ++m) {
        ss_shadow_mode mode = m ? SS_SHADOW_CUMULATIVE : SS_SHADOW_EXACT;
        int ok = run(&g, NULL, SS_TRUNK_GAPS_IGNORE, NULL, 0.6, mode, 2, tilt, 270.0, &open) &&
                 run(&g, &cn, SS_TRUNK_GAPS_IGNORE, leaf_off, 0.6, mode, 2, tilt, 270.0, &o);
        double got = ok ? band_share_got(&open, &o, 20, lost, tilt) : NAN;
        tap_ok(ok && fabs(got - want) < 0.004,
               "%s: a leaf-on and a leaf-off record (T 0.2, 0.6) take the band's share %.5f "
               "(closed form %.5f at 20 m) by their transmissivities",
               m ? "cumulative sky" : "exact steps", got, want);
    }
    outputs_free(&open);
    outputs_free(&o);
    free(height);
    ss_grid_free(&g);
}

/* ---- Beer-Lambert -------------------------------------------------------- */

/* The ray from (x, y) on flat ground toward the sun through a cylinder of
 * radius R about (cx, cy) from `bottom` to `top`: the length inside it. */
static double cylinder_path(double x, double y, double az, double el, double cx, double cy,
                            double R, double bottom, double top)
{
    double ux = sin(rad(az)), uy = cos(rad(az)); /* grid y grows northward */
    double dx = x - cx, dy = y - cy;
    double b = dx * ux + dy * uy, c = dx * dx + dy * dy - R * R, disc = b * b - c;
    if (disc <= 0.0)
        return 0.0;
    double s0 = fmax(-b - sqrt(disc), bottom / tan(rad(el)));
    double s1 = fmin(-b + sqrt(disc), top / tan(rad(el)));
    return s1 > s0 ? (s1 - s0) / cos(rad(el)) : 0.0;
}

static void beer_lambert(void)
{
    enum { W = 60, H = 60 };
    const size_t n = (size_t)W * H;
    const double R = 5.0, top = 10.0, ratio = 0.25, G = 0.5, LAD = 0.3;
    ss_grid g = test_grid(W, H, 1, 1);
    float *height = malloc(n * sizeof(float));
    tree_cylinder(&g, height, 30.0, 30.0, R, top);
    sun_pos at = {200.0, 35.0};
    ss_surface flat = {SS_SURFACE_CELL, 0.0, 0.0};
    ss_canopy cn = {height, NULL, ratio, 0.03};
    ss_insolation_trees bl = {&g, &cn, NULL, 0.5, NULL, 0, SS_TRUNK_GAPS_IGNORE, LAD, G};
    outputs open = outputs_new(n), o = outputs_new(n);
    double *path = malloc(n * sizeof(double));
    tree_brute_paths(&g, &cn, at.azimuth_deg, at.elevation_deg, path);
    int ok = run_with(&g, NULL, SS_SHADOW_EXACT, 1, flat, 16, &at, &open) &&
             run_with(&g, &bl, SS_SHADOW_EXACT, 1, flat, 16, &at, &o);
    size_t shaded = 0, wrong = 0;
    double worst = 0.0, sum_path = 0.0, sum_closed = 0.0;
    for (size_t i = 0; ok && i < n; ++i) {
        double f = exp(-G * LAD * path[i]);
        double beam = f * open.beam[i], hours = f * open.hours[i];
        double e = fmax(fabs(o.beam[i] - beam) / open.beam[i], fabs(o.hours[i] - hours));
        worst = fmax(worst, e);
        wrong += !(e <= 2e-6);
        shaded += path[i] > 0.0;
        sum_path += path[i];
        int r = (int)(i / W), c = (int)(i % W);
        /* Rows run north to south: the cell's centre, y northward. */
        sum_closed += cylinder_path(c + 0.5, H - r - 0.5, at.azimuth_deg, at.elevation_deg,
                                    30.0, H - 30.0, R, ratio * top, top);
    }
    tap_ok(ok && shaded > 50 && wrong == 0,
           "Beer-Lambert (G %.1f, LAD %.1f m2/m3), a cylindrical crown, sun 200/35: every cell's "
           "beam and hours of sun are exp(-G LAD L) x the open cell's, L by brute force on the "
           "digital lines (%zu cells with a path, %zu off, worst %.2g)",
           G, LAD, shaded, wrong, worst);
    tap_ok(ok && fabs(sum_path - sum_closed) <= 0.05 * sum_closed,
           "the paths' sum %.1f m, the cylinder's chords in closed form %.1f m (within 5 %%)",
           sum_path, sum_closed);
    /* The sky through crowns (the run's 16 directions, trunk gaps
     * ignored): where no path crosses the beam, the diffuse and reflected
     * light the crowns take are (1 - the cell's mean light through its
     * hidden sky) / (1 - T) x the constant model's. */
    float *V = malloc(n * sizeof(float)), *sky_T = malloc(n * sizeof(float));
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 16;
    ss_ctx *ctx = ss_ctx_new();
    ok = ok &&
         ss_canopy_sky(ctx, &g, &cn, &opt, SS_SVF_DEF_HORIZONTAL, SS_TRUNK_GAPS_IGNORE, NULL,
                       V) == SS_OK &&
         ss_canopy_sky_through(ctx, &g, &cn, &opt, SS_TRUNK_GAPS_IGNORE, G * LAD, sky_T) == SS_OK;
    ss_ctx_free(ctx);
    bl.sky_hidden = V;
    ss_insolation_trees constant = {&g, &cn, V, 0.5, NULL, 1, SS_TRUNK_GAPS_IGNORE, 0.0, 0.0};
    outputs k = outputs_new(n);
    ok = ok && run_with(&g, &bl, SS_SHADOW_EXACT, 1, flat, 16, &at, &o) &&
         run_with(&g, &constant, SS_SHADOW_EXACT, 1, flat, 16, &at, &k);
    size_t sky_cells = 0;
    wrong = 0;
    worst = 0.0;
    for (size_t i = 0; ok && i < n; ++i) {
        if (path[i] > 0.0 || !(V[i] > 0.05))
            continue;
        double ratio_want = (1.0 - sky_T[i]) / (1.0 - cn.transmissivity);
        double e = fmax(fabs((open.diffuse[i] - o.diffuse[i]) -
                             ratio_want * (open.diffuse[i] - k.diffuse[i])) /
                            (open.diffuse[i] - k.diffuse[i]),
                        fabs((o.reflected[i] - open.reflected[i]) -
                             ratio_want * (k.reflected[i] - open.reflected[i])) /
                            (k.reflected[i] - open.reflected[i]));
        worst = fmax(worst, e);
        wrong += !(e <= 1e-4);
        ++sky_cells;
    }
    tap_ok(ok && sky_cells > 50 && wrong == 0,
           "Beer-Lambert's sky: on %zu cells whose sky crowns hide (V > 0.05) and whose beam "
           "crosses none, the diffuse and reflected light the crowns take are (1 - the mean "
           "exp(-G LAD L) over the hidden sky) / (1 - T) x the constant model's (%zu off, "
           "worst relative %.2g)",
           sky_cells, wrong, worst);
    /* A huge leaf area density is transmissivity 0 byte for byte, the sky
     * through crowns and Perez's band on a tilted surface included, though
     * the canopy's constant is 0.5: Beer-Lambert's leaf-on steps do not
     * take it. */
    ss_canopy opaque = {height, NULL, ratio, 0.0}, half = {height, NULL, ratio, 0.5};
    ss_insolation_trees huge = {&g, &half, V, 0.5, NULL, 0, SS_TRUNK_GAPS_IGNORE, 20.0, 1.0};
    ss_insolation_trees zero = {&g, &opaque, V, 0.5, NULL, 1, SS_TRUNK_GAPS_IGNORE, 0.0, 0.0};
    outputs h = outputs_new(n);
    int same = ok;
    ss_surface tilted = {SS_SURFACE_FIXED, 60.0, 20.0};
    for (int s = 0; s < 2; ++s) {
        ss_surface surface = s ? tilted : flat;
        ok = ok && run_with(&g, &huge, SS_SHADOW_EXACT, 1, surface, 16, &at, &h) &&
             run_with(&g, &zero, SS_SHADOW_EXACT, 1, surface, 16, &at, &o);
        same &= ok && !memcmp(h.global, o.global, n * sizeof(float)) &&
                !memcmp(h.diffuse, o.diffuse, n * sizeof(float)) &&
                !memcmp(h.reflected, o.reflected, n * sizeof(float)) &&
                !memcmp(h.beam, o.beam, n * sizeof(float)) &&
                !memcmp(h.hours, o.hours, n * sizeof(float));
    }
    tap_ok(same,
           "Beer-Lambert with LAD 20 m2/m3 and G 1 gives transmissivity 0's global, beam, "
           "diffuse, reflected light and hours of sun byte for byte on digital lines, a "
           "horizontal and a tilted surface (the sky and horizon band through crowns included)");
    /* A leaf-off step: the constant leaf-off transmissivity on the cells
     * with a path. */
    const unsigned char off[1] = {1};
    bl.leaf_off = off;
    ok = ok && run_with(&g, &bl, SS_SHADOW_EXACT, 1, flat, 16, &at, &o);
    wrong = 0;
    for (size_t i = 0; ok && i < n; ++i)
        wrong += !(fabs(o.beam[i] - (path[i] > 0.0 ? 0.5 : 1.0) * open.beam[i]) <=
                   2e-6 * open.beam[i]);
    tap_ok(ok && wrong == 0,
           "Beer-Lambert, a leaf-off step: the leaf-off transmissivity 0.5 on every cell with a "
           "path, the open beam elsewhere (%zu cells off)",
           wrong);
    outputs_free(&open), outputs_free(&o), outputs_free(&h), outputs_free(&k);
    free(path), free(height), free(V), free(sky_T);
    ss_grid_free(&g);
}

/* ---- Beer-Lambert through the crowns' sky ------------------------------ */

/* Smooth hills 3 m high and round crowns of several sizes. */
static void crowned_hills(ss_grid *g, float *height)
{
    static const double crowns[][4] = {/* column, row, radius, top */
                                       {10, 12, 3.5, 11}, {30, 9, 2.5, 7},   {22, 26, 4.5, 13},
                                       {38, 34, 3.0, 9},  {9, 37, 2.0, 6},   {27, 40, 1.5, 8},
                                       {40, 18, 2.0, 12}, {16, 20, 1.0, 5}};
    int w = g->width, h = g->height;
    test_fill(g, TERRAIN_SMOOTH, 7, 3.0);
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) {
            float top = 0.0f;
            for (size_t k = 0; k < sizeof crowns / sizeof *crowns; ++k)
                if (hypot(c + 0.5 - crowns[k][0], r + 0.5 - crowns[k][1]) <= crowns[k][2])
                    top = (float)crowns[k][3];
            height[(size_t)r * w + c] = top;
        }
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The integral of exp(-x sec e) x f(e) over elevations (a, b): f is
 * sin 2e (the horizontal surface's sky) or 1 (the horizon band); Simpson's
 * rule on 512 panels. */
static double simpson_through(double a, double b, double x, int sky)
{
    const int n = 512;
    double h = (b - a) / n, sum = 0.0;
    for (int k = 0; k <= n; ++k) {
        double e = a + k * h, f = exp(-x / cos(e)) * (sky ? sin(2.0 * e) : 1.0);
        sum += f * (k == 0 || k == n ? 1.0 : k % 2 ? 4.0 : 2.0);
    }
    return sum * h / 3.0;
}

/* By brute force on one direction's digital lines: for each cell, its
 * solid horizon is the steepest rise to any cell before it; every crown
 * before it hides the rises from its bottom (with the gaps ignored, from
 * the ground: all below the solid horizon) to its top; the elevations
 * between every two ends of those rises, above the solid horizon and the
 * horizontal, cross the crowns that hold their middle, a path of that
 * many cells' runs x sec e; their weight and passed light are summed
 * (band_rad 0: the sky, weighted d sin^2 e; else the band, uniform in e
 * to band_rad, each direction weighted by `facing` per cell). */
static void brute_sky(const ss_grid *g, const ss_canopy *cn, int open, double per_m, double az,
                      double band_rad, const float *facing, double *hidden, double *through)
{
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, g->width, g->height, g->cell_x_m, g->cell_y_m, az,
                            SS_LINE_MODEL_DIGITAL);
    ls.families = 1;
    double run_m = ls.major_is_row ? g->cell_y_m / fabs(cos(rad(az)))
                                   : g->cell_x_m / fabs(sin(rad(az)));
    int longest = g->width > g->height ? g->width : g->height;
    size_t *cell = malloc(sizeof(size_t) * longest);
    double *w = malloc(sizeof(double) * longest), *ends = malloc(sizeof(double) * 2 * longest);
    for (int line = 0; line < ss_line_count(&ls); ++line) {
        int m = 0;
        ss_line_cursor cur = ss_line_cursor_start(&ls, line);
        while (ss_line_cursor_next(&cur))
            cell[m] = cur.cell, w[m++] = cur.walked_m;
        for (int p = 0; p < m; ++p) {
            size_t i = cell[p];
            double z = g->z[i], ts = -HUGE_VAL;
            for (int q = 0; q < p; ++q)
                if (w[p] > w[q])
                    ts = fmax(ts, (g->z[cell[q]] - z) / (w[p] - w[q]));
            double floor_rise = fmax(ts, 0.0);
            int n_ends = 0;
            ends[n_ends++] = floor_rise;
            for (int q = 0; q < p; ++q) {
                size_t j = cell[q];
                if (!(w[p] > w[q]) || !(cn->height_m[j] > 0.0f))
                    continue;
                double d = w[p] - w[q];
                ends[n_ends++] = (g->z[j] + cn->trunk_ratio * cn->height_m[j] - z) / d;
                ends[n_ends++] = (g->z[j] + cn->height_m[j] - z) / d;
            }
            qsort(ends, (size_t)n_ends, sizeof *ends, by_value);
            double f = band_rad > 0.0 ? facing[i] : 1.0;
            if (!(f > 0.0))
                continue;
            for (int k = 0; k + 1 < n_ends; ++k) {
                double a = ends[k], b = ends[k + 1], mid = 0.5 * (a + b);
                if (!(a >= floor_rise) || !(b > a))
                    continue;
                int count = 0;
                for (int q = 0; q < p; ++q) {
                    size_t j = cell[q];
                    double d = w[p] - w[q];
                    if (!(d > 0.0) || !(cn->height_m[j] > 0.0f))
                        continue;
                    double lo = open ? (g->z[j] + cn->trunk_ratio * cn->height_m[j] - z) / d
                                     : -HUGE_VAL;
                    count += mid > lo && mid < (g->z[j] + cn->height_m[j] - z) / d;
                }
                if (count == 0)
                    continue;
                double ea = atan(a), eb = atan(b), x = per_m * run_m * count;
                if (band_rad > 0.0) {
                    eb = fmin(eb, band_rad);
                    if (!(eb > ea))
                        continue;
                    hidden[i] += f * (eb - ea) / band_rad;
                    through[i] += f * simpson_through(ea, eb, x, 0) / band_rad;
                } else {
                    hidden[i] += sin(eb) * sin(eb) - sin(ea) * sin(ea);
                    through[i] += simpson_through(ea, eb, x, 1);
                }
            }
        }
    }
    free(cell), free(w), free(ends);
}

static void beer_lambert_sky(void)
{
    enum { W = 48, H = 48, D = 8 };
    const size_t n = (size_t)W * H;
    const double per_m = 0.5 * 0.6, band_rad = rad(BAND_DEG);
    ss_grid g = test_grid(W, H, 1, 1);
    float *height = calloc(n, sizeof(float)), *got = malloc(n * sizeof(float)),
          *V = malloc(n * sizeof(float)), *band_hidden = malloc(n * sizeof(float));
    float *de = malloc(n * sizeof(float)), *dn = malloc(n * sizeof(float)),
          *facing = malloc(n * sizeof(float));
    double *hidden = malloc(n * sizeof(double)), *through = malloc(n * sizeof(double)),
           *weight = malloc(n * sizeof(double));
    crowned_hills(&g, height);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = D;
    /* The band on a surface tilted 40 degrees toward grid azimuth 120. */
    for (size_t i = 0; i < n; ++i) {
        de[i] = (float)(tan(rad(40.0)) * -sin(rad(120.0)));
        dn[i] = (float)(tan(rad(40.0)) * -cos(rad(120.0)));
    }
    ss_ctx *ctx = ss_ctx_new();
    for (int open = 0; open < 2; ++open) {
        ss_canopy cn = {height, NULL, 0.3, 0.03};
        ss_trunk_gaps gaps = open ? SS_TRUNK_GAPS_OPEN : SS_TRUNK_GAPS_IGNORE;
        for (int band = 0; band < 2; ++band) {
            for (size_t i = 0; i < n; ++i)
                hidden[i] = through[i] = weight[i] = 0.0;
            for (int d = 0; d < D; ++d) {
                double az = ss_direction_azimuth(&opt, d);
                float east = (float)sin(rad(az)), north = (float)cos(rad(az));
                for (size_t i = 0; i < n; ++i) {
                    facing[i] = fmaxf(ss_cos_incidence_gradient(east, north, 0.0f, de[i], dn[i]),
                                      0.0f);
                    weight[i] += facing[i];
                }
                brute_sky(&g, &cn, open, per_m, az, band ? band_rad : 0.0, facing, hidden,
                          through);
            }
            int ok = band ? ss_canopy_band_hidden(ctx, &g, &cn, &opt, gaps, BAND_DEG, de, dn,
                                                  per_m, band_hidden, got) == SS_OK
                          : ss_canopy_sky(ctx, &g, &cn, &opt, SS_SVF_DEF_HORIZONTAL, gaps, NULL,
                                          V) == SS_OK &&
                                ss_canopy_sky_through(ctx, &g, &cn, &opt, gaps, per_m, got) ==
                                    SS_OK;
            double worst = 0.0, worst_hidden = 0.0, lo = 1.0, hi = 0.0;
            size_t cells = 0;
            for (size_t i = 0; ok && i < n; ++i) {
                double share = band ? (weight[i] > 0.0 ? hidden[i] / weight[i] : 0.0)
                                    : hidden[i] / D;
                double mine = band ? band_hidden[i] : V[i];
                double want = hidden[i] > 0.0 ? through[i] / hidden[i] : 1.0;
                worst_hidden = fmax(worst_hidden, fabs(mine - share));
                worst = fmax(worst, fabs(got[i] - want));
                if (hidden[i] > 0.0) {
                    ++cells;
                    lo = fmin(lo, want), hi = fmax(hi, want);
                }
            }
            tap_ok(ok && cells > 200 && lo < hi && worst <= 1e-6 && worst_hidden <= 1e-6,
                   "Beer-Lambert through the crowns' %s, --trunk-gaps %s, G LAD %.2f/m, %d "
                   "directions: the mean of exp(-G LAD L) over the hidden directions matches a "
                   "brute-force path march on the same digital lines on every cell (%zu cells "
                   "hide some, mean %.4f to %.4f; worst %.2g; the hidden share itself within "
                   "%.2g)",
                   band ? "horizon band (a surface tilted 40 degrees)" : "sky",
                   open ? "open" : "ignore", per_m, D, cells, lo, hi, worst, worst_hidden);
        }
    }
    ss_ctx_free(ctx);
    free(height), free(got), free(V), free(band_hidden), free(de), free(dn), free(facing);
    free(hidden), free(through), free(weight);
    ss_grid_free(&g);
}

static void refusals(void)
{
    ss_grid g = test_grid(8, 8, 1, 1);
    float height[64] = {0};
    test_plane(&g, 0.0, 0.0);
    ss_canopy cn = {height, NULL, 0.25, 0.03};
    static const double bad[][2] = {{25.0, 0.5}, {-1.0, 0.5}, {NAN, 0.5}, {1.0, 0.0}, {1.0, 2.0}};
    int refused = 0;
    outputs o = outputs_new(64);
    ss_surface flat = {SS_SURFACE_CELL, 0.0, 0.0};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; ++k) {
        ss_insolation_trees t = {&g, &cn, NULL, 0.5, NULL, 0, SS_TRUNK_GAPS_IGNORE, bad[k][0],
                                 bad[k][1]};
        refused += !run_with(&g, &t, SS_SHADOW_EXACT, 1, flat, 8, NULL, &o);
    }
    ss_insolation_trees t = {&g, &cn, NULL, 0.5, NULL, 0, SS_TRUNK_GAPS_IGNORE, 1.0, 0.5};
    refused += !run_with(&g, &t, SS_SHADOW_CUMULATIVE, 1, flat, 8, NULL, &o);
    tap_ok(refused == 6,
           "Beer-Lambert refuses a leaf area density of 25, -1 or NaN, an extinction of 0 or 2, "
           "and the cumulative sky (%d of 6 refused)",
           refused);
    outputs_free(&o);
    ss_grid_free(&g);
}

int main(void)
{
    horizon_band();
    beer_lambert();
    beer_lambert_sky();
    refusals();
    return tap_done();
}
