/* Point horizons (src/core/point_horizon.h) against the grid sweep and
 * closed forms: at every cell of random terrain with nodata holes, both
 * line models, curvature off and on, the point profile equals ss_horizon's
 * value for that cell; a site between cell centres is the bilinear mix of
 * its cells; a fine step finds a narrow peak that 1-degree directions
 * miss; an observer above a flat plane sees the plane's edge (no
 * curvature) or the dip of the sea horizon (curvature) exactly; bad sites
 * and options are refused. Then the Kilauea DEM when ../shared/data is
 * present. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_io.h"
#include "skysweep_sites.h"
#include "tap.h"
#include "testlib.h"

#define TOL_RAD 1e-5
#define DEG (M_PI / 180.0)

typedef struct {
    float *angle, *dist; /* directions x cells */
    size_t cells;
} grid_profiles;

static int keep_direction(int index, double az, const float *angle, const float *dist,
                          const float *cast, void *user)
{
    (void)cast;
    (void)az;
    grid_profiles *gp = user;
    memcpy(gp->angle + (size_t)index * gp->cells, angle, gp->cells * sizeof(float));
    memcpy(gp->dist + (size_t)index * gp->cells, dist, gp->cells * sizeof(float));
    return 1;
}

/* ss_horizon's angles and distances for every direction of opt. */
static ss_status grid_horizon(const char *device, const ss_grid *g, const ss_sweep_options *opt,
                              grid_profiles *gp)
{
    gp->cells = (size_t)g->width * g->height;
    gp->angle = malloc(sizeof(float) * gp->cells * opt->directions);
    gp->dist = malloc(sizeof(float) * gp->cells * opt->directions);
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, device);
    ss_status st = ss_horizon(ctx, g, opt, 1, keep_direction, gp);
    if (st != SS_OK)
        tap_diag("ss_horizon: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st;
}

static void grid_profiles_free(grid_profiles *gp)
{
    free(gp->angle);
    free(gp->dist);
}

static ss_point_grid *prepare(const ss_grid *g)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_point_grid *pg = NULL;
    if (ss_point_grid_new(ctx, g, &pg) != SS_OK) {
        printf("Bail out! %s\n", ss_ctx_message(ctx));
        exit(99);
    }
    ss_ctx_free(ctx);
    return pg;
}

static ss_status profile(const ss_point_grid *pg, const ss_sweep_options *opt, double col,
                         double row, double height_m, ss_point_horizon_result *out)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_point_site site = {col, row, height_m, opt->grid_north_deg};
    ss_status st = ss_point_horizon(ctx, pg, opt, &site, out);
    ss_ctx_free(ctx);
    return st;
}

static void options(ss_sweep_options *opt, int directions, double offset_deg, int model,
                    double radius_m, double grid_north_deg)
{
    ss_sweep_options_default(opt);
    opt->directions = directions;
    opt->offset_deg = offset_deg;
    opt->lines = (ss_line_model)model;
    opt->earth_radius_m = radius_m;
    opt->refraction_k = radius_m > 0 ? 0.13 : 0.0;
    opt->grid_north_deg = grid_north_deg;
}

/* Every valid cell of g: point profile == grid horizon within TOL_RAD;
 * with check_dist, the reported distance within a cell diagonal of the
 * grid's (the grid measures from the sample, the point from the cell
 * centre), allowing the rare direction where float and double pick
 * different casters of nearly equal elevation. */
static void compare_all_cells(const char *label, const char *device, const ss_grid *g,
                              const ss_sweep_options *opt, int check_dist)
{
    grid_profiles gp;
    if (!tap_ok(grid_horizon(device, g, opt, &gp) == SS_OK, "%s: grid sweep runs", label))
        return;
    ss_point_grid *pg = prepare(g);
    ss_point_horizon_result *res = malloc(sizeof *res * opt->directions);
    double worst = 0.0, diag_m = hypot(g->cell_x_m, g->cell_y_m);
    size_t compared = 0, far_dist = 0, failures = 0;
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            size_t cell = (size_t)r * g->width + c;
            if (!isfinite(g->z[cell]))
                continue;
            if (profile(pg, opt, c, r, 0.0, res) != SS_OK) {
                failures++;
                continue;
            }
            for (int i = 0; i < opt->directions; ++i) {
                double want = gp.angle[(size_t)i * gp.cells + cell];
                double err = fabs(res[i].elevation_deg - want) * DEG;
                worst = err > worst || !isfinite(err) ? err : worst;
                double dg = gp.dist[(size_t)i * gp.cells + cell];
                far_dist += fabs(res[i].distance_m - dg) > diag_m;
                compared++;
            }
        }
    tap_ok(worst <= TOL_RAD && !failures,
           "%s: point == grid on %zu cell-directions, worst %.2e rad", label, compared, worst);
    if (check_dist)
        tap_ok(far_dist * 1000 <= compared,
               "%s: distance within a cell diagonal of the grid's: %zu of %zu beyond", label,
               far_dist, compared);
    free(res);
    ss_point_grid_free(pg);
    grid_profiles_free(&gp);
}

static void equal_to_grid(void)
{
    ss_grid g = test_grid(97, 61, 30, 25);
    test_fill(&g, TERRAIN_SMOOTH, 5, 500);
    test_holes(&g, 9, 6, 7);
    g.z_origin_m = 812.0;
    ss_sweep_options opt;
    for (int model = 0; model < 2; ++model) {
        char label[160];
        const char *name = model ? "digital" : "interpolated";
        options(&opt, 24, 7.3, model, 0, 0);
        snprintf(label, sizeof label, "smooth 97x61 with holes, %s, 24 directions", name);
        compare_all_cells(label, NULL, &g, &opt, 1);
        options(&opt, 13, 2.9, model, 0, 1.7);
        snprintf(label, sizeof label, "same, %s, C twin, grid north 1.7 deg", name);
        compare_all_cells(label, "reference", &g, &opt, 1);
    }
    ss_grid_free(&g);
    /* Curvature matters at km scale: 1 km cells, lines of 100 km. */
    g = test_grid(83, 67, 1000, 1000);
    test_fill(&g, TERRAIN_SMOOTH, 42, 1500);
    test_holes(&g, 43, 5, 6);
    for (int model = 0; model < 2; ++model) {
        char label[160];
        options(&opt, 16, 11.0, model, 6371000.0, 0);
        snprintf(label, sizeof label, "smooth 83x67 (1 km cells), %s, curvature on",
                 model ? "digital" : "interpolated");
        compare_all_cells(label, NULL, &g, &opt, 1);
    }
    ss_grid_free(&g);
    /* Plateaus: long runs of exact ties, where float (grid) and double
     * (point) rounding may pick different ones of equal casters, so only
     * the elevation is compared. */
    g = test_grid(60, 50, 1, 1);
    test_fill(&g, TERRAIN_PLATEAUS, 3, 4);
    options(&opt, 16, 0.0, SS_LINES_INTERPOLATED, 0, 0);
    compare_all_cells("plateaus 60x50 (exact ties), interpolated", NULL, &g, &opt, 0);
    ss_grid_free(&g);
}

/* Between cell centres the profile is the bilinear mix of the four cells'
 * grid horizons; a nodata neighbour drops out, the others renormalised,
 * and so, per direction, does a cell with nothing ahead (-90): -90 only
 * where all have nothing ahead. */
static void between_cells(void)
{
    ss_grid g = test_grid(70, 60, 30, 30);
    test_fill(&g, TERRAIN_SMOOTH, 17, 400);
    g.z[(size_t)31 * g.width + 41] = NAN;
    g.z_origin_m = 100.0;
    ss_sweep_options opt;
    options(&opt, 12, 4.0, SS_LINES_INTERPOLATED, 0, 0);
    grid_profiles gp;
    if (!tap_ok(grid_horizon(NULL, &g, &opt, &gp) == SS_OK, "grid sweep for bilinear sites"))
        return;
    ss_point_grid *pg = prepare(&g);
    ss_point_horizon_result res[12];
    const double sites[][2] = {{20.3, 30.6}, {40.25, 30.5}, {0.0, 45.7}, {69.4, 59.4}};
    for (size_t s = 0; s < sizeof sites / sizeof sites[0]; ++s) {
        double col = sites[s][0], row = sites[s][1];
        int c0 = (int)floor(col), r0 = (int)floor(row);
        double worst = 0.0;
        ss_status st = profile(pg, &opt, col, row, 0.0, res);
        for (int i = 0; i < opt.directions && st == SS_OK; ++i) {
            double sum = 0.0, wsum = 0.0;
            for (int k = 0; k < 4; ++k) {
                int c = c0 + (k & 1), r = r0 + (k >> 1);
                double w =
                    ((k & 1) ? col - c0 : 1 - (col - c0)) * ((k >> 1) ? row - r0 : 1 - (row - r0));
                if (w <= 0 || c >= g.width || r >= g.height ||
                    !isfinite(g.z[(size_t)r * g.width + c]))
                    continue;
                double a = gp.angle[(size_t)i * gp.cells + (size_t)r * g.width + c];
                if (a == -90.0)
                    continue;
                sum += w * a;
                wsum += w;
            }
            double err = fabs(res[i].elevation_deg - (wsum > 0 ? sum / wsum : -90.0)) * DEG;
            worst = err > worst ? err : worst;
        }
        tap_ok(st == SS_OK && worst <= TOL_RAD,
               "site at column %g, row %g == bilinear mix of its cells' grid horizons: worst %.2e "
               "rad",
               col, row, worst);
    }
    ss_ctx *ctx = ss_ctx_new();
    double h = 0;
    ss_status st = ss_point_ground_height(ctx, pg, 20.5, 30.25, &h);
    h -= g.z_origin_m;
    float *z = g.z;
    double want = 0.375 * z[30 * 70 + 20] + 0.375 * z[30 * 70 + 21] + 0.125 * z[31 * 70 + 20] +
                  0.125 * z[31 * 70 + 21];
    tap_ok(st == SS_OK && fabs(h - want) < 1e-9, "ground height is bilinear: %.9g, want %.9g", h,
           want);
    ss_ctx_free(ctx);
    ss_point_grid_free(pg);
    grid_profiles_free(&gp);
    ss_grid_free(&g);
}

/* A one-cell spike 1.8 km away at azimuth 37.57 deg, 0.43 and 0.57 deg from
 * the 1-degree directions: their lines pass more than a cell beside it. */
static void narrow_peak(void)
{
    ss_grid g = test_grid(401, 401, 10, 10);
    for (size_t i = 0; i < (size_t)401 * 401; ++i)
        g.z[i] = 0.0f;
    int sc = 200 + 110, sr = 200 - 143;
    g.z[(size_t)sr * 401 + sc] = 100.0f;
    double peak_az = atan2(110.0, 143.0) / DEG, peak_d = 10.0 * hypot(110.0, 143.0);
    double peak_elev = atan(100.0 / peak_d) / DEG;
    ss_point_grid *pg = prepare(&g);
    ss_sweep_options fine, coarse;
    options(&fine, 3600, 0.0, SS_LINES_INTERPOLATED, 0, 0);
    options(&coarse, 360, 0.0, SS_LINES_INTERPOLATED, 0, 0);
    ss_point_horizon_result *res = malloc(sizeof *res * 3600);
    double fine_max = -90, fine_az = 0, fine_dist = 0, coarse_max = -90;
    profile(pg, &fine, 200, 200, 0.0, res);
    for (int i = 0; i < 3600; ++i)
        if (res[i].elevation_deg > fine_max) {
            fine_max = res[i].elevation_deg;
            fine_az = res[i].azimuth_deg;
            fine_dist = res[i].distance_m;
        }
    profile(pg, &coarse, 200, 200, 0.0, res);
    for (int i = 0; i < 360; ++i)
        coarse_max = res[i].elevation_deg > coarse_max ? res[i].elevation_deg : coarse_max;
    tap_ok(fine_max > 0.85 * peak_elev && fabs(fine_az - peak_az) < 0.1 &&
               fabs(fine_dist - peak_d) < 10,
           "0.1-degree step resolves a one-cell peak (%.4f deg at az %.3f, %.1f m): max %.4f deg "
           "at az %.1f, %.1f m",
           peak_elev, peak_az, peak_d, fine_max, fine_az, fine_dist);
    tap_ok(coarse_max == 0.0, "1-degree directions miss it: max %.6f deg", coarse_max);
    /* And the grid product, swept at that fine azimuth, agrees. */
    ss_sweep_options one;
    options(&one, 1, fine_az, SS_LINES_INTERPOLATED, 0, 0);
    grid_profiles gp;
    if (grid_horizon(NULL, &g, &one, &gp) == SS_OK) {
        double grid_deg = gp.angle[(size_t)200 * 401 + 200];
        tap_ok(fabs(grid_deg - fine_max) * DEG <= TOL_RAD,
               "grid sweep at azimuth %.1f gives the same %.6f deg at the site", fine_az, grid_deg);
        grid_profiles_free(&gp);
    } else {
        tap_ok(0, "grid sweep at the peak's azimuth");
    }
    free(res);
    ss_point_grid_free(pg);
    ss_grid_free(&g);
}

/* Observer h above a flat plane, no curvature: every occluder lies h below
 * the eye, so the best slope -h/d is the farthest occluding sample's. On
 * the axes and diagonals of square cells the sample lines run through
 * cell centres, and that sample is the last cell centre before the edge:
 * elevation = atan(-h / d_edge) exactly. */
static void observer_flat(void)
{
    const int w = 101, ht = 81, c = 30, r = 20;
    const double cell = 30.0, h = 2.0;
    ss_grid g = test_grid(w, ht, cell, cell);
    for (size_t i = 0; i < (size_t)w * ht; ++i)
        g.z[i] = 50.0f;
    ss_point_grid *pg = prepare(&g);
    for (int model = 0; model < 2; ++model) {
        ss_sweep_options opt;
        options(&opt, 8, 0.0, model, 0, 0);
        ss_point_horizon_result res[8];
        ss_status st = profile(pg, &opt, c, r, h, res);
        /* Steps to the edge toward N, NE, E, SE, S, SW, W, NW. */
        const int steps[8] = {r,          r < w - 1 - c ? r : w - 1 - c,
                              w - 1 - c,  ht - 1 - r < w - 1 - c ? ht - 1 - r : w - 1 - c,
                              ht - 1 - r, ht - 1 - r < c ? ht - 1 - r : c,
                              c,          r < c ? r : c};
        double worst = 0.0;
        for (int i = 0; i < 8 && st == SS_OK; ++i) {
            double d_edge = steps[i] * cell * (i % 2 ? M_SQRT2 : 1.0);
            double err = fabs(res[i].elevation_deg * DEG - atan(-h / d_edge));
            worst = err > worst ? err : worst;
        }
        tap_ok(st == SS_OK && worst < 1e-9,
               "%s: eye 2 m over a flat plane sees atan(-h/d_edge) on axes and diagonals: worst "
               "%.2e rad",
               model ? "digital" : "interpolated", worst);
        options(&opt, 360, 0.5, model, 0, 0);
        ss_point_horizon_result all[360];
        st = profile(pg, &opt, c, r, h, all);
        double highest = -90, lowest = 90;
        for (int i = 0; i < 360 && st == SS_OK; ++i) {
            highest = all[i].elevation_deg > highest ? all[i].elevation_deg : highest;
            lowest = all[i].elevation_deg < lowest ? all[i].elevation_deg : lowest;
        }
        /* Every sample lies within a cell of the site: its last occluder
         * is at least 19 cells away (the north edge) and at most a cell
         * and a half beyond the farthest corner. */
        tap_ok(st == SS_OK && highest < 0 &&
                   highest <= atan(-h / ((hypot(70, 60) + 1.5) * cell)) / DEG &&
                   lowest >= atan(-h / (r * cell - cell)) / DEG,
               "%s: over 360 directions nothing rises above the plane: %.5f to %.5f deg",
               model ? "digital" : "interpolated", lowest, highest);
    }
    ss_ctx *ctx = ss_ctx_new();
    double ground = 0;
    ss_status st = ss_point_ground_height(ctx, pg, c + 0.3, r - 0.2, &ground);
    tap_ok(st == SS_OK && ground == 50.0, "ground height on the plane: %g m", ground);
    ss_ctx_free(ctx);
    ss_point_grid_free(pg);
    ss_grid_free(&g);
}

/* With curvature the eye h above a flat plane sees its farthest point
 * where (-h - k d^2) / d peaks, d* = sqrt(h / k), the dip of the sea
 * horizon: elevation = atan(-2 sqrt(h k)) = atan(-sqrt(2 h / R_eff)),
 * in every direction while d* (5.4 km for 2 m) lies inside the grid. */
static void observer_curved(void)
{
    ss_grid g = test_grid(401, 401, 30, 30);
    for (size_t i = 0; i < (size_t)401 * 401; ++i)
        g.z[i] = 0.0f;
    ss_point_grid *pg = prepare(&g);
    ss_sweep_options opt;
    options(&opt, 360, 0.25, SS_LINES_INTERPOLATED, 6371000.0, 0);
    const double h = 2.0;
    /* The k the sweep uses (float, products_common.c). */
    double k = (float)(0.5 * (1.0 - opt.refraction_k) / opt.earth_radius_m);
    double want = atan(-2.0 * sqrt(h * k)), worst = 0.0, d_worst = 0.0;
    ss_point_horizon_result res[360];
    ss_status st = profile(pg, &opt, 200, 200, h, res);
    for (int i = 0; i < 360 && st == SS_OK; ++i) {
        double err = fabs(res[i].elevation_deg * DEG - want);
        worst = err > worst ? err : worst;
        double d_err = fabs(res[i].distance_m - sqrt(h / k));
        d_worst = d_err > d_worst ? d_err : d_worst;
    }
    tap_ok(st == SS_OK && worst < 1e-7 && d_worst < 45,
           "curvature: eye 2 m over a flat plane sees the dip %.6f deg at %.0f m in all 360 "
           "directions: worst %.2e rad, distance off by %.1f m",
           want / DEG, sqrt(h / k), worst, d_worst);
    ss_point_grid_free(pg);
    ss_grid_free(&g);
}

static void refusals(void)
{
    ss_grid g = test_grid(20, 10, 5, 5);
    test_fill(&g, TERRAIN_SMOOTH, 1, 20);
    g.z[3 * 20 + 4] = NAN;
    ss_point_grid *pg = prepare(&g);
    ss_sweep_options opt;
    options(&opt, 8, 0.0, SS_LINES_INTERPOLATED, 0, 0);
    ss_point_horizon_result res[8];
    const struct {
        double col, row, height_m;
        const char *what;
    } bad[] = {{-0.6, 5, 0, "west of the grid"},
               {19.51, 5, 0, "east of the grid"},
               {3, 9.6, 0, "south of the grid"},
               {NAN, 3, 0, "NaN column"},
               {4.4, 2.6, 0, "on a nodata cell"},
               {5, 5, -1, "negative observer height"},
               {5, 5, INFINITY, "infinite observer height"}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        ss_ctx *ctx = ss_ctx_new();
        ss_point_site site = {bad[i].col, bad[i].row, bad[i].height_m, 0};
        ss_status st = ss_point_horizon(ctx, pg, &opt, &site, res);
        tap_ok(st == SS_ERR_ARGUMENT && ss_ctx_message(ctx)[0], "site %s is refused: %s",
               bad[i].what, ss_ctx_message(ctx));
        ss_ctx_free(ctx);
    }
    ss_ctx *ctx = ss_ctx_new();
    ss_point_site edge = {-0.5, 9.5, 0, 0};
    tap_ok(ss_point_horizon(ctx, pg, &opt, &edge, res) == SS_OK,
           "a site on the grid's outer corner is accepted %s", ss_ctx_message(ctx));
    opt.directions = 0;
    tap_ok(ss_point_horizon(ctx, pg, &opt, &edge, res) == SS_ERR_ARGUMENT,
           "zero directions are refused: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    ss_point_grid_free(pg);
    ss_grid_free(&g);
}

static void kilauea(void)
{
    const char *path = test_shared_data("hawaii_kilauea_utm5n_30m.tif");
    if (!path) {
        tap_skip("Kilauea DEM, point == grid", "../shared/data is absent");
        return;
    }
    ss_ctx *ctx = ss_ctx_new();
    ss_dem dem;
    const char *paths[] = {path};
    if (!tap_ok(ss_dem_read(ctx, paths, 1, NULL, &dem) == SS_OK, "read Kilauea DEM %s",
                ss_ctx_message(ctx))) {
        ss_ctx_free(ctx);
        return;
    }
    const ss_grid *g = &dem.grid;
    ss_point_grid *pg = prepare(g);
    for (int model = 0; model < 2; ++model) {
        ss_sweep_options opt;
        options(&opt, 2, 33.3, model, model ? 6371000.0 : 0.0, 0.8);
        grid_profiles gp;
        if (grid_horizon(NULL, g, &opt, &gp) != SS_OK) {
            tap_ok(0, "Kilauea grid sweep");
            continue;
        }
        double worst = 0.0;
        int sites = 0;
        unsigned s = 12345;
        ss_point_horizon_result res[2];
        while (sites < 400) {
            s = s * 1664525u + 1013904223u;
            int c = (int)((s >> 8) % (unsigned)g->width);
            s = s * 1664525u + 1013904223u;
            int r = (int)((s >> 8) % (unsigned)g->height);
            size_t cell = (size_t)r * g->width + c;
            if (!isfinite(g->z[cell]))
                continue;
            sites++;
            if (profile(pg, &opt, c, r, 0.0, res) != SS_OK) {
                worst = INFINITY;
                continue;
            }
            for (int i = 0; i < 2; ++i) {
                double err = fabs(res[i].elevation_deg - gp.angle[(size_t)i * gp.cells + cell]);
                worst = err * DEG > worst ? err * DEG : worst;
            }
        }
        tap_ok(worst <= TOL_RAD,
               "Kilauea 857x793, %s, curvature %s: point == grid at %d random cells, worst %.2e "
               "rad",
               model ? "digital" : "interpolated", model ? "on" : "off", sites, worst);
        grid_profiles_free(&gp);
    }
    ss_point_grid_free(pg);
    ss_dem_free(&dem);
    ss_ctx_free(ctx);
}

int main(void)
{
    equal_to_grid();
    between_cells();
    narrow_peak();
    observer_flat();
    observer_curved();
    refusals();
    kilauea();
    return tap_done();
}
