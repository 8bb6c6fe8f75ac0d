/* Box-model crowns by each cell's own ray (src/core/box_crowns.c, through
 * ss_canopy_crossed on box lines) against the independent ray march of
 * tests/box_march.c, cell by cell: a synthetic city with trees, the same
 * with nodata holes and cells longer one way, one column and one row of
 * cells, crowns high on their trunks
 * over hills, and the Gothenburg DSM and CDSM where ../shared/data has
 * them. Suns in 40 azimuths (the axes, the diagonals, and others between
 * and a hundredth of a degree off them) and 7 elevations up to 89.5
 * degrees. A bound that failed would settle a cell the march finds
 * crossed; the families' walks (--box-shadows lines) differ from the march
 * on some cells, which shows the comparison can fail. Asking only the cells
 * the solid shadows may light (as insolation does) changes no answer. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "box_crowns.h"
#include "box_march.h"
#include "box_shadow.h"
#include "tap.h"
#include "testlib.h"
#include "tree_scenes.h"

static const double elevations[] = {0.5, 3.0, 9.0, 21.5, 33.0, 57.0, 89.5};

/* Cells where the library's crossed differs from the march's. */
static long disagreements(const ss_grid *g, const ss_canopy *cn, const float *trunk,
                          const unsigned char *crossed, double az, double el, double z_max,
                          long *found)
{
    long wrong = 0;
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            size_t i = (size_t)r * g->width + c;
            if (!isfinite(g->z[i]))
                continue;
            int m = box_march_crossed(g, cn->height_m, trunk, r, c, az, el, z_max);
            *found += m;
            wrong += m != crossed[i];
        }
    return wrong;
}

/* Every sun over grid g with crowns `height` on trunks `trunk` (metres
 * above each cell's surface). On a grid one cell wide (one_wide) a ray
 * crosses a square or two before it leaves, and the families' walks need
 * not differ from the march: they are not compared there. */
static void check_scene(const char *name, const ss_grid *g, const float *height, const float *trunk,
                        int one_wide)
{
    size_t n = (size_t)g->width * g->height;
    unsigned char *crossed = malloc(n);
    ss_canopy cn = {height, trunk, 0.0, 0.03};
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = SS_LINES_BOX;
    ss_ctx *ctx = ss_ctx_new();
    double z_max = -INFINITY;
    for (size_t i = 0; i < n; ++i)
        if (isfinite(g->z[i]))
            z_max = fmax(z_max, g->z[i] + height[i]);
    long wrong = 0, found = 0, suns = 0;
    int failed = !crossed;
    for (size_t a = 0; !failed && a < BOX_MARCH_AZIMUTHS; ++a)
        for (size_t e = 0; !failed && e < sizeof elevations / sizeof *elevations; ++e, ++suns) {
            if (ss_canopy_crossed(ctx, g, &cn, &opt, box_march_azimuths[a], elevations[e],
                                  crossed) != SS_OK) {
                tap_diag("%s: %s", name, ss_ctx_message(ctx));
                failed = 1;
                break;
            }
            long w = disagreements(g, &cn, trunk, crossed, box_march_azimuths[a], elevations[e],
                                   z_max, &found);
            if (w && !wrong)
                tap_diag("%s: %ld cells differ at azimuth %g, elevation %g", name, w,
                         box_march_azimuths[a], elevations[e]);
            wrong += w;
        }
    ss_counters counts = ss_ctx_counters(ctx);
    tap_ok(!failed && wrong == 0 && found > 0 && counts.crown_march_steps == (uint64_t)suns,
           "%s: every cell's ray crosses a crown exactly where the box-model march finds one "
           "(%ld suns, %ld crossings, %.1f %% of cells marched)",
           name, suns, found,
           counts.crown_march_cells
               ? 100.0 * (double)counts.crown_march_marched / (double)counts.crown_march_cells
               : 0.0);
    /* The families' walks stand for each ray by the nearest of their
     * lines: they differ somewhere, so the comparison above can fail. */
    opt.box_shadows = SS_BOX_SHADOWS_LINES;
    long lines_wrong = 0, lines_found = 0;
    for (size_t a = 0; !failed && !one_wide && a < 4; ++a)
        if (ss_canopy_crossed(ctx, g, &cn, &opt, box_march_azimuths[4 * a + 2], 21.5, crossed) ==
            SS_OK)
            lines_wrong += disagreements(g, &cn, trunk, crossed, box_march_azimuths[4 * a + 2],
                                         21.5, z_max, &lines_found);
    if (!one_wide)
        tap_ok(lines_wrong > 0,
               "%s: the box lines' families differ from the march on %ld "
               "cells of 4 suns",
               name, lines_wrong);
    ss_ctx_free(ctx);
    free(crossed);
}

/* Insolation asks only the cells its marched solid shadows may light: those
 * are answered as when every cell is asked, the rest left 0. */
static void solid_mask(const char *name, const ss_grid *g, const float *height, const float *trunk)
{
    size_t n = (size_t)g->width * g->height;
    unsigned char *all = malloc(n), *asked = malloc(n);
    float *angle = malloc(n * sizeof(float));
    ss_canopy cn = {height, trunk, 0.0, 0.03};
    ss_box_ray_counts c_all, c_asked, c_solid;
    const double az = 203.0, lo = 19.5, hi = 21.5;
    int ok = ss_box_shadow_horizons(g, az, lo, hi, 0.0, 0, g->height, NULL, angle, &c_solid) &&
             ss_box_crowns_crossed(g, &cn, az, 20.5, 0, g->height, NULL, 0.0, NULL, all, &c_all) &&
             ss_box_crowns_crossed(g, &cn, az, 20.5, 0, g->height, angle, hi, NULL, asked,
                                   &c_asked);
    size_t wrong = 0, shaded = 0;
    for (size_t i = 0; ok && i < n; ++i) {
        int solid_shade = angle[i] >= hi && isfinite(g->z[i]);
        shaded += solid_shade;
        wrong += asked[i] != (solid_shade ? 0 : all[i]);
    }
    tap_ok(ok && wrong == 0 && shaded > 0 && c_asked.cells + shaded == c_all.cells,
           "%s: asking only the cells the solid may light answers them as before (%zu cells "
           "left unasked, %zu differ)",
           name, shaded, wrong);
    free(all), free(asked), free(angle);
}

/* A band's rows at a time (a run in bands), with the band's own solid
 * horizons: the crowns crossed are the whole grid's bit for bit, for 40
 * azimuths and bands of 1, 7 and 33 rows, each band's cells counted once;
 * rows outside the band are left as they were (the whole answer is
 * refilled with 2 before each band height). */
static void bands_as_whole(const char *name, const ss_grid *g, const float *height,
                           const float *trunk)
{
    static const int band_rows[] = {1, 7, 33};
    size_t n = (size_t)g->width * g->height;
    unsigned char *whole = malloc(n), *banded = malloc(n);
    float *angle = malloc(n * sizeof(float));
    ss_canopy cn = {height, trunk, 0.0, 0.03};
    const double lo = 19.5, hi = 21.5;
    long differ = 0, runs = 0;
    int ok = whole && banded && angle;
    for (int a = 0; ok && a < BOX_MARCH_AZIMUTHS; ++a) {
        double az = box_march_azimuths[a];
        ss_box_ray_counts c_whole, c_band, c_solid;
        ok = ss_box_shadow_horizons(g, az, lo, hi, 0.0, 0, g->height, NULL, angle, &c_solid) &&
             ss_box_crowns_crossed(g, &cn, az, 20.5, 0, g->height, angle, hi, NULL, whole,
                                   &c_whole);
        for (size_t b = 0; ok && b < sizeof band_rows / sizeof band_rows[0]; ++b) {
            memset(banded, 2, n);
            uint64_t cells = 0;
            for (int r0 = 0; ok && r0 < g->height; r0 += band_rows[b]) {
                int rows = g->height - r0 < band_rows[b] ? g->height - r0 : band_rows[b];
                ok = ss_box_crowns_crossed(g, &cn, az, 20.5, r0, rows,
                                           angle + (size_t)r0 * g->width, hi, NULL, banded,
                                           &c_band);
                cells += c_band.cells;
            }
            ++runs;
            differ += ok && (memcmp(whole, banded, n) != 0 || cells != c_whole.cells);
        }
    }
    tap_ok(ok && differ == 0,
           "%s: the crowns crossed by bands of 1, 7 and 33 rows, with each band's solid horizons, "
           "are the whole grid's bit for bit (%ld of %ld runs differ)",
           name, differ, runs);
    free(whole), free(banded), free(angle);
}

/* Trunks at `ratio` of each crown's height. */
static float *trunks(const float *height, size_t n, double ratio)
{
    float *trunk = malloc(n * sizeof(float));
    for (size_t i = 0; i < n; ++i)
        trunk[i] = (float)(ratio * height[i]);
    return trunk;
}

static void synthetic(void)
{
    const int n = 120;
    size_t cells = (size_t)n * n;
    ss_grid city = box_march_city(n);
    float *height = malloc(cells * sizeof(float));
    tree_plant(&city, height, 11, 40);
    float *trunk = trunks(height, cells, 0.25);
    check_scene("a synthetic city with 40 trees", &city, height, trunk, 0);
    solid_mask("a synthetic city with 40 trees", &city, height, trunk);
    bands_as_whole("a synthetic city with 40 trees", &city, height, trunk);
    /* Nodata holes neither hold a crown nor receive; cells half as long
     * again north-south. */
    for (size_t i = 0; i < cells; i += 37)
        city.z[i] = NAN;
    city.cell_y_m = 1.5;
    check_scene("a city with holes, 1 x 1.5 m cells", &city, height, trunk, 0);
    free(trunk);
    ss_grid_free(&city);
    /* Crowns high on their trunks over hills: light passes under them. */
    ss_grid hills = test_grid(n, n, 1, 1);
    test_fill(&hills, TERRAIN_SMOOTH, 3, 6.0);
    tree_plant(&hills, height, 5, 30);
    trunk = trunks(height, cells, 0.6);
    check_scene("high crowns (trunk 0.6) over 6 m hills", &hills, height, trunk, 0);
    bands_as_whole("high crowns (trunk 0.6) over 6 m hills", &hills, height, trunk);
    free(trunk);
    free(height);
    ss_grid_free(&hills);
    /* One column and one row of cells, every third with a crown: the
     * major axis of a grid one cell wide may be its rows with a stride of 1. */
    for (int k = 0; k < 2; ++k) {
        ss_grid line = test_grid(k ? 200 : 1, k ? 1 : 200, 1, 1);
        float *h = malloc(200 * sizeof(float));
        for (int i = 0; i < 200; ++i) {
            line.z[i] = (float)((i * 7919) % 5);
            h[i] = i % 3 ? 0.0f : (float)(3 + i % 7);
        }
        float *t = trunks(h, 200, 0.3);
        check_scene(k ? "one row" : "one column", &line, h, t, 1);
        free(t), free(h);
        ss_grid_free(&line);
    }
}

static void gothenburg(void)
{
    ss_dem d;
    float *height;
    int found = tree_gothenburg(&d, &height);
    if (found == 0)
        tap_skip("the Gothenburg DSM and CDSM", "../shared/data is not here");
    if (found <= 0)
        return;
    size_t cells = (size_t)d.grid.width * d.grid.height;
    float *trunk = trunks(height, cells, 0.25);
    check_scene("the Gothenburg DSM and CDSM", &d.grid, height, trunk, 0);
    free(trunk);
    free(height);
    ss_dem_free(&d);
}

int main(void)
{
    synthetic();
    gothenburg();
    return tap_done();
}
