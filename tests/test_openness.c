/* Topographic openness (physics.md 2.3) and radius-limited horizons
 * against closed forms and the brute-force horizon: flat and tilted planes,
 * a conical pit and peak (positive, negative, radius-limited), random
 * terrain with nodata holes, the radius scan against the hull sweep, and a
 * wall beyond and within the radius of SVF. Both devices. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "tap.h"
#include "testlib.h"

#define DEG (180.0 / M_PI)

static const char *devices[] = {NULL, "reference"};
static const char *device_name(int d)
{
    return devices[d] ? devices[d] : "OpenCL";
}

/* Openness on device d with the options given (directions set here). */
static float *run_openness_with(int device, const ss_grid *g, ss_sweep_options opt,
                                int directions, int negative, double radius_m)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, devices[device]);
    opt.directions = directions;
    float *out = malloc(sizeof(float) * (size_t)g->width * g->height);
    if (ss_openness(ctx, g, &opt, negative, radius_m, out) != SS_OK) {
        tap_diag("ss_openness failed: %s", ss_ctx_message(ctx));
        free(out);
        out = NULL;
    }
    ss_ctx_free(ctx);
    return out;
}

static float *run_openness(int device, const ss_grid *g, int directions, int negative,
                           double radius_m)
{
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.earth_radius_m = 0;
    return run_openness_with(device, g, opt, directions, negative, radius_m);
}

static double worst_error(const float *v, size_t n, double want)
{
    double worst = v ? 0 : INFINITY;
    for (size_t c = 0; v && c < n; ++c) {
        double e = fabs(v[c] - want);
        worst = e > worst || !isfinite(e) ? e : worst;
    }
    return worst;
}

/* Nothing rises above or sinks below the horizontal anywhere: 90 deg. */
static void flat_plane(void)
{
    ss_grid g = test_grid(40, 30, 10, 10);
    for (size_t c = 0; c < 40 * 30; ++c)
        g.z[c] = 1234.5f;
    for (int d = 0; d < 2; ++d)
        for (int negative = 0; negative < 2; ++negative)
            for (int limited = 0; limited < 2; ++limited) {
                float *o = run_openness(d, &g, 16, negative, limited ? 55.0 : 0.0);
                double e = worst_error(o, 40 * 30, 90.0);
                tap_ok(e <= 1e-4, "flat plane, %s, %s openness, radius %s: worst |O - 90| = %.2g deg",
                       device_name(d), negative ? "negative" : "positive",
                       limited ? "55 m" : "unlimited", e);
                free(o);
            }
    ss_grid_free(&g);
}

/* A plane rising at slope s towards azimuth a_up: every sample ahead in
 * direction theta lies on the plane, at elevation angle atan(s cos(theta -
 * a_up)) (negative downhill, where the nearest sample is the highest), so
 * positive openness is 90 - mean atan(s cos(theta_i - a_up)) and negative
 * openness 90 - mean atan(-s cos(theta_i - a_up)). Over N even directions
 * the odd atan cancels in pairs, and over most odd N its harmonics nearly
 * do; with N = 3 the third harmonic survives, so the mean is far from 0.
 * Cells two from the edge have terrain ahead in every direction. */
static void tilted_plane(void)
{
    const int w = 41, h = 37, dirs = 3;
    const double s = 1.0, cell = 10, a_up = 70 / DEG;
    ss_grid g = test_grid(w, h, cell, cell);
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) /* x east = c cell, y north = -r cell */
            g.z[(size_t)r * w + c] =
                (float)(500 + s * cell * (c * sin(a_up) - r * cos(a_up)));
    double mean_up = 0;
    for (int i = 0; i < dirs; ++i)
        mean_up += atan(s * cos(i * 2 * M_PI / dirs - a_up)) * DEG / dirs;
    for (int d = 0; d < 2; ++d)
        for (int negative = 0; negative < 2; ++negative) {
            float *o = run_openness(d, &g, dirs, negative, 0);
            double want = negative ? 90 + mean_up : 90 - mean_up, worst = o ? 0 : INFINITY;
            for (int r = 2; o && r < h - 2; ++r)
                for (int c = 2; c < w - 2; ++c)
                    worst = fmax(worst, fabs(o[(size_t)r * w + c] - want));
            tap_ok(worst <= 1e-3,
                   "plane of slope %.1f, %s, %d directions: %s openness %.4f deg, worst error "
                   "%.2g deg",
                   s, device_name(d), dirs, negative ? "negative" : "positive", want, worst);
            free(o);
        }
    ss_grid_free(&g);
}

/* A cone of radius R and height +-D, flat beyond. At the bottom of the pit
 * every direction sees the rim at atan(D/R): positive openness 90 -
 * atan(D/R). The peak is the inverted pit, so its negative openness at the
 * apex is the same. Within a radius r < R the peak's apex sees only the
 * cone falling away at atan(D/R): positive openness 90 + atan(D/R). With 8
 * directions every line passes through the apex's centre and samples the
 * cone's profile exactly. */
static void cones(void)
{
    const int n = 81, c0 = 40;
    const double cell = 10, R = 300, D = 120;
    ss_grid pit = test_grid(n, n, cell, cell), peak = test_grid(n, n, cell, cell);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            double rho = hypot((c - c0) * cell, (r - c0) * cell);
            double z = rho < R ? D * rho / R - D : 0.0;
            pit.z[(size_t)r * n + c] = (float)z;
            peak.z[(size_t)r * n + c] = (float)-z;
        }
    size_t apex = (size_t)c0 * n + c0;
    double rim = atan(D / R) * DEG;
    for (int d = 0; d < 2; ++d) {
        float *pit_pos = run_openness(d, &pit, 8, 0, 0);
        float *peak_neg = run_openness(d, &peak, 8, 1, 0);
        float *pit_pos_r = run_openness(d, &pit, 8, 0, 150);
        float *peak_pos_r = run_openness(d, &peak, 8, 0, 150);
        tap_ok(pit_pos && fabs(pit_pos[apex] - (90 - rim)) <= 1e-3,
               "conical pit, %s: positive openness at the bottom %.5f deg (want 90 - atan(D/R) "
               "= %.5f)",
               device_name(d), pit_pos ? pit_pos[apex] : NAN, 90 - rim);
        tap_ok(peak_neg && fabs(peak_neg[apex] - (90 - rim)) <= 1e-3,
               "conical peak, %s: negative openness at the apex %.5f deg (want %.5f)",
               device_name(d), peak_neg ? peak_neg[apex] : NAN, 90 - rim);
        tap_ok(pit_pos_r && fabs(pit_pos_r[apex] - (90 - rim)) <= 1e-3,
               "conical pit, %s, radius 150 m < R: positive openness %.5f deg (want %.5f)",
               device_name(d), pit_pos_r ? pit_pos_r[apex] : NAN, 90 - rim);
        tap_ok(peak_pos_r && fabs(peak_pos_r[apex] - (90 + rim)) <= 1e-3,
               "conical peak, %s, radius 150 m < R: positive openness %.5f deg (want 90 + "
               "atan(D/R) = %.5f)",
               device_name(d), peak_pos_r ? peak_pos_r[apex] : NAN, 90 + rim);
        free(pit_pos);
        free(peak_neg);
        free(pit_pos_r);
        free(peak_pos_r);
    }
    ss_grid_free(&pit);
    ss_grid_free(&peak);
}

/* Random hills with nodata holes: positive openness must be 90 minus the
 * mean of the brute-force horizons (0 where nothing lies ahead), negative
 * openness the same on -z; a radius longer than the grid must give the
 * unlimited result (a plain scan agreeing with the hull sweep), and the
 * devices must agree. */
static void random_terrain(void)
{
    const int w = 37, h = 29, dirs = 12;
    const size_t n = (size_t)w * h;
    ss_grid g = test_grid(w, h, 20, 14), inv = test_grid(w, h, 20, 14);
    test_fill(&g, TERRAIN_SMOOTH, 7, 300);
    test_holes(&g, 3, 4, 5);
    for (size_t c = 0; c < n; ++c)
        inv.z[c] = -g.z[c];
    double *want[2], *angle = malloc(sizeof(double) * n), *near = malloc(sizeof(double) * n),
                      *claimed = malloc(sizeof(double) * n);
    for (int neg = 0; neg < 2; ++neg) {
        want[neg] = calloc(n, sizeof(double));
        for (int i = 0; i < dirs; ++i) {
            test_brute_horizon_terms(neg ? &inv : &g, i * 360.0 / dirs, 0.0, 0.0,
                                     SS_LINE_MODEL_INTERPOLATED, 0.0, angle);
            for (size_t c = 0; c < n; ++c)
                want[neg][c] += angle[c] / dirs;
        }
        for (size_t c = 0; c < n; ++c)
            want[neg][c] = 90.0 - want[neg][c];
    }
    float *first = NULL;
    for (int d = 0; d < 2; ++d)
        for (int neg = 0; neg < 2; ++neg) {
            float *o = run_openness(d, &g, dirs, neg, 0);
            float *far = run_openness(d, &g, dirs, neg, 1e6);
            double worst = o ? 0 : INFINITY, worst_far = far ? 0 : INFINITY;
            int nodata_ok = 1;
            for (size_t c = 0; o && far && c < n; ++c) {
                if (!isfinite(g.z[c])) {
                    nodata_ok &= o[c] == SS_NODATA && far[c] == SS_NODATA;
                    continue;
                }
                double e = fabs(o[c] - want[neg][c]), ef = fabs(far[c] - o[c]);
                worst = e > worst || !isfinite(e) ? e : worst;
                worst_far = ef > worst_far || !isfinite(ef) ? ef : worst_far;
            }
            tap_ok(worst <= 2e-3 && nodata_ok,
                   "random hills with holes, %s, %s openness: worst |sweep - brute force| = "
                   "%.2g deg, nodata kept: %s",
                   device_name(d), neg ? "negative" : "positive", worst, nodata_ok ? "yes" : "no");
            tap_ok(worst_far <= 2e-3,
                   "random hills, %s, %s openness: radius 1000 km scan vs unlimited sweep, worst "
                   "%.2g deg",
                   device_name(d), neg ? "negative" : "positive", worst_far);
            if (d == 0 && neg == 0) {
                first = o;
                o = NULL;
            } else if (d == 1 && neg == 0) {
                double e = 0;
                for (size_t c = 0; first && o && c < n; ++c)
                    e = fmax(e, fabs(first[c] - o[c]));
                tap_ok(first && o && e <= 1e-3,
                       "random hills: OpenCL and reference positive openness agree within %.2g deg",
                       e);
            }
            free(o);
            free(far);
        }
    free(first);
    for (int neg = 0; neg < 2; ++neg)
        free(want[neg]);
    free(angle);
    free(near);
    free(claimed);
    ss_grid_free(&g);
    ss_grid_free(&inv);
}

/* Random hills with holes seen within a finite radius, on both line
 * models, flat and on a small planet (R = 40 km, refraction 0.13, where
 * curvature bends horizons by degrees): positive openness must be 90 minus
 * the mean of brute-force horizons that look no farther than the radius
 * (0 where nothing lies within it). The library scans the short windows
 * and finds the long ones (over 20 steps: the last radius, and the third
 * for some directions) by chunked hulls, the brute force by trying every
 * sample. */
static void radius_brute_force(void)
{
    const int w = 41, h = 35, dirs = 8;
    const size_t n = (size_t)w * h;
    const double radii[] = {47.3, 151.3, 407.7, 731.9}, planet_m = 4e4, refraction = 0.13;
    ss_grid g = test_grid(w, h, 20, 14);
    test_fill(&g, TERRAIN_NOISE, 19, 120);
    test_holes(&g, 4, 3, 4);
    double *want = malloc(sizeof(double) * n), *angle = malloc(sizeof(double) * n);
    for (int model = 0; model < 2; ++model)
        for (int curved = 0; curved < 2; ++curved)
            for (size_t r = 0; r < sizeof radii / sizeof *radii; ++r) {
                double curv_k = curved ? 0.5 * (1 - refraction) / planet_m : 0.0;
                for (size_t c = 0; c < n; ++c)
                    want[c] = 90.0;
                for (int i = 0; i < dirs; ++i) {
                    test_brute_horizon_terms(&g, i * 360.0 / dirs, curv_k, radii[r], model, 0.0,
                                             angle);
                    for (size_t c = 0; c < n; ++c)
                        want[c] -= angle[c] / dirs;
                }
                ss_sweep_options opt;
                ss_sweep_options_default(&opt);
                opt.lines = (ss_line_model)model;
                opt.earth_radius_m = curved ? planet_m : 0.0;
                opt.refraction_k = refraction;
                for (int d = 0; d < 2; ++d) {
                    float *o = run_openness_with(d, &g, opt, dirs, 0, radii[r]);
                    double worst = o ? 0 : INFINITY;
                    for (size_t c = 0; o && c < n; ++c) {
                        if (!isfinite(g.z[c]))
                            continue;
                        double e = fabs(o[c] - want[c]);
                        worst = e > worst || !isfinite(e) ? e : worst;
                    }
                    tap_ok(worst <= 2e-3,
                           "noisy hills with holes, %s lines, %s, %s, radius %.1f m: worst "
                           "|openness - brute force within the radius| = %.2g deg",
                           model ? "digital" : "interpolated", curved ? "40 km planet" : "flat",
                           device_name(d), radii[r], worst);
                    free(o);
                }
            }
    free(want);
    free(angle);
    ss_grid_free(&g);
}

/* physics.md 2.3's test vectors. A V-valley with 30 deg walls, axis
 * north-south: from its floor the mean horizon over 8 directions is
 * 18.603827 deg, so positive openness is 71.396173 deg. A spike 10 cells
 * high on flat ground: its negative openness over 8 directions, the first
 * samples one cell away on the axes and sqrt 2 on the diagonals, is
 * 6.880030 deg. */
static void published_vectors(void)
{
    const int n = 61, c0 = 30;
    const double cell = 10;
    ss_grid valley = test_grid(n, n, cell, cell), spike = test_grid(n, n, cell, cell);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            valley.z[(size_t)r * n + c] = (float)(abs(c - c0) * cell * tan(30 / DEG));
            spike.z[(size_t)r * n + c] = r == c0 && c == c0 ? (float)(10 * cell) : 0.0f;
        }
    size_t centre = (size_t)c0 * n + c0;
    for (int d = 0; d < 2; ++d) {
        float *phi = run_openness(d, &valley, 8, 0, 0);
        float *psi = run_openness(d, &spike, 8, 1, 0);
        tap_ok(phi && fabs(phi[centre] - 71.396173) <= 1e-4,
               "V-valley of 30 deg, %s: positive openness at the floor %.6f (want 71.396173)",
               device_name(d), phi ? phi[centre] : NAN);
        tap_ok(psi && fabs(psi[centre] - 6.880030) <= 1e-4,
               "spike 10 cells high, %s: negative openness at its top %.6f (want 6.880030)",
               device_name(d), psi ? psi[centre] : NAN);
        free(phi);
        free(psi);
    }
    ss_grid_free(&valley);
    ss_grid_free(&spike);
}

/* Negative openness is defined as the positive openness of -z: the
 * library must give exactly that, nodata included. */
static void inversion_identity(void)
{
    const int w = 33, h = 25;
    const size_t n = (size_t)w * h;
    ss_grid g = test_grid(w, h, 15, 15), inv = test_grid(w, h, 15, 15);
    test_fill(&g, TERRAIN_NOISE, 11, 80);
    test_holes(&g, 5, 3, 4);
    for (size_t c = 0; c < n; ++c)
        inv.z[c] = -g.z[c];
    for (int d = 0; d < 2; ++d) {
        float *neg = run_openness(d, &g, 16, 1, 0), *pos_inv = run_openness(d, &inv, 16, 0, 0);
        size_t differ = neg && pos_inv ? 0 : n;
        for (size_t c = 0; neg && pos_inv && c < n; ++c)
            differ += neg[c] != pos_inv[c];
        tap_ok(differ == 0, "%s: negative openness of z == positive openness of -z (%zu cells "
                            "differ)",
               device_name(d), differ);
        free(neg);
        free(pos_inv);
    }
    ss_grid_free(&g);
    ss_grid_free(&inv);
}

/* A wall 100 m high along column 30 of a flat plane (10 m cells). From
 * column 10, row 20 it is 200 m away to the east and at most 283 m in the
 * directions that meet it before the grid's edge: a radius of 150 m does
 * not reach it (SVF 1 exactly, as on the plane), 300 m reaches all of it
 * (the unlimited SVF). */
static void svf_radius_wall(void)
{
    const int w = 41, h = 41;
    ss_grid g = test_grid(w, h, 10, 10);
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c)
            g.z[(size_t)r * w + c] = c == 30 ? 100.0f : 0.0f;
    size_t cell = (size_t)20 * w + 10;
    for (int d = 0; d < 2; ++d) {
        ss_ctx *ctx = ss_ctx_new();
        ss_ctx_use_device(ctx, devices[d]);
        ss_sweep_options opt;
        ss_sweep_options_default(&opt);
        opt.directions = 16;
        opt.earth_radius_m = 0;
        float *near = malloc(sizeof(float) * w * h), *far = malloc(sizeof(float) * w * h),
              *all = malloc(sizeof(float) * w * h);
        int ok = ss_svf_within(ctx, &g, &opt, SS_SVF_DEF_GEOMETRIC, 150, near) == SS_OK &&
                 ss_svf_within(ctx, &g, &opt, SS_SVF_DEF_GEOMETRIC, 300, far) == SS_OK &&
                 ss_svf(ctx, &g, &opt, SS_SVF_DEF_GEOMETRIC, all) == SS_OK;
        tap_ok(ok && near[cell] == 1.0f && all[cell] < 0.99f && fabs(far[cell] - all[cell]) < 1e-6,
               "wall 200 m away, %s: SVF within 150 m %.6f (want 1), within 300 m %.6f == "
               "unlimited %.6f (< 1)",
               device_name(d), ok ? near[cell] : NAN, ok ? far[cell] : NAN, ok ? all[cell] : NAN);
        ss_status st = ss_svf_within(ctx, &g, &opt, SS_SVF_DEF_RADIATIVE, 100, near);
        tap_ok(st == SS_ERR_ARGUMENT, "radius-limited radiative (tilted) SVF is refused: %s",
               ss_ctx_message(ctx));
        free(near);
        free(far);
        free(all);
        ss_ctx_free(ctx);
    }
    ss_grid_free(&g);
}

/* The VAT recipe worked by hand (src/core/relief_blend.c): white stays
 * white, black black; a middle cell: hillshade 0.6, slope 25 deg inverted
 * to 0.5 and mixed half -> 0.55; openness 80.5 -> 0.5, overlay on 0.55 ->
 * 1 - 2 (0.5)(0.45) = 0.55, mixed half -> 0.55; SVF 0.85 -> 0.5, multiply
 * 0.275 mixed a quarter -> 0.48125. A flat plane: hillshade sin 35 deg,
 * slope 0 -> 1, openness 90 -> 0.88, SVF 1 -> 1. */
static void vat_recipe(void)
{
    struct {
        float hs, slope, openness, svf;
        double want;
    } cases[] = {{1, 0, 93, 1, 1.0}, {0, 50, 68, 0.7f, 0.0}, {0.6f, 25, 80.5f, 0.85f, 0.48125}};
    for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
        float v = ss_vat_compose(cases[i].hs, cases[i].slope, cases[i].openness, cases[i].svf);
        tap_ok(fabs(v - cases[i].want) <= 1e-6,
               "VAT of hillshade %.2f, slope %.0f, openness %.1f, SVF %.2f: %.6f (want %.6f)",
               cases[i].hs, cases[i].slope, cases[i].openness, cases[i].svf, v, cases[i].want);
    }
    double image = 0.5 * sin(35 / DEG) + 0.5;
    image = 0.5 * (1 - 2 * (1 - 0.88) * (1 - image)) + 0.5 * image;
    ss_grid g = test_grid(30, 20, 5, 5);
    for (size_t c = 0; c < 600; ++c)
        g.z[c] = c == 7 ? NAN : 42.0f;
    for (int d = 0; d < 2; ++d) {
        ss_ctx *ctx = ss_ctx_new();
        ss_ctx_use_device(ctx, devices[d]);
        ss_sweep_options opt;
        ss_sweep_options_default(&opt);
        opt.directions = 8;
        float out[600];
        ss_status st = ss_vat(ctx, &g, &opt, 50, out);
        double worst = 0;
        for (size_t c = 0; st == SS_OK && c < 600; ++c)
            if (c != 7)
                worst = fmax(worst, fabs(out[c] - image));
        tap_ok(st == SS_OK && worst <= 1e-5 && out[7] == SS_NODATA,
               "VAT of a flat plane with a hole, %s: %.6f everywhere (want %.6f, worst %.2g), "
               "nodata kept",
               device_name(d), st == SS_OK ? out[0] : NAN, image, worst);
        ss_ctx_free(ctx);
    }
    ss_grid_free(&g);
}

static void bad_radius(void)
{
    ss_grid g = test_grid(8, 8, 1, 1);
    ss_ctx *ctx = ss_ctx_new();
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    float out[64];
    ss_status st = ss_openness(ctx, &g, &opt, 0, -5, out);
    tap_ok(st == SS_ERR_ARGUMENT, "a negative radius is refused: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    ss_grid_free(&g);
}

int main(void)
{
    flat_plane();
    tilted_plane();
    cones();
    published_vectors();
    inversion_identity();
    svf_radius_wall();
    radius_brute_force();
    vat_recipe();
    random_terrain();
    bad_radius();
    return tap_done();
}
