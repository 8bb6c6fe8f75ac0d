/* The continuous reference (reference_march.c) against closed forms
 * (reference/physics.md sec. 2.4 and 5) on shapes whose bilinear surface is
 * the shape itself, so the reference must reproduce them to rounding:
 * flat planes, tilted planes (square and 30 x 10 m cells), a V-valley with
 * its axis on a column of centres, a trench whose walls are one-cell ramps,
 * a cliff seen over curved ground, nodata masking; then its own step is
 * shown converged and its shortcuts (stop or skip a block once nothing farther can win)
 * shown exact. It shares no code with kernels/ or src/core: the library is
 * used only to allocate grids (testlib) and, at the end, to show that
 * the sweep agrees with it where both sample the same points and converges
 * to it elsewhere. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "reference_march.h"
#include "tap.h"
#include "testlib.h"

#define N_AZ 3600

static void flat_planes(void)
{
    const double heights[] = {0.0, 8848.0, -430.0, 1e5};
    for (int i = 0; i < 4; ++i) {
        ss_grid g = test_grid(31, 25, 30, 30);
        for (int k = 0; k < 31 * 25; ++k)
            g.z[k] = (float)heights[i];
        ref_march rm;
        ref_march_init(&rm, &g, 0, 0);
        double worst_h = 0, svf[3], worst_svf = 0;
        for (int a = 0; a < 360; a += 7)
            worst_h = fmax(worst_h, fabs(ref_horizon_deg(&rm, 12, 10, a + 0.3, NULL)));
        ref_svf(&rm, 12, 10, N_AZ, 0, svf, NULL);
        for (int d = 0; d < 3; ++d)
            worst_svf = fmax(worst_svf, fabs(svf[d] - 1));
        /* A cell on the west edge looking west has nothing ahead. */
        double out = ref_horizon_deg(&rm, 0, 10, 270, NULL);
        tap_ok(worst_h == 0 && worst_svf < 1e-12 && out == -90,
               "flat plane at %g m: horizon 0 (worst %g), SVF 1 in all definitions (worst %g), "
               "-90 looking off the grid (%g)",
               heights[i], worst_h, worst_svf, out);
        ref_march_free(&rm);
        ss_grid_free(&g);
    }
}

/* Plane of slope S facing aspect A on n x n cells of cx x cy metres. */
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

static void tilted_planes(void)
{
    const struct {
        double cx, cy, slope, aspect;
    } cases[] = {{30, 30, 30, 180}, {30, 30, 10, 63}, {30, 10, 45, 120}};
    for (int i = 0; i < 3; ++i) {
        const int n = 41;
        ss_grid g = tilted_plane(n, cases[i].cx, cases[i].cy, cases[i].slope, cases[i].aspect);
        ref_march rm;
        ref_march_init(&rm, &g, 0, 0);
        double t = tan(cases[i].slope * M_PI / 180), worst = 0;
        /* Every point of the plane ahead is seen at atan(rise): uphill and
         * downhill (negative) alike, at any distance. */
        for (int a = 0; a < 360; a += 5) {
            double az = a + 0.37;
            double want = atan(-t * cos((az - cases[i].aspect) * M_PI / 180)) * 180 / M_PI;
            worst = fmax(worst, fabs(ref_horizon_deg(&rm, 17, 22, az, NULL) - want));
        }
        /* float32 heights of up to ~700 m round by 3e-5 m over >= 10 m. */
        tap_ok(worst < 1e-4,
               "tilted plane S=%g A=%g on %gx%g m cells: horizon = atan(rise) in 72 "
               "azimuths (worst %.2e deg)",
               cases[i].slope, cases[i].aspect, cases[i].cx, cases[i].cy, worst);
        /* Continuous closed forms (physics.md 2.4): 1 - S/pi; horizontal
         * and tilted (convention A) both (1 + cos S)/2. The rectangle rule
         * at 3600 azimuths errs by ~1e-8 at the kinks of h+ (6.2). */
        double svf[3], s = cases[i].slope * M_PI / 180;
        ref_svf(&rm, 20, 20, N_AZ, 0, svf, NULL);
        double want[3] = {1 - s / M_PI, (1 + cos(s)) / 2, (1 + cos(s)) / 2};
        tap_ok(fabs(svf[0] - want[0]) < 1e-5 && fabs(svf[1] - want[1]) < 1e-5 &&
                   fabs(svf[2] - want[2]) < 1e-5,
               "tilted plane S=%g: SVF geometric %.6f (1 - S/pi = %.6f), horizontal %.6f and "
               "tilted %.6f ((1 + cos S)/2 = %.6f)",
               cases[i].slope, svf[0], want[0], svf[1], svf[2], want[1]);
        ref_march_free(&rm);
        ss_grid_free(&g);
    }
}

/* V-valley of side slope alpha, axis north-south on the centre column: the
 * surface depends on the column only and kinks on a column of centres, so
 * the bilinear surface is the V. From the bottom, h = atan(tan a |sin phi|)
 * to any distance; SVF_Z = 1 - 2a/pi, SVF_D = cos a (physics.md 2.4). */
static void v_valley(void)
{
    const int n = 61, c0 = 30;
    const double alpha = 30 * M_PI / 180;
    ss_grid g = test_grid(n, n, 10, 10);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            g.z[(size_t)r * n + c] = (float)(tan(alpha) * abs(c - c0) * 10);
    ref_march rm;
    ref_march_init(&rm, &g, 0, 0);
    double worst = 0;
    for (int a = 0; a < 360; a += 3) {
        double want = atan(tan(alpha) * fabs(sin(a * M_PI / 180))) * 180 / M_PI;
        worst = fmax(worst, fabs(ref_horizon_deg(&rm, c0, 30, a, NULL) - want));
    }
    double svf[3];
    ref_svf(&rm, c0, 30, N_AZ, 0, svf, NULL);
    tap_ok(worst < 1e-5 && fabs(svf[0] - (1 - 2 * alpha / M_PI)) < 1e-5 &&
               fabs(svf[1] - cos(alpha)) < 1e-5 && fabs(svf[2] - cos(alpha)) < 1e-5,
           "V-valley a=30 deg, bottom: horizon atan(tan a |sin phi|) (worst %.1e deg); SVF "
           "geometric %.6f (want %.6f), horizontal %.6f and tilted %.6f (want cos a = %.6f)",
           worst, svf[0], 1 - 2 * alpha / M_PI, svf[1], svf[2], cos(alpha));
    ref_march_free(&rm);
    ss_grid_free(&g);
}

/* Trench along the columns: floor -D for |c - c0| <= 20, ground 0 beyond;
 * the bilinear wall is a one-cell ramp whose top (the rim) lies on the
 * column of centres 21 cells out, where the ray is sampled exactly. From
 * the floor centre a ray at theta from the axis leaves the grid's end (80
 * cells along the axis) x_end = 80 tan theta cells across it. If x_end >= 21
 * it meets the rim at 21 / |sin theta| and sees it at
 * atan(D |sin theta| / 21) (beyond, the ground only falls away in angle);
 * if x_end <= 20 it sees flat floor only, 0; in between it ends on the ramp,
 * whose angle grows outward, so its end point casts the horizon. */
static double trench_horizon_deg(double theta, double D, double half_rim, double reach)
{
    double s = fabs(sin(theta)), c = fabs(cos(theta));
    double x_end = c > 0 ? reach * s / c : INFINITY;
    if (x_end >= half_rim)
        return atan(D * s / half_rim) * 180 / M_PI;
    if (x_end <= half_rim - 1)
        return 0.0;
    return atan(D * (x_end - (half_rim - 1)) / (reach / c)) * 180 / M_PI;
}

static void trench(void)
{
    const int n = 161, c0 = 80;
    const double D = 30, half_rim = 21, reach = 80;
    ss_grid g = test_grid(n, n, 1, 1);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            g.z[(size_t)r * n + c] = (float)(abs(c - c0) <= 20 ? -D : 0.0);
    ref_march rm;
    ref_march_init(&rm, &g, 0, 0);
    static double h[N_AZ], want_h[N_AZ];
    double worst = 0;
    for (int i = 0; i < N_AZ; ++i) {
        want_h[i] = trench_horizon_deg(i * 2 * M_PI / N_AZ, D, half_rim, reach);
        h[i] = ref_horizon_deg(&rm, c0, c0, i * 360.0 / N_AZ, NULL);
        worst = fmax(worst, fabs(h[i] - want_h[i]));
    }
    double svf[3], want[3];
    ref_svf(&rm, c0, c0, N_AZ, 0, svf, NULL);
    ref_svf_from_horizons(want_h, N_AZ, 0, 0, 0, want);
    tap_ok(worst < 1e-5 && fabs(svf[0] - want[0]) < 1e-6 && fabs(svf[1] - want[1]) < 1e-6,
           "trench 2D/W'=%.4f: floor-centre horizon = rim angle or 0 in %d azimuths (worst "
           "%.1e deg); SVF geometric %.6f, horizontal %.6f (closed-form horizons: %.6f, %.6f)",
           D / half_rim, N_AZ, worst, svf[0], svf[1], want[0], want[1]);
    ref_march_free(&rm);
    ss_grid_free(&g);
}

/* A 1000 m cliff 5 km east of a cell, 1 km cells: with curvature the top
 * is lowered by d^2/(2 R_eff) (physics.md 5; r.horizon's ring wall gives
 * 0.197017 rad at 5000.04 m with R = 6371 km and no refraction). Beyond
 * the edge the plateau only falls away, so the edge casts the horizon. */
static void cliff_with_curvature(void)
{
    const int n = 21;
    ss_grid g = test_grid(n, n, 1000, 1000);
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c)
            g.z[(size_t)r * n + c] = c >= 15 ? 1000.0f : 0.0f;
    const double R = 6371000.0, ks[2] = {0.0, 0.13};
    for (int i = 0; i < 2; ++i) {
        double curv_k = 0.5 * (1 - ks[i]) / R, dist;
        ref_march rm;
        ref_march_init(&rm, &g, curv_k, 0);
        double h = ref_horizon_deg(&rm, 10, 10, 90, &dist);
        double want = atan((1000 - 5000.0 * 5000.0 * curv_k) / 5000.0) * 180 / M_PI;
        tap_ok(fabs(h - want) < 1e-9 && dist == 5000,
               "cliff 1000 m at 5 km, curvature R=6371 km k=%g: horizon %.9f deg (want %.9f, "
               "%.6f rad), cast at %g m",
               ks[i], h, want, want * M_PI / 180, dist);
        ref_march_free(&rm);
    }
    ss_grid_free(&g);
}

static void nodata(void)
{
    /* Holes in a tilted plane only remove samples: every remaining one is
     * still on the plane. */
    ss_grid g = tilted_plane(41, 30, 30, 20, 200);
    test_holes(&g, 3, 12, 5);
    g.z[20 * 41 + 20] = 0.0f;
    ref_march rm;
    ref_march_init(&rm, &g, 0, 0);
    double t = tan(20 * M_PI / 180), worst = 0;
    int none = 0;
    for (int a = 0; a < 360; a += 5) {
        double h = ref_horizon_deg(&rm, 20, 20, a, NULL);
        if (h == -90) {
            none++;
            continue;
        }
        worst = fmax(worst, fabs(h - atan(-t * cos((a - 200) * M_PI / 180)) * 180 / M_PI));
    }
    tap_ok(worst < 1e-4 && none == 0,
           "tilted plane with 12 nodata holes: horizons still atan(rise) (worst %.1e deg, %d "
           "azimuths with nothing ahead)",
           worst, none);
    double nd = ref_horizon_deg(&rm, 0, 0, 0, NULL);
    int hole = -1;
    for (int k = 0; k < 41 * 41 && hole < 0; ++k)
        hole = isfinite(g.z[k]) ? -1 : k;
    double at_hole = ref_horizon_deg(&rm, hole % 41, hole / 41, 45, NULL);
    tap_ok(nd == -90 && isnan(at_hole), "nothing ahead gives -90 (%g), a nodata cell NAN (%g)", nd,
           at_hole);
    ref_march_free(&rm);
    ss_grid_free(&g);

    /* A sample whose stencil touches nodata is skipped: a 50 m column with
     * a nodata cell right behind it, seen along the row from 5 cells west,
     * casts its horizon at its own centre. All-nodata surroundings: -90. */
    g = test_grid(15, 3, 10, 10);
    for (int k = 0; k < 45; ++k)
        g.z[k] = 0.0f;
    g.z[15 + 8] = 50.0f;
    g.z[15 + 9] = NAN;
    ref_march_init(&rm, &g, 0, 0);
    double dist, h = ref_horizon_deg(&rm, 3, 1, 90, &dist);
    tap_close(h, atan(50.0 / 50.0) * 180 / M_PI, 1e-12,
              "column beside a nodata cell: horizon 45 deg from 5 cells");
    for (int k = 0; k < 45; ++k)
        g.z[k] = NAN;
    g.z[15 + 7] = 10.0f;
    ref_march_free(&rm);
    ref_march_init(&rm, &g, 0, 0);
    int all_none = 1;
    for (int a = 0; a < 360; a += 15)
        all_none &= ref_horizon_deg(&rm, 7, 1, a, NULL) == -90;
    tap_ok(all_none, "a single valid cell among nodata: -90 in every azimuth");
    ref_march_free(&rm);
    ss_grid_free(&g);
}

/* The step of 1/8 cell against 1/64 on rough smooth terrain: the
 * reference's own discretisation must sit far below the errors it is used
 * to measure (the sweep's at 360 directions are tenths of a degree at worst
 * on such terrain). And the shortcuts are exact: marching every ray to the edge
 * must give the same angles. */
static void converged_and_exact(void)
{
    /* Cell sizes that are no round numbers (as a projected DEM's ground
     * sizes are), so ray positions carry rounding. */
    ss_grid g = test_grid(120, 90, 29.9918999284, 30.0007123);
    test_fill(&g, TERRAIN_SMOOTH, 11, 150);
    ref_march coarse, fine, full;
    ref_march_init(&coarse, &g, 0, 0);
    ref_march_init(&fine, &g, 0, 1.0 / 64);
    ref_march_init(&full, &g, 0, 0);
    full.no_shortcuts = 1;
    double worst_step = 0, mean_step = 0, worst_prune = 0;
    int n = 0;
    for (int k = 0; k < 60; ++k) {
        int c = 10 + (k * 37) % 100, r = 10 + (k * 53) % 70;
        for (int a = 0; a < 8; ++a) {
            double az = k * 7.3 + a * 45.0 + 0.1;
            double h = ref_horizon_deg(&coarse, c, r, az, NULL);
            double e = fabs(h - ref_horizon_deg(&fine, c, r, az, NULL));
            worst_step = fmax(worst_step, e);
            mean_step += e;
            worst_prune = fmax(worst_prune, fabs(h - ref_horizon_deg(&full, c, r, az, NULL)));
            n++;
        }
    }
    mean_step /= n;
    tap_ok(worst_step < 0.02 && mean_step < 0.002,
           "step 1/8 cell vs 1/64 on smooth 150 m relief: mean %.2e deg, worst %.2e deg over %d "
           "rays",
           mean_step, worst_step, n);
    tap_ok(worst_prune == 0,
           "the shortcuts (stop, or skip an 8 x 8 block, once nothing farther can rise above "
           "the best slope) change nothing (worst %g deg)",
           worst_prune);

    /* Along a row or column of centres the bilinear surface is the linear
     * interpolation between them, whose steepest points are the centres:
     * the sweep's samples. There the two must agree to float rounding. */
    double worst_axis = 0;
    float *angle = malloc(sizeof(float) * 120 * 90);
    for (int i = 0; i < 4; ++i) {
        char err[300];
        if (test_lib_horizon(NULL, &g, i * 90.0, 0, 0, SS_LINES_INTERPOLATED, angle, NULL, err,
                             sizeof err) != SS_OK) {
            worst_axis = INFINITY;
            continue;
        }
        for (int k = 0; k < 60; ++k) {
            int c = 10 + (k * 37) % 100, r = 10 + (k * 53) % 70;
            worst_axis = fmax(worst_axis, fabs(angle[r * 120 + c] -
                                               ref_horizon_deg(&coarse, c, r, i * 90.0, NULL)));
        }
    }
    free(angle);
    tap_ok(worst_axis < 1e-4,
           "along rows and columns the sweep's samples are the bilinear surface's kinks: "
           "reference == sweep to %.1e deg",
           worst_axis);
    ref_march_free(&coarse);
    ref_march_free(&fine);
    ref_march_free(&full);
    ss_grid_free(&g);
}

/* At other azimuths the sweep samples the surface differently (across its
 * lines, and only where they cross a row or column), so it differs from the
 * reference by a discretisation error that must shrink with the cells: the
 * same smooth surface sampled at 30, 15 and 7.5 m. */
static void sweep_converges(void)
{
    double err[3];
    for (int level = 0; level < 3; ++level) {
        int k = 1 << level, W = 120 * k, H = 90 * k;
        double cell = 30.0 / k;
        ss_grid g = test_grid(W, H, cell, cell);
        for (int r = 0; r < H; r++)
            for (int c = 0; c < W; c++) {
                double x = c / (double)k, y = r / (double)k; /* in 30 m cells */
                g.z[(size_t)r * W + c] =
                    (float)(150 * sin(0.21 * x + 0.13 * y + 1) +
                            75 * sin(-0.05 * x + 0.27 * y + 2) + 50 * sin(0.29 * x - 0.1 * y));
            }
        ref_march rm;
        ref_march_init(&rm, &g, 0, 0);
        float *a = malloc(sizeof(float) * W * H);
        char msg[300];
        double sum = 0;
        int n = 0;
        for (int i = 0; i < 4; ++i) {
            double az = 52.5 + 90 * i;
            if (test_lib_horizon(NULL, &g, az, 0, 0, SS_LINES_INTERPOLATED, a, NULL, msg,
                                 sizeof msg) != SS_OK) {
                sum = INFINITY;
                continue;
            }
            for (int q = 0; q < 60; ++q) {
                int c = (10 + (q * 37) % 100) * k, r = (10 + (q * 53) % 70) * k;
                sum += fabs(a[(size_t)r * W + c] - ref_horizon_deg(&rm, c, r, az, NULL));
                n++;
            }
        }
        err[level] = sum / n;
        free(a);
        ref_march_free(&rm);
        ss_grid_free(&g);
    }
    tap_ok(err[1] < 0.6 * err[0] && err[2] < 0.6 * err[1],
           "the sweep converges to the reference as cells shrink: mean |difference| %.3f, "
           "%.3f, %.3f deg at 30, 15, 7.5 m",
           err[0], err[1], err[2]);
}

int main(void)
{
    flat_planes();
    tilted_planes();
    v_valley();
    trench();
    cliff_with_curvature();
    nodata();
    converged_and_exact();
    sweep_converges();
    return tap_done();
}
