/* The sweep (OpenCL kernels and the C twin) against an independent brute
 * force of the same discrete model, on every cell: random terrain of several
 * kinds and sizes, plateaus with exact ties, nodata holes, all quadrants and
 * the axis and diagonal directions, curvature off and on; then the Kilauea
 * DEM when ../shared/data is present. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "dem_io.h"
#include "tap.h"
#include "testlib.h"

#define TOL_RAD 1e-5

typedef struct {
    double max_angle_err; /* worst |library - brute| over valid cells, rad */
    size_t bad_nodata;    /* nodata handled wrongly */
    size_t bad_caster;    /* reported distance names no cell casting the horizon */
    size_t cells;
    char error[600];
} comparison;

static const char *model_name(int model)
{
    return model == SS_LINE_MODEL_DIGITAL ? "digital lines" : "interpolated lines";
}

static void compare(const char *device, const ss_grid *g, double az, double radius, double k,
                    int model, comparison *cmp)
{
    size_t n = (size_t)g->width * g->height;
    float *angle = malloc(n * sizeof *angle), *dist = malloc(n * sizeof *dist);
    double *ref = malloc(n * sizeof *ref), *near = malloc(n * sizeof *near),
           *claimed = malloc(n * sizeof *claimed);
    memset(cmp, 0, sizeof *cmp);
    if (test_lib_horizon(device, g, az, radius, k, model, angle, dist, cmp->error,
                         sizeof cmp->error) != SS_OK) {
        cmp->max_angle_err = INFINITY;
    } else {
        double curv_k = radius > 0 ? 0.5 * (1.0 - k) / radius : 0.0;
        test_brute_horizon(g, az, curv_k, model, dist, ref, near, claimed);
        for (size_t c = 0; c < n; ++c) {
            if (!isfinite(g->z[c])) {
                cmp->bad_nodata += angle[c] != SS_NODATA || dist[c] != SS_NODATA;
                continue;
            }
            cmp->cells++;
            double err = fabs(angle[c] - ref[c]) * M_PI / 180.0;
            if (!(err <= cmp->max_angle_err))
                cmp->max_angle_err = isfinite(err) ? err : INFINITY;
            if (!(claimed[c] >= near[c] - TOL_RAD))
                cmp->bad_caster++;
        }
    }
    free(angle);
    free(dist);
    free(ref);
    free(near);
    free(claimed);
}

static void check_case(const char *label, const ss_grid *g, const double *azimuths, int n_az,
                       double radius, double k)
{
    const char *devices[] = {NULL, "reference"};
    for (int model = 0; model < 2; ++model)
        for (int d = 0; d < 2; ++d) {
            double worst = 0, worst_az = 0;
            size_t bad_nodata = 0, bad_caster = 0;
            char error[600] = "";
            for (int i = 0; i < n_az; ++i) {
                comparison cmp;
                compare(devices[d], g, azimuths[i], radius, k, model, &cmp);
                if (!(cmp.max_angle_err <= worst)) {
                    worst = cmp.max_angle_err;
                    worst_az = azimuths[i];
                }
                bad_nodata += cmp.bad_nodata;
                bad_caster += cmp.bad_caster;
                if (cmp.error[0])
                    snprintf(error, sizeof error, "%s", cmp.error);
            }
            tap_ok(worst <= TOL_RAD && !bad_nodata && !bad_caster && !error[0],
                   "%s, %s, %s == brute force over %d azimuths: worst %.2e rad (az %.9g), %zu "
                   "nodata errors, %zu wrong casting cells %s",
                   label, model_name(model), devices[d] ? devices[d] : "OpenCL", n_az, worst,
                   worst_az, bad_nodata, bad_caster, error);
        }
}

static void random_cases(void)
{
    double az[24];
    int n = 0;
    const double axes[] = {0, 45, 90, 135, 180, 225, 270, 315};
    for (int i = 0; i < 8; ++i)
        az[n++] = axes[i];
    az[n++] = 45 + 1e-9;
    az[n++] = 90 - 1e-9;
    az[n++] = 180 + 1e-9;
    az[n++] = 315 - 1e-9;
    unsigned s = 99;
    while (n < 24) {
        s = s * 1664525u + 1013904223u;
        az[n++] = (s >> 9) % 360000 / 1000.0;
    }
    const struct {
        int w, h;
        double cx, cy;
        terrain_kind kind;
        double relief;
        int holes;
    } cases[] = {
        {64, 64, 30, 30, TERRAIN_SMOOTH, 500, 0},  {97, 41, 30, 30, TERRAIN_NOISE, 100, 0},
        {41, 97, 30, 10, TERRAIN_SMOOTH, 800, 6},  {80, 80, 1, 1, TERRAIN_PLATEAUS, 4, 0},
        {80, 60, 1, 1, TERRAIN_PLATEAUS, 4, 10},   {70, 70, 5, 5, TERRAIN_SPIKES, 300, 0},
        {1, 50, 10, 10, TERRAIN_NOISE, 50, 0},     {50, 1, 10, 10, TERRAIN_NOISE, 50, 0},
        {2, 2, 10, 10, TERRAIN_NOISE, 50, 0},      {3, 200, 10, 10, TERRAIN_SMOOTH, 50, 2},
    };
    const char *names[] = {"smooth", "noise", "smooth", "plateaus", "plateaus", "spikes",
                           "noise",  "noise", "noise",  "smooth"};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        ss_grid g = test_grid(cases[i].w, cases[i].h, cases[i].cx, cases[i].cy);
        test_fill(&g, cases[i].kind, (unsigned)i + 1, cases[i].relief);
        if (cases[i].holes)
            test_holes(&g, (unsigned)i + 7, cases[i].holes, 8);
        char label[160];
        snprintf(label, sizeof label, "%s %dx%d (%gx%g m)%s", names[i], cases[i].w, cases[i].h,
                 cases[i].cx, cases[i].cy, cases[i].holes ? " with nodata holes" : "");
        check_case(label, &g, az, n, 0, 0);
        ss_grid_free(&g);
    }
    /* Curvature matters at km scale: 1 km cells, 100 km lines. */
    ss_grid g = test_grid(97, 61, 1000, 1000);
    test_fill(&g, TERRAIN_SMOOTH, 42, 1500);
    test_holes(&g, 43, 5, 6);
    check_case("smooth 97x61 (1 km cells), curvature on (R 6371 km, k 0.13)", &g, az, 12,
               6371000.0, 0.13);
    ss_grid_free(&g);
}

static void kilauea(void)
{
    const char *path = test_shared_data("hawaii_kilauea_utm5n_30m.tif");
    if (!path) {
        tap_skip("Kilauea DEM, OpenCL == brute force", "../shared/data is absent");
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
    const double az[] = {0.0, 123.4};
    for (int model = 0; model < 2; ++model)
        for (int pass = 0; pass < 2; ++pass) {
            double radius = pass ? 6371000.0 : 0.0;
            comparison cmp;
            int i = (model + pass) % 2;
            compare(NULL, &dem.grid, az[i], radius, 0.13, model, &cmp);
            tap_ok(cmp.max_angle_err <= TOL_RAD && !cmp.bad_nodata && !cmp.bad_caster,
                   "Kilauea 857x793, %s, azimuth %g, curvature %s: OpenCL == brute force on "
                   "%zu cells, worst %.2e rad, %zu nodata errors, %zu wrong casting cells %s",
                   model_name(model), az[i], radius > 0 ? "on" : "off", cmp.cells,
                   cmp.max_angle_err, cmp.bad_nodata, cmp.bad_caster, cmp.error);
        }
    ss_dem_free(&dem);
    ss_ctx_free(ctx);
}

int main(void)
{
    random_cases();
    kilauea();
    return tap_done();
}
