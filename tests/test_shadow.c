/* Cast shadows against closed forms and the brute force: a vertical wall's
 * shadow is H / tan(e) long (oblique suns: H cos(delta) / tan(e), physics.md
 * sec. 3); the sun on, just above and just below the horizon; the sun at the
 * zenith; and on random terrain the mask equals the brute-force horizon of
 * the same model compared with the sun. Both devices. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "tap.h"
#include "testlib.h"

static const char *devices[] = {NULL, "reference"};

static float *shadow(int device, const ss_grid *g, double az, double el, char *err)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, devices[device]);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    float *lit = malloc(sizeof(float) * (size_t)g->width * g->height);
    if (ss_cast_shadow(ctx, g, &opt, az, el, NULL, lit, NULL) != SS_OK) {
        snprintf(err, 300, "%s", ss_ctx_message(ctx));
        free(lit);
        lit = NULL;
    }
    ss_ctx_free(ctx);
    return lit;
}

/* A north-south wall of height H one cell wide at column cw on flat ground. */
static void wall(int device)
{
    const int n = 201, cw = 150;
    const double H = 30;
    ss_grid g = test_grid(n, n, 1, 1);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            g.z[(size_t)r * n + c] = c == cw ? (float)H : 0.0f;
    const double cases[][2] = {{90, 20}, {90, 45}, {90 + 30, 25}, {90 - 40, 35}};
    for (int k = 0; k < 4; ++k) {
        double az = cases[k][0], el = cases[k][1];
        double delta = (az - 90) * M_PI / 180;
        double length = H * cos(delta) / tan(el * M_PI / 180); /* perpendicular to the wall */
        char err[300] = "";
        float *lit = shadow(device, &g, az, el, err);
        int wrong = 0, checked = 0;
        /* Cells well inside the grid west of the wall, away from where the
         * boundary falls within half a cell of a centre. */
        for (int r = 60; lit && r < 140; ++r)
            for (int c = 0; c < cw; ++c) {
                double x = cw - c;
                if (fabs(x - length) < 0.5)
                    continue;
                int want_lit = x > length;
                wrong += (lit[(size_t)r * n + c] == 1.0f) != want_lit;
                checked++;
            }
        tap_ok(lit && wrong == 0 && checked > 0,
               "%s: wall H=%g, sun azimuth %g elevation %g: shadow reaches %.2f cells from the "
               "wall (H cos(delta)/tan e); %d of %d cells wrong %s",
               devices[device] ? devices[device] : "OpenCL", H, az, el, length, wrong, checked,
               err);
        free(lit);
    }
    ss_grid_free(&g);
}

static void horizon_and_zenith(int device)
{
    const int n = 40;
    ss_grid g = test_grid(n, n, 10, 10);
    for (int k = 0; k < n * n; ++k)
        g.z[k] = 250.0f;
    const struct {
        double el;
        float want;
    } cases[] = {{0.0, 0.0f}, {1e-6, 1.0f}, {-1e-6, 0.0f}, {-0.1, 0.0f}, {-18.5, 0.0f},
                 {90.0, 1.0f}};
    for (int k = 0; k < 6; ++k) {
        char err[300] = "";
        float *lit = shadow(device, &g, 123.0, cases[k].el, err);
        int wrong = 0;
        for (int i = 0; lit && i < n * n; ++i)
            wrong += lit[i] != cases[k].want;
        tap_ok(lit && wrong == 0,
               "%s: flat plane, sun at %g deg: every cell %s (%d wrong; lit means strictly "
               "above the horizon, which is the horizontal on a plane and at the edge) %s",
               devices[device] ? devices[device] : "OpenCL", cases[k].el,
               cases[k].want ? "sunlit" : "shadowed", wrong, err);
        free(lit);
    }
    /* The sun at the zenith lights rough terrain everywhere. */
    test_fill(&g, TERRAIN_NOISE, 3, 500);
    char err[300] = "";
    float *lit = shadow(device, &g, 0.0, 90.0, err);
    int dark = 0;
    for (int i = 0; lit && i < n * n; ++i)
        dark += lit[i] != 1.0f;
    tap_ok(lit && dark == 0, "%s: sun at the zenith casts no shadow on rough terrain (%d dark) %s",
           devices[device] ? devices[device] : "OpenCL", dark, err);
    free(lit);
    ss_grid_free(&g);
}

/* The mask equals the brute-force horizon (interpolated lines, the same
 * model; nothing ahead counts as the horizontal) compared with the sun,
 * except within 1e-5 rad of the boundary. */
static void against_brute_force(int device)
{
    ss_grid g = test_grid(90, 70, 20, 20);
    test_fill(&g, TERRAIN_SMOOTH, 11, 300);
    test_holes(&g, 12, 4, 5);
    size_t n = (size_t)g.width * g.height;
    double *ref = malloc(n * sizeof(double)), *near = malloc(n * sizeof(double)),
           *claimed = malloc(n * sizeof(double));
    int wrong = 0, close_calls = 0;
    char err[300] = "";
    const double az[] = {17.0, 135.0, 250.5}, el[] = {12.0, 5.0, 30.0};
    for (int k = 0; k < 3; ++k) {
        float *lit = shadow(device, &g, az[k], el[k], err);
        if (!lit) {
            wrong = -1;
            break;
        }
        test_brute_horizon_none(&g, az[k], SS_LINES_INTERPOLATED, 0.0, ref, near, claimed);
        for (size_t c = 0; c < n; ++c) {
            if (!isfinite(g.z[c])) {
                wrong += lit[c] != SS_NODATA;
                continue;
            }
            if (fabs(ref[c] - el[k]) < 1e-5 * 180 / M_PI) {
                close_calls++;
                continue;
            }
            wrong += (lit[c] == 1.0f) != (el[k] > ref[c]);
        }
        free(lit);
    }
    tap_ok(wrong == 0, "%s: shadow mask == brute-force horizon vs sun on random terrain with holes "
                       "(%d wrong, %d within 1e-5 rad skipped) %s",
           devices[device] ? devices[device] : "OpenCL", wrong, close_calls, err);
    free(ref);
    free(near);
    free(claimed);
    ss_grid_free(&g);
}

/* The proven horizon bound (ss_horizon_bound_deg) lets insolation skip
 * shadow sweeps: a sun just above it must light every cell, in every line
 * model (box lines with 32 per cell), on rough terrain with cliffs and at
 * every azimuth tried. */
static void above_the_bound(int device)
{
    ss_grid g = test_grid(70, 50, 30, 30);
    test_fill(&g, TERRAIN_SMOOTH, 21, 60);
    g.z[35 * 70 + 20] += 40.0f; /* a one-cell tower: a horizon with a steep edge */
    int dark = 0, runs = 0;
    double bound_deg = ss_horizon_bound_deg(&g, SS_LINES_INTERPOLATED, 0);
    char err[300] = "";
    for (int model = SS_LINES_INTERPOLATED; model <= SS_LINES_BOX; ++model) {
        double el = ss_horizon_bound_deg(&g, (ss_line_model)model, 32) + 1e-6;
        for (double az = 7.5; az < 360; az += 45) {
            ss_ctx *ctx = ss_ctx_new();
            ss_ctx_use_device(ctx, devices[device]);
            ss_sweep_options opt;
            ss_sweep_options_default(&opt);
            opt.lines = (ss_line_model)model;
            opt.box_lines = 32;
            float *lit = malloc(sizeof(float) * 70 * 50);
            if (el > 90 || ss_cast_shadow(ctx, &g, &opt, az, el, NULL, lit, NULL) != SS_OK) {
                snprintf(err, sizeof err, "%s", ss_ctx_message(ctx));
                dark = -1;
            }
            for (int k = 0; dark >= 0 && k < 70 * 50; ++k)
                dark += lit[k] != 1.0f;
            runs++;
            free(lit);
            ss_ctx_free(ctx);
        }
    }
    tap_ok(dark == 0 && bound_deg < 80,
           "%s: a sun just above the proven horizon bound (%.1f deg) lights every cell (%d runs, "
           "%d shadowed cells) %s",
           devices[device] ? devices[device] : "OpenCL", bound_deg, runs, dark, err);
    ss_grid_free(&g);
}

int main(void)
{
    for (int d = 0; d < 2; ++d) {
        wall(d);
        horizon_and_zenith(d);
        against_brute_force(d);
        above_the_bound(d);
    }
    return tap_done();
}
