/* Box-model shadows by bounds and march (src/core/box_shadow.c) against
 * the independent box-model ray march of tests/box_march.c, cell by cell:
 * on a synthetic city, the same with nodata holes and cells longer one
 * way, a grid of one row and one of one column, a tower seen from a plain, and the Gothenburg
 * DSM where ../shared/data has it. Suns in 40 azimuths (the axes, the
 * diagonals, and others between and a hundredth of a degree off them),
 * from the horizontal to overhead, each over a range of elevations (a
 * step's suns over the cells) whose lowest, middle and highest must all
 * be lit exactly where the march lights them; with and without the
 * earth's curvature. A bound that failed would settle a cell the march
 * decides otherwise. The march of a band of rows (a run in bands) must
 * give the whole grid's answer there bit for bit. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "box_march.h"
#include "box_shadow.h"
#include "shared_dem.h"
#include "tap.h"
#include "testlib.h"

static const double elevations[][2] = {{-2.0, 0.5},  {0.5, 0.5},   {3.0, 3.4},   {9.0, 9.0},
                                       {20.0, 21.5}, {33.0, 33.0}, {55.0, 57.0}, {88.5, 89.6}};

/* Cells whose verdict differs from the march's at elevation el. */
static long disagreements(const ss_grid *g, const float *angle, double az, double el, double z_max,
                          double curv_k)
{
    long wrong = 0;
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            size_t i = (size_t)r * g->width + c;
            if (!isfinite(g->z[i]))
                continue;
            int lit = el > angle[i];
            /* A sun at or below the horizontal lights no column's top. */
            wrong += lit != (el > 0.0 && box_march_lit_curved(g, r, c, az, el, z_max, curv_k));
        }
    return wrong;
}

static void check_grid(const char *name, const ss_grid *g, double curv_k)
{
    size_t n = (size_t)g->width * g->height;
    float *angle = malloc(n * sizeof(float));
    double z_max = box_march_top(g);
    long wrong = 0, suns = 0;
    uint64_t cells = 0, marched = 0;
    int failed = !angle;
    for (int a = 0; !failed && a < BOX_MARCH_AZIMUTHS; ++a)
        for (size_t e = 0; !failed && e < sizeof elevations / sizeof elevations[0]; ++e) {
            double lo = elevations[e][0], hi = elevations[e][1];
            ss_box_ray_counts counts;
            if (!ss_box_shadow_horizons(g, box_march_azimuths[a], lo, hi, curv_k, 0, g->height, NULL, angle,
                                        &counts)) {
                failed = 1;
                break;
            }
            cells += counts.cells;
            marched += counts.marched;
            double at[3] = {lo, 0.5 * (lo + hi), hi};
            for (int k = 0; k < 3; ++k, ++suns) {
                long w = disagreements(g, angle, box_march_azimuths[a], at[k], z_max, curv_k);
                if (w && !wrong)
                    tap_diag("%s: %ld cells differ at azimuth %g, elevation %g (range %g..%g)",
                             name, w, box_march_azimuths[a], at[k], lo, hi);
                wrong += w;
            }
        }
    tap_ok(!failed && wrong == 0,
           "%s%s: every cell lit exactly where the box-model march lights it (%ld suns, "
           "%.1f %% of cells marched)",
           name, curv_k > 0 ? ", curvature" : "", suns,
           cells ? 100.0 * (double)marched / (double)cells : 0.0);
    /* The bounds must settle most cells, or the march is all there is. */
    if (!failed && curv_k == 0.0)
        tap_ok(marched < cells / 2, "%s: the bounds settle %.1f %% of cells", name,
               cells ? 100.0 - 100.0 * (double)marched / (double)cells : 0.0);
    free(angle);
}

/* The march over a band of rows (a banded run's) gives the whole grid's
 * horizons on those rows bit for bit, for every azimuth and range of
 * elevations, bands of 1, 7 and 33 rows covering the grid, their cells
 * counted once; each band marched into a buffer of its own size (so that
 * a write beyond it is caught by the sanitizers), the whole answer
 * refilled with NaN before each band height. */
static void check_bands(const char *name, const ss_grid *g, double curv_k)
{
    static const int band_rows[] = {1, 7, 33};
    size_t n = (size_t)g->width * g->height;
    float *whole = malloc(n * sizeof(float)), *band = malloc(n * sizeof(float));
    long differ = 0, runs = 0;
    int failed = !whole || !band;
    for (int a = 0; !failed && a < BOX_MARCH_AZIMUTHS; ++a)
        for (size_t e = 0; !failed && e < sizeof elevations / sizeof elevations[0]; ++e) {
            double az = box_march_azimuths[a], lo = elevations[e][0], hi = elevations[e][1];
            ss_box_ray_counts all, part;
            failed = !ss_box_shadow_horizons(g, az, lo, hi, curv_k, 0, g->height, NULL, whole,
                                             &all);
            for (size_t b = 0; !failed && b < sizeof band_rows / sizeof band_rows[0]; ++b) {
                uint64_t cells = 0;
                for (size_t c = 0; c < n; ++c)
                    band[c] = NAN;
                for (int r0 = 0; !failed && r0 < g->height; r0 += band_rows[b]) {
                    int rows = g->height - r0 < band_rows[b] ? g->height - r0 : band_rows[b];
                    size_t own = (size_t)rows * g->width;
                    float *rows_angle = malloc(own * sizeof(float));
                    failed = !rows_angle || !ss_box_shadow_horizons(g, az, lo, hi, curv_k, r0, rows,
                                                                    NULL, rows_angle, &part);
                    if (!failed)
                        memcpy(band + (size_t)r0 * g->width, rows_angle, own * sizeof(float));
                    free(rows_angle);
                    cells += part.cells;
                }
                ++runs;
                differ += !failed && (memcmp(whole, band, n * sizeof(float)) != 0 ||
                                      cells != all.cells);
            }
        }
    tap_ok(!failed && differ == 0,
           "%s%s: the march by bands of 1, 7 and 33 rows gives the whole grid's horizons bit "
           "for bit, each cell counted once (%ld of %ld runs differ)",
           name, curv_k > 0 ? ", curvature" : "", differ, runs);
    free(whole);
    free(band);
}

static void check_dsm(const char *name, const ss_grid *g, void *user)
{
    (void)user;
    check_grid(name, g, 0.0);
}

int main(void)
{
    ss_grid city = box_march_city(120);
    check_grid("a synthetic city", &city, 0.0);
    /* A radius of 2 km: curvature that matters across 120 m. */
    check_grid("a synthetic city", &city, 1.0 / (2.0 * 2000.0));
    check_bands("a synthetic city", &city, 1.0 / (2.0 * 2000.0));
    box_march_holes(&city);
    check_grid("a city with holes, 1 x 1.5 m cells", &city, 0.0);
    check_bands("a city with holes, 1 x 1.5 m cells", &city, 0.0);
    ss_grid_free(&city);
    ss_grid row = box_march_strip(300, 1);
    check_grid("one row", &row, 0.0);
    ss_grid_free(&row);
    /* One column: the major axis may be its rows with a stride of 1. */
    ss_grid column = box_march_strip(1, 300);
    check_grid("one column", &column, 0.0);
    check_bands("one column", &column, 0.0);
    ss_grid_free(&column);
    ss_grid tower = box_march_tower();
    check_grid("one tower on a plain", &tower, 0.0);
    check_bands("one tower on a plain", &tower, 0.0);
    ss_grid_free(&tower);
    shared_dem_run("goteborg_kronenhuset_dsm_1m.tif", "the Gothenburg DSM", check_dsm, NULL);
    return tap_done();
}
