/* Horizons and sky-view factors against closed forms (reference/physics.md
 * sec. 2.4 and 6.2) on shapes whose answers are known: flat planes at sea
 * level and at great heights, tilted planes (square and 30 x 10 m cells), a
 * conical pit and a trench. Both devices, both line models.
 *
 * Tolerances: where every sample of a line lies on one plane the discrete
 * model is exact and only float rounding is allowed (1e-5 rad, 1e-5 in SVF).
 * Where a feature is resolved by samples one cell apart, the horizon's
 * tangent can be off by about one cell over the distance to the feature,
 * so those tolerances are derived from that distance (stated per case). */
#include "config.h"

#include <math.h>
#include <string.h>

#include "ss_terms.h"
#include "tap.h"
#include "testlib.h"

static const char *devices[] = {NULL, "reference"};
static const char *device_name(int d)
{
    return devices[d] ? devices[d] : "OpenCL";
}
static const char *model_name(int m)
{
    return m == SS_LINES_DIGITAL ? "digital" : "interpolated";
}

static float *run_svf(int device, const ss_grid *g, int directions, double offset,
                      ss_svf_definition def, int model)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, devices[device]);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = directions;
    opt.offset_deg = offset;
    opt.lines = (ss_line_model)model;
    float *out = malloc(sizeof(float) * (size_t)g->width * g->height);
    if (ss_svf(ctx, g, &opt, def, out) != SS_OK) {
        tap_diag("ss_svf failed: %s", ss_ctx_message(ctx));
        free(out);
        out = NULL;
    }
    ss_ctx_free(ctx);
    return out;
}

static float *run_horizon(int device, const ss_grid *g, double azimuth, int model)
{
    float *angle = malloc(sizeof(float) * (size_t)g->width * g->height);
    char err[512];
    if (test_lib_horizon(devices[device], g, azimuth, 0, 0, model, angle, NULL, err,
                         sizeof err) != SS_OK) {
        tap_diag("horizon failed: %s", err);
        free(angle);
        return NULL;
    }
    return angle;
}

/* Worst |value - want| over the cells on the grid's edge, corners left
 * out (gdaldem's gradient, which skysweep follows, is one-sided across the
 * side there: kernels/ss_terms.h, ss_z_or). */
static double worst_edge(const float *v, const ss_grid *g, double want)
{
    double worst = 0;
    if (!v)
        return INFINITY;
    int w = g->width, h = g->height;
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) {
            int edge = r == 0 || c == 0 || r == h - 1 || c == w - 1;
            int corner = (r == 0 || r == h - 1) && (c == 0 || c == w - 1);
            double e = edge && !corner ? fabs(v[(size_t)r * w + c] - want) : 0;
            worst = e > worst || !isfinite(e) ? e : worst;
        }
    return worst;
}

/* Worst |value - want| over cells at least `margin` cells from every edge. */
static double worst_interior(const float *v, const ss_grid *g, int margin, double want)
{
    double worst = 0;
    if (!v)
        return INFINITY;
    for (int r = margin; r < g->height - margin; ++r)
        for (int c = margin; c < g->width - margin; ++c) {
            double e = fabs(v[(size_t)r * g->width + c] - want);
            worst = e > worst || !isfinite(e) ? e : worst;
        }
    return worst;
}

static void flat_planes(void)
{
    const double heights[] = {0.0, 8848.0, -430.0, 1e5};
    for (size_t i = 0; i < 4; ++i)
        for (int model = 0; model < 2; ++model)
            for (int d = 0; d < 2; ++d) {
                ss_grid g = test_grid(41, 37, 30, 30);
                for (size_t k = 0; k < 41u * 37u; ++k)
                    g.z[k] = (float)heights[i];
                double worst_h = 0;
                const double az[] = {0, 30, 45, 90, 137.5, 180, 225, 300};
                for (int a = 0; a < 8; ++a) {
                    float *h = run_horizon(d, &g, az[a], model);
                    double w = worst_interior(h, &g, 2, 0.0);
                    worst_h = w > worst_h || !isfinite(w) ? w : worst_h;
                    free(h);
                }
                double worst_svf = 0;
                for (int def = 0; def < 3; ++def) {
                    float *s = run_svf(d, &g, 16, 0, (ss_svf_definition)def, model);
                    double w = worst_interior(s, &g, 0, 1.0);
                    worst_svf = w > worst_svf || !isfinite(w) ? w : worst_svf;
                    free(s);
                }
                tap_ok(worst_h == 0.0 && worst_svf == 0.0,
                       "flat plane at %g m, %s lines, %s: horizon exactly 0 (worst %g deg), "
                       "SVF exactly 1 in all definitions (worst %g)",
                       heights[i], model_name(model), device_name(d), worst_h, worst_svf);
                ss_grid_free(&g);
            }
}

/* Plane of slope S (deg) facing aspect A (deg): z falls toward A. */
static ss_grid tilted_plane(int n, double cx, double cy, double slope_deg, double aspect_deg)
{
    ss_grid g = test_grid(n, n, cx, cy);
    double t = tan(slope_deg * M_PI / 180), a = aspect_deg * M_PI / 180;
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            double east = (c - n / 2) * cx, north = -(r - n / 2) * cy;
            g.z[(size_t)r * n + c] = (float)(-t * (east * sin(a) + north * cos(a)));
        }
    return g;
}

/* Rise of the plane along azimuth phi: -tan S cos(phi - A). Ahead of any
 * cell every point of the plane is seen at atan(rise), so that is the
 * horizon, negative where the plane falls away. */
static double plane_horizon_deg(double slope_deg, double aspect_deg, double phi_deg)
{
    return atan(-tan(slope_deg * M_PI / 180) * cos((phi_deg - aspect_deg) * M_PI / 180)) * 180 /
           M_PI;
}

static void tilted_planes(void)
{
    const struct {
        double cx, cy, slope, aspect;
    } cases[] = {{30, 30, 30, 180}, {30, 30, 10, 63}, {30, 10, 30, 180}, {30, 10, 45, 120}};
    for (size_t i = 0; i < 4; ++i)
        for (int d = 0; d < 2; ++d) {
            ss_grid g = tilted_plane(61, cases[i].cx, cases[i].cy, cases[i].slope,
                                     cases[i].aspect);
            /* Horizons: interpolated samples lie on the plane: exact. */
            double worst = 0;
            for (double az = 0; az < 360; az += 22.5) {
                float *h = run_horizon(d, &g, az + 3.7, SS_LINES_INTERPOLATED);
                double w = worst_interior(h, &g, 2,
                                          plane_horizon_deg(cases[i].slope, cases[i].aspect,
                                                            az + 3.7));
                worst = w > worst || !isfinite(w) ? w : worst;
                free(h);
            }
            /* The plane is stored in float32, which rounds each height by
             * up to half an ulp: over the nearest sample (one short cell) that
             * can tilt a horizon by ~2 ulp / cell on its own. */
            double z_max = 0;
            for (size_t k = 0; k < 61u * 61u; ++k)
                z_max = fmax(z_max, fabs(g.z[k]));
            double tol = fmax(1e-5, 3 * (nextafterf((float)z_max, INFINITY) - (float)z_max) /
                                        fmin(cases[i].cx, cases[i].cy));
            tap_ok(worst * M_PI / 180 <= tol,
                   "tilted plane S=%g A=%g on %gx%g m cells, %s: horizon = atan(rise) in 16 "
                   "azimuths (worst %.2e rad, float32 height resolution allows %.1e)",
                   cases[i].slope, cases[i].aspect, cases[i].cx, cases[i].cy, device_name(d),
                   worst * M_PI / 180, tol);
            /* SVF: the expected value is the same discrete mean of the exact
             * horizons, and for the radiative definitions the closed form
             * (physics.md 2.4: (1 + cos S)/2, converged at D = 16). */
            const int D = 32;
            double sum_z = 0, sum_h = 0;
            for (int k = 0; k < D; ++k) {
                double h = plane_horizon_deg(cases[i].slope, cases[i].aspect, 360.0 * k / D);
                double hp = h > 0 ? h * M_PI / 180 : 0;
                sum_z += sin(hp);
                sum_h += cos(hp) * cos(hp);
            }
            float *svf_z = run_svf(d, &g, D, 0, SS_SVF_DEF_GEOMETRIC, SS_LINES_INTERPOLATED);
            float *svf_h = run_svf(d, &g, D, 0, SS_SVF_DEF_HORIZONTAL, SS_LINES_INTERPOLATED);
            float *svf_t = run_svf(d, &g, D, 0, SS_SVF_DEF_RADIATIVE, SS_LINES_INTERPOLATED);
            double ez = worst_interior(svf_z, &g, 2, 1 - sum_z / D);
            double eh = worst_interior(svf_h, &g, 2, sum_h / D);
            double want_t = (1 + cos(cases[i].slope * M_PI / 180)) / 2;
            double et = worst_interior(svf_t, &g, 2, want_t);
            /* The tilted cell's own plane bounds its sky on the edge too, where
             * its slope comes from heights extrapolated past the edge (aspect
             * 180: lines along the grid's axes, where an edge cell's horizons
             * are exact too; oblique lines mix samples there, doc/model.md). */
            double et_edge = cases[i].aspect == 180 ? worst_edge(svf_t, &g, want_t) : 0;
            tap_ok(ez <= 1e-5 && eh <= 1e-5 && et <= 1e-5 && et_edge <= 1e-5,
                   "tilted plane S=%g A=%g on %gx%g m cells, %s, D=%d: geometric SVF %.6f, "
                   "horizontal %.6f, radiative (1+cos S)/2 = %.6f (worst errors %.1e %.1e "
                   "%.1e; on the edge %.1e%s)",
                   cases[i].slope, cases[i].aspect, cases[i].cx, cases[i].cy, device_name(d), D,
                   1 - sum_z / D, sum_h / D, want_t, ez, eh, et, et_edge,
                   cases[i].aspect == 180 ? "" : ", not checked: oblique lines");
            /* The gradient itself on every cell but the corners: the plane's
             * (Horn and Zevenbergen-Thorne, as gdaldem -compute_edges). */
            double worst_grad = 0;
            double rise = tan(cases[i].slope * M_PI / 180), a = cases[i].aspect * M_PI / 180;
            for (int r = 0; d == 0 && r < g.height; ++r)
                for (int c = 0; c < g.width; ++c) {
                    if ((r == 0 || r == g.height - 1) && (c == 0 || c == g.width - 1))
                        continue;
                    float de[2], dn[2];
                    ss_gradient_horn(g.z, g.width, g.height, c, r, (float)g.cell_x_m,
                                     (float)g.cell_y_m, &de[0], &dn[0]);
                    ss_gradient_zt(g.z, g.width, g.height, c, r, (float)g.cell_x_m,
                                   (float)g.cell_y_m, &de[1], &dn[1]);
                    for (int k = 0; k < 2; ++k) /* downhill toward the aspect */
                        worst_grad = fmax(worst_grad, fmax(fabs(de[k] + rise * sin(a)),
                                                           fabs(dn[k] + rise * cos(a))));
                }
            if (d == 0)
                tap_ok(worst_grad <= 1e-4 * (1 + rise),
                       "tilted plane S=%g A=%g on %gx%g m cells: Horn's and Zevenbergen-Thorne's "
                       "gradient on every cell but the corners, edges included, is the plane's "
                       "(worst %.1e)",
                       cases[i].slope, cases[i].aspect, cases[i].cx, cases[i].cy, worst_grad);
            free(svf_z);
            free(svf_h);
            free(svf_t);
            ss_grid_free(&g);
        }
    /* Convergence to the continuous closed form 1 - S/pi (physics.md 6.2:
     * S = 30, D = 16 aligned gives 0.835708, half a step off 0.832141). */
    ss_grid g = tilted_plane(61, 30, 30, 30, 180);
    float *aligned = run_svf(0, &g, 16, 0, SS_SVF_DEF_GEOMETRIC, SS_LINES_INTERPOLATED);
    float *half = run_svf(0, &g, 16, 11.25, SS_SVF_DEF_GEOMETRIC, SS_LINES_INTERPOLATED);
    size_t centre = (size_t)30 * 61 + 30;
    tap_close(aligned ? aligned[centre] : NAN, 0.835708, 2e-6,
              "tilted plane S=30, D=16 aligned: physics.md 6.2 value");
    tap_close(half ? half[centre] : NAN, 0.832141, 2e-6,
              "tilted plane S=30, D=16 half a step off: physics.md 6.2 value");
    free(aligned);
    free(half);
    ss_grid_free(&g);
}

/* Conical pit: rim radius R, depth D, flat beyond the rim. From the bottom
 * the whole cone is seen at atan(D/R) (physics.md 2.4). With 4 or 8
 * directions every line passes through the bottom cell's centre and the
 * cone's radial profile is sampled exactly, so the result is exact. */
static void conical_pit(void)
{
    const int n = 121, c0 = 60;
    const double cell = 10, R = 400, D = 200;
    ss_grid g = test_grid(n, n, cell, cell);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) {
            double rho = hypot((c - c0) * cell, (r - c0) * cell);
            g.z[(size_t)r * n + c] = (float)(rho < R ? D * rho / R - D : 0.0);
        }
    double h = atan(D / R);
    size_t bottom = (size_t)c0 * n + c0;
    for (int model = 0; model < 2; ++model)
        for (int d = 0; d < 2; ++d) {
            float *z8 = run_svf(d, &g, 8, 0, SS_SVF_DEF_GEOMETRIC, model);
            float *h8 = run_svf(d, &g, 8, 0, SS_SVF_DEF_HORIZONTAL, model);
            tap_ok(z8 && h8 && fabs(z8[bottom] - (1 - sin(h))) <= 1e-5 &&
                       fabs(h8[bottom] - cos(h) * cos(h)) <= 1e-5,
                   "conical pit R=%g D=%g, %s lines, %s, D=8: bottom SVF %.6f (want 1 - D/sqrt(R^2 "
                   "+ D^2) = %.6f), horizontal %.6f (want R^2/(R^2 + D^2) = %.6f)",
                   R, D, model_name(model), device_name(d), z8 ? z8[bottom] : NAN, 1 - sin(h),
                   h8 ? h8[bottom] : NAN, cos(h) * cos(h));
            free(z8);
            free(h8);
        }
    /* Off the axes, interpolated samples pass beside the apex by at most
     * half a cell; along the cone the tangent is then low by about that
     * offset over the rim radius (0.5 cell / 40 cells), so SVF may be high
     * by cos(h) * dh, h = atan(D/R): allow 0.5/40 * cos^2(h) * cos(h). */
    double tol = 0.5 / (R / cell) * pow(cos(h), 3);
    float *z64 = run_svf(0, &g, 64, 0, SS_SVF_DEF_GEOMETRIC, SS_LINES_INTERPOLATED);
    tap_ok(z64 && fabs(z64[bottom] - (1 - sin(h))) <= tol,
           "conical pit, interpolated lines, D=64: bottom SVF %.6f, closed form %.6f +- %.4f "
           "(half-cell sampling bound)",
           z64 ? z64[bottom] : NAN, 1 - sin(h), tol);
    free(z64);
    ss_grid_free(&g);
}

/* Trench running north-south across the whole grid: floor at -D for
 * |x| < W/2, ground 0 beyond, vertical walls between cells. From the floor
 * centre the walls' tops are seen at atan(2D/W') across the trench, where
 * W' is the rim-to-rim width between the first ground samples (interpolated
 * lines ramp over the one-cell wall); along the trench the floor is flat to
 * the grid's edge, so the horizon is 0. */

/* The continuous SVFs of this finite trench seen from the floor centre, by
 * quadrature over azimuth: a direction theta from the axis meets the rim at
 * W'/2 / |sin theta| unless it leaves the grid (at `reach` cells) first, and
 * then sees only flat floor. In an infinite trench this is 1 - 2 psi / pi
 * and cos psi (physics.md 2.4); the grid's end cuts the near-axis rims. */
static void finite_trench_svf(double depth, double half_rim, double reach, double *svf_z,
                              double *svf_h)
{
    const int n = 36000;
    double sz = 0, sh = 0;
    for (int i = 0; i < n; ++i) {
        double th = (i + 0.5) * 2 * M_PI / n, s = fabs(sin(th)), c = fabs(cos(th));
        double h = half_rim * c <= reach * s ? atan(depth * s / half_rim) : 0.0;
        sz += sin(h);
        sh += cos(h) * cos(h);
    }
    *svf_z = 1 - sz / n;
    *svf_h = sh / n;
}
static void trench(void)
{
    const int n = 161, c0 = 80, half_floor = 20; /* floor cells |c - c0| <= 20 */
    const double cell = 1, D = 30;
    ss_grid g = test_grid(n, n, cell, cell);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            g.z[(size_t)r * n + c] = (float)(abs(c - c0) <= half_floor ? -D : 0.0);
    double w_rim = 2.0 * (half_floor + 1) * cell;
    double psi = atan(2 * D / w_rim);
    size_t centre = (size_t)c0 * n + c0;
    for (int model = 0; model < 2; ++model)
        for (int d = 0; d < 2; ++d) {
            /* 4 directions: two along the floor (h = 0), two at the rims. */
            float *z4 = run_svf(d, &g, 4, 0, SS_SVF_DEF_GEOMETRIC, model);
            float *h4 = run_svf(d, &g, 4, 0, SS_SVF_DEF_HORIZONTAL, model);
            double want_z = 1 - sin(psi) / 2, want_h = 0.5 + cos(psi) * cos(psi) / 2;
            tap_ok(z4 && h4 && fabs(z4[centre] - want_z) <= 1e-5 &&
                       fabs(h4[centre] - want_h) <= 1e-5,
                   "trench 2D/W'=%.4f, %s lines, %s, D=4: floor SVF %.6f (want %.6f), "
                   "horizontal %.6f (want %.6f)",
                   2 * D / w_rim, model_name(model), device_name(d), z4 ? z4[centre] : NAN,
                   want_z, h4 ? h4[centre] : NAN, want_h);
            free(z4);
            free(h4);
        }
    /* Many directions converge to the continuous values. Oblique lines meet
     * the rim between samples one cell apart across the trench; the tangent
     * is then off by up to one cell over the half-width: allow that in psi,
     * over the whole circle. */
    double want_z, want_h;
    finite_trench_svf(D, w_rim / 2, c0, &want_z, &want_h);
    double dpsi = cell / (w_rim / 2) * sin(psi) * cos(psi);
    float *z = run_svf(0, &g, 256, 0, SS_SVF_DEF_GEOMETRIC, SS_LINES_INTERPOLATED);
    float *h = run_svf(0, &g, 256, 0, SS_SVF_DEF_HORIZONTAL, SS_LINES_INTERPOLATED);
    double tol_z = dpsi + 2e-3, tol_h = 2 * dpsi + 2e-3;
    tap_ok(z && h && fabs(z[centre] - want_z) <= tol_z && fabs(h[centre] - want_h) <= tol_h,
           "trench, interpolated lines, D=256: floor SVF %.6f vs quadrature %.6f (+- %.4f), "
           "horizontal %.6f vs %.6f (+- %.4f)",
           z ? z[centre] : NAN, want_z, tol_z, h ? h[centre] : NAN, want_h, tol_h);
    free(z);
    free(h);
    ss_grid_free(&g);
}

int main(void)
{
    flat_planes();
    tilted_planes();
    conical_pit();
    trench();
    return tap_done();
}
