/* Heights of the horizon-casting points (ss_horizon with
 * SS_HORIZON_CAST_HEIGHT, `skysweep horizon --cast-height`):
 *   - on random terrain, with and without nodata holes and earth
 *     curvature, both line models and both devices, every cell with a
 *     caster reports the height of the sample that an independent brute
 *     force finds at the reported distance ahead of the cell's
 *     distance-naming sample, and SS_NODATA exactly where the distance is 0
 *     or the cell has no height;
 *   - a far wall of known height behind a flat plane is every cell's
 *     caster, at the DEM's own datum (a stored zero of 3000 m);
 *   - the two devices give the same grid. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "testlib.h"

static const char *devices[] = {NULL, "reference"};
static const double azimuths[] = {0, 22.5, 60.5, 90, 137.5, 201.3, 270, 333.3};
#define N_AZ ((int)(sizeof azimuths / sizeof azimuths[0]))
#define EARTH_M 6371000.0
#define REFRACTION 0.13

typedef struct {
    size_t casters, wrong, none_wrong, nodata_wrong;
    double worst_m;
} tally;

static void check_terrain(terrain_kind kind, int holes, int curved, int model, int device)
{
    ss_grid g = test_grid(72, 56, 30.0, 25.0);
    test_fill(&g, kind, 11 + (unsigned)kind, 400.0);
    if (holes)
        test_holes(&g, 3, 6, 5);
    g.z_origin_m = 1200.0;
    size_t n = (size_t)g.width * g.height;
    float *angle = malloc(n * sizeof(float)), *dist = malloc(n * sizeof(float));
    float *cast = malloc(n * sizeof(float));
    double *ref = malloc(n * sizeof(double));
    tally t = {0, 0, 0, 0, 0.0};
    char err[256] = "";
    double radius = curved ? EARTH_M : 0.0;
    double curv_k = curved ? 0.5 * (1.0 - REFRACTION) / EARTH_M : 0.0;
    int ran = 1;
    for (int a = 0; a < N_AZ && ran; ++a) {
        if (test_lib_caster(devices[device], &g, azimuths[a], radius, REFRACTION, model, angle,
                            dist, cast, err, sizeof err) != SS_OK) {
            ran = 0;
            break;
        }
        test_brute_caster_height(&g, azimuths[a], curv_k, model, dist, ref);
        for (size_t c = 0; c < n; ++c) {
            if (!isfinite(g.z[c])) {
                t.nodata_wrong += cast[c] != SS_NODATA;
                continue;
            }
            if (dist[c] == 0.0f) {
                t.none_wrong += cast[c] != SS_NODATA;
                continue;
            }
            t.casters++;
            double want = g.z_origin_m + ref[c];
            double e = fabs((double)cast[c] - want);
            /* float heights near 1600 m: a few 1e-4 m of rounding */
            if (!(e <= 2e-3)) {
                t.wrong++;
                if (!(e <= t.worst_m))
                    t.worst_m = e;
            }
        }
    }
    tap_ok(ran && t.casters > 0 && t.wrong == 0 && t.none_wrong == 0 && t.nodata_wrong == 0,
           "terrain %d%s%s, %s lines, %s: %zu casters over %d azimuths, %zu not the brute "
           "force's sample (worst %.3g m), %zu without a caster not nodata, %zu nodata cells "
           "wrong %s",
           (int)kind, holes ? " with holes" : "", curved ? ", curvature" : "",
           model == SS_LINES_DIGITAL ? "digital" : "interpolated",
           devices[device] ? devices[device] : "OpenCL", t.casters, N_AZ, t.wrong, t.worst_m,
           t.none_wrong, t.nodata_wrong, err);
    free(angle);
    free(dist);
    free(cast);
    free(ref);
    free(g.z);
}

/* A flat plane at the stored zero with a wall WALL_M high along its
 * northern edge: looking north every cell's caster is the wall, at
 * z_origin_m + WALL_M; looking south nothing is ahead but the flat plane,
 * whose casters lie at the plane's height (the farthest of equal
 * horizons; the wall looks down onto the plane's far edge) except in the
 * last row, which has none. */
#define WALL_M 250.0f
static void wall(int device)
{
    ss_grid g = test_grid(40, 30, 10.0, 10.0);
    for (size_t c = 0; c < (size_t)g.width * g.height; ++c)
        g.z[c] = c < (size_t)g.width ? WALL_M : 0.0f;
    g.z_origin_m = 3000.0;
    size_t n = (size_t)g.width * g.height;
    float *angle = malloc(n * sizeof(float)), *dist = malloc(n * sizeof(float));
    float *cast_n = malloc(n * sizeof(float)), *cast_s = malloc(n * sizeof(float));
    char err[256] = "";
    ss_status st = test_lib_caster(devices[device], &g, 0.0, 0, 0, SS_LINES_INTERPOLATED, angle,
                                   dist, cast_n, err, sizeof err);
    if (st == SS_OK)
        st = test_lib_caster(devices[device], &g, 180.0, 0, 0, SS_LINES_INTERPOLATED, angle, dist,
                             cast_s, err, sizeof err);
    size_t north_wrong = 0, south_wrong = 0;
    for (int r = 0; r < g.height && st == SS_OK; ++r)
        for (int c = 0; c < g.width; ++c) {
            size_t i = (size_t)r * g.width + c;
            if (r == 0)
                north_wrong += cast_n[i] != SS_NODATA; /* the wall sees nothing north */
            else
                north_wrong += cast_n[i] != 3000.0f + WALL_M;
            if (r == g.height - 1)
                south_wrong += cast_s[i] != SS_NODATA;
            else
                south_wrong += cast_s[i] != 3000.0f;
        }
    tap_ok(st == SS_OK && north_wrong == 0 && south_wrong == 0,
           "wall %g m at the north edge, %s: %zu cells whose northern caster is not the wall at "
           "%g m, %zu whose southern caster is not the plane at 3000 m %s",
           (double)WALL_M, devices[device] ? devices[device] : "OpenCL", north_wrong,
           3000.0 + WALL_M, south_wrong, err);
    free(angle);
    free(dist);
    free(cast_n);
    free(cast_s);
    free(g.z);
}

static void devices_agree(void)
{
    ss_grid g = test_grid(64, 48, 20.0, 20.0);
    test_fill(&g, TERRAIN_SMOOTH, 4, 600.0);
    test_holes(&g, 8, 4, 4);
    size_t n = (size_t)g.width * g.height;
    float *angle = malloc(n * sizeof(float)), *dist = malloc(n * sizeof(float));
    float *cast[2] = {malloc(n * sizeof(float)), malloc(n * sizeof(float))};
    char err[256] = "";
    size_t differ = 0;
    int ran = 1;
    for (int a = 0; a < N_AZ && ran; ++a) {
        for (int d = 0; d < 2 && ran; ++d)
            ran = test_lib_caster(devices[d], &g, azimuths[a], EARTH_M, REFRACTION,
                                  SS_LINES_INTERPOLATED, angle, dist, cast[d], err,
                                  sizeof err) == SS_OK;
        for (size_t c = 0; c < n && ran; ++c)
            differ += !(fabsf(cast[0][c] - cast[1][c]) <= 1e-3f) &&
                      !(cast[0][c] == SS_NODATA && cast[1][c] == SS_NODATA);
    }
    tap_ok(ran && differ == 0,
           "OpenCL and the C reference give the same casting heights (%zu cell-directions "
           "differ) %s",
           differ, err);
    free(angle);
    free(dist);
    free(cast[0]);
    free(cast[1]);
    free(g.z);
}

int main(void)
{
    const terrain_kind kinds[] = {TERRAIN_SMOOTH, TERRAIN_NOISE, TERRAIN_PLATEAUS};
    for (int d = 0; d < 2; ++d)
        for (int m = 0; m < 2; ++m) {
            int model = m ? SS_LINES_DIGITAL : SS_LINES_INTERPOLATED;
            for (int k = 0; k < 3; ++k)
                check_terrain(kinds[k], k == 0, k == 1, model, d);
        }
    for (int d = 0; d < 2; ++d)
        wall(d);
    devices_agree();
    return tap_done();
}
