/* Horizons at the grid's edges and beside nodata, where the two samples
 * that feed a cell (interpolated lines) can disagree on whether any terrain
 * lies ahead. The rule (doc/model.md, Edges): a cell's horizon is the
 * weighted mean over its samples that have terrain ahead, their weights
 * renormalised; -90 (shadows: 0) only where none has; its distance is that
 * of the nearer such sample, 0 only where none has. Every cell is checked,
 * edges included, both devices, both line models, at axis and off-axis
 * azimuths:
 *   - a flat plane (with and without nodata holes) gives exactly 0 with a
 *     positive distance, or exactly -90 with distance 0, as the brute force
 *     does, and -90 only beside an edge or a hole;
 *   - a tilted plane gives its own angle or -90, never a mix;
 *   - cast shadows on that plane take the same angle, or 0 where the
 *     horizon gave -90. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lines.h"
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

/* Axis, diagonal and off-axis azimuths in all four quadrants. */
static const double azimuths[] = {0,     3.7, 22.5,  30,  45,  60.5,  90,  111.1,
                                  137.5, 180, 201.3, 225, 250, 292.6, 315, 333.3};
#define N_AZ ((int)(sizeof azimuths / sizeof azimuths[0]))

/* 1 if cell c lies within `reach` cells (either axis) of the grid's edge or
 * of a nodata cell: the only places where nothing can lie ahead on a plane. */
static int near_edge_or_hole(const ss_grid *g, size_t c, int reach)
{
    int r0 = (int)(c / (size_t)g->width), c0 = (int)(c % (size_t)g->width);
    for (int r = r0 - reach; r <= r0 + reach; ++r)
        for (int k = c0 - reach; k <= c0 + reach; ++k)
            if (r < 0 || k < 0 || r >= g->height || k >= g->width ||
                !isfinite(g->z[(size_t)r * g->width + k]))
                return 1;
    return 0;
}

typedef struct {
    size_t mixed;      /* horizon neither the plane's angle nor -90 */
    size_t dist_wrong; /* distance 0 where the horizon is not -90, or the reverse */
    size_t vs_brute;   /* horizon differs from the brute force */
    size_t inland;     /* -90 away from every edge and hole */
    size_t nodata;     /* nodata cells not SS_NODATA */
    size_t open, covered;
    char error[512];
} tally;

static void tally_flat(const ss_grid *g, const float *angle, const float *dist, const double *ref,
                       tally *t)
{
    for (size_t c = 0; c < (size_t)g->width * g->height; ++c) {
        if (!isfinite(g->z[c])) {
            t->nodata += angle[c] != SS_NODATA || dist[c] != SS_NODATA;
            continue;
        }
        int ahead = angle[c] == 0.0f, none = angle[c] == -90.0f;
        t->mixed += !ahead && !none;
        t->dist_wrong += ahead ? !(dist[c] > 0.0f) : dist[c] != 0.0f;
        t->vs_brute += angle[c] != ref[c];
        t->inland += none && !near_edge_or_hole(g, c, 2);
        t->open += none;
        t->covered += ahead;
    }
}

/* A flat plane at height z, optionally with nodata holes. */
static void flat_plane(float z, int holes)
{
    ss_grid g = test_grid(37, 29, 10, 10);
    size_t n = (size_t)g.width * g.height;
    for (size_t c = 0; c < n; ++c)
        g.z[c] = z;
    if (holes)
        test_holes(&g, 5, 5, 4);
    float *angle = malloc(n * sizeof *angle), *dist = malloc(n * sizeof *dist);
    double *ref = malloc(n * sizeof *ref), *near = malloc(n * sizeof *near),
           *claimed = malloc(n * sizeof *claimed);
    for (int model = 0; model < 2; ++model)
        for (int d = 0; d < 2; ++d) {
            tally t;
            memset(&t, 0, sizeof t);
            for (int a = 0; a < N_AZ && !t.error[0]; ++a) {
                if (test_lib_horizon(devices[d], &g, azimuths[a], 0, 0, model, angle, dist,
                                     t.error, sizeof t.error) != SS_OK)
                    break;
                test_brute_horizon(&g, azimuths[a], 0, model, NULL, ref, near, claimed);
                tally_flat(&g, angle, dist, ref, &t);
            }
            tap_ok(!t.error[0] && !t.mixed && !t.dist_wrong && !t.vs_brute && !t.inland &&
                       !t.nodata && t.open > 0 && t.covered > 0,
                   "flat plane at %g m%s, %s lines, %s, %d azimuths, every cell: horizon exactly "
                   "0 with distance > 0 (%zu) or exactly -90 with distance 0 (%zu); %zu mixed, "
                   "%zu wrong distances, %zu != brute force, %zu -90 away from edges and holes, "
                   "%zu nodata wrong %s",
                   z, holes ? " with nodata holes" : "", model_name(model), device_name(d), N_AZ,
                   t.covered, t.open, t.mixed, t.dist_wrong, t.vs_brute, t.inland, t.nodata,
                   t.error);
        }
    free(angle);
    free(dist);
    free(ref);
    free(near);
    free(claimed);
    ss_grid_free(&g);
}

/* A plane that rises by `rise` per metre along the lines' major axis only
 * (rows: northward, columns: eastward): every sample lies on it, including
 * those that lean on one cell across an edge or beside a hole, so every
 * horizon with terrain ahead is exactly the plane's angle along the
 * azimuth. Returns that angle in degrees. */
static double major_plane(ss_grid *g, double az, double rise)
{
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, g->width, g->height, g->cell_x_m, g->cell_y_m, az,
                            SS_LINE_MODEL_INTERPOLATED);
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            double north = -(r - g->height / 2) * g->cell_y_m;
            double east = (c - g->width / 2) * g->cell_x_m;
            size_t k = (size_t)r * g->width + c;
            if (isfinite(g->z[k]))
                g->z[k] = (float)(rise * (ls.major_is_row ? north : east));
        }
    double along = ls.major_is_row ? cos(az * M_PI / 180) : sin(az * M_PI / 180);
    return atan(rise * along) * 180 / M_PI;
}

static float *cast_shadow(int d, const ss_grid *g, double az, double sun_deg, float *horizon,
                          char *err, size_t err_size)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, devices[d]);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    float *lit = malloc(sizeof(float) * (size_t)g->width * g->height);
    if (ss_cast_shadow(ctx, g, &opt, az, sun_deg, NULL, lit, horizon) != SS_OK) {
        snprintf(err, err_size, "%s", ss_ctx_message(ctx));
        free(lit);
        lit = NULL;
    }
    ss_ctx_free(ctx);
    return lit;
}

/* Tilted planes, interpolated lines (digital lines feed each cell from one
 * sample, so they have nothing to mix, and their samples sit beside the
 * line, off the plane's exact angle). */
static void tilted_plane(double cell_y_m, int holes)
{
    const double tol_rad = 1e-5, sun_deg = 7.0;
    ss_grid g = test_grid(41, 33, 10, cell_y_m);
    size_t n = (size_t)g.width * g.height;
    memset(g.z, 0, n * sizeof(float));
    if (holes)
        test_holes(&g, 9, 5, 4);
    float *angle = malloc(n * sizeof *angle), *dist = malloc(n * sizeof *dist),
          *shadow_h = malloc(n * sizeof *shadow_h);
    for (int d = 0; d < 2; ++d) {
        double worst = 0;
        tally t, ts;
        memset(&t, 0, sizeof t);
        memset(&ts, 0, sizeof ts);
        size_t lit_wrong = 0;
        for (int a = 0; a < N_AZ && !t.error[0] && !ts.error[0]; ++a) {
            double az = azimuths[a];
            double want = major_plane(&g, az, 0.4);
            if (test_lib_horizon(devices[d], &g, az, 0, 0, SS_LINES_INTERPOLATED, angle, dist,
                                 t.error, sizeof t.error) != SS_OK)
                break;
            float *lit = cast_shadow(d, &g, az, sun_deg, shadow_h, ts.error, sizeof ts.error);
            if (!lit)
                break;
            for (size_t c = 0; c < n; ++c) {
                if (!isfinite(g.z[c])) {
                    t.nodata += angle[c] != SS_NODATA || dist[c] != SS_NODATA;
                    ts.nodata += shadow_h[c] != SS_NODATA || lit[c] != SS_NODATA;
                    continue;
                }
                int none = angle[c] == -90.0f;
                double err = fabs(angle[c] - want) * M_PI / 180;
                if (!none && err > worst)
                    worst = err;
                t.mixed += !none && !(err <= tol_rad);
                t.dist_wrong += none ? dist[c] != 0.0f : !(dist[c] > 0.0f);
                t.inland += none && !near_edge_or_hole(&g, c, 2);
                t.open += none;
                t.covered += !none;
                /* Shadows: the same horizon, the horizontal where none. */
                double sh_err = fabs(shadow_h[c] - want) * M_PI / 180;
                ts.mixed += none ? shadow_h[c] != 0.0f : !(sh_err <= tol_rad);
                lit_wrong += lit[c] != (sun_deg > shadow_h[c] ? 1.0f : 0.0f);
            }
            free(lit);
        }
        tap_ok(!t.error[0] && worst <= tol_rad && !t.mixed && !t.dist_wrong && !t.inland &&
                   !t.nodata && t.open > 0 && t.covered > 0,
               "tilted plane (rise 0.4 along the major axis, 10x%g m cells)%s, interpolated "
               "lines, %s, %d azimuths, every cell: horizon = the plane's angle (%zu cells, "
               "worst %.2e rad) or -90 with distance 0 (%zu); %zu mixed, %zu wrong distances, "
               "%zu -90 away from edges and holes, %zu nodata wrong %s",
               cell_y_m, holes ? " with nodata holes" : "", device_name(d), N_AZ, t.covered,
               worst, t.open, t.mixed, t.dist_wrong, t.inland, t.nodata, t.error);
        tap_ok(!ts.error[0] && !ts.mixed && !ts.nodata && !lit_wrong,
               "the same plane%s, %s: cast-shadow horizon = the plane's angle, exactly 0 where "
               "the horizon product gives -90 (%zu cells wrong), sunlit <=> sun %g > horizon "
               "(%zu wrong), %zu nodata wrong %s",
               holes ? " with nodata holes" : "", device_name(d), ts.mixed, sun_deg, lit_wrong,
               ts.nodata, ts.error);
    }
    free(angle);
    free(dist);
    free(shadow_h);
    ss_grid_free(&g);
}

int main(void)
{
    flat_plane(0.0f, 0);
    flat_plane(1234.5f, 0);
    flat_plane(1234.5f, 1);
    tilted_plane(10, 0);
    tilted_plane(7, 1);
    return tap_done();
}
