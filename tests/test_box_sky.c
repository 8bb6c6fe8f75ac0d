/* The box model's sky view by each cell's own ray (src/core/box_sky.c,
 * the default on box lines) against the independent box-model march of
 * tests/box_march.c, cell by cell: every SVF definition and both
 * opennesses, with and without the earth's curvature, on a synthetic
 * city, the same with nodata holes and cells longer one way, a grid of
 * one row and one of one column, a tower on a plain, rolling hills (where
 * a walk passes over most blocks of the grid, and walks far uphill), and
 * the Gothenburg DSM where ../shared/data has it. Directions along the axes and the
 * diagonals (where a ray meets the cells' corners) and off them. In bands
 * of any height the answer is the whole grid's bit for bit, the radiative
 * SVF's slopes included; OpenCL gives the C twin's; --box-sky lines still
 * walks the lines. Four cells in AVX2's lanes give the one-cell walk's
 * tangents bit for bit. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "box_march.h"
#include "box_sky_walk.h"
#include "shared_dem.h"
#include "ss_terms.h"
#include "tap.h"
#include "testlib.h"

/* The library's sky product of term on the C twin (or device), whole grid. */
static int library_sky(const char *device, const ss_grid *g, const ss_sweep_options *opt,
                       ss_sky_term term, float *out, char *err)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, device);
    ss_status st = term <= SS_SKY_SVF_RADIATIVE
                       ? ss_svf(ctx, g, opt, (ss_svf_definition)term, out)
                       : ss_openness(ctx, g, opt, term == SS_SKY_OPENNESS_NEGATIVE, 0.0, out);
    if (st != SS_OK)
        snprintf(err, 300, "%s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st == SS_OK;
}

/* The march's value of term at cell (r, c): its horizons in opt's
 * directions (turned into the grid's frame by its grid north), on heights negated for negative openness
 * (flipped, the same grid negated), finished as the products define it
 * (doc/model.md). */
static double reference(const ss_grid *g, const ss_grid *flipped, const ss_sweep_options *opt,
                        ss_sky_term term, double curv_k, int r, int c)
{
    float de = 0.0f, dn = 0.0f;
    if (term == SS_SKY_SVF_RADIATIVE)
        ss_gradient_horn(g->z, g->width, g->height, c, r, (float)g->cell_x_m,
                         (float)g->cell_y_m, &de, &dn);
    double sum = 0.0;
    for (int k = 0; k < opt->directions; ++k) {
        double az = ss_direction_azimuth(opt, k) - opt->grid_north_deg;
        double h = box_march_horizon_curved_deg(term == SS_SKY_OPENNESS_NEGATIVE ? flipped : g,
                                                r, c, az, curv_k);
        double rad = h * M_PI / 180;
        sum += term == SS_SKY_SVF_GEOMETRIC    ? sin(rad)
               : term == SS_SKY_SVF_HORIZONTAL ? cos(rad) * cos(rad)
               : term == SS_SKY_SVF_RADIATIVE
                   ? ss_svf_tilted_term((float)cos(rad), (float)sin(rad),
                                        (float)sin(az * M_PI / 180),
                                        (float)cos(az * M_PI / 180), de, dn)
                   : h;
    }
    double mean = sum / opt->directions;
    if (term >= SS_SKY_OPENNESS_POSITIVE)
        return 90.0 - mean;
    double v = term == SS_SKY_SVF_GEOMETRIC ? 1.0 - mean : mean;
    return fmin(fmax(v, 0.0), 1.0);
}

static const char *term_names[] = {"geometric SVF", "horizontal SVF", "radiative SVF",
                                   "positive openness", "negative openness"};

/* Every term against the march on every cell with a height: SVF within
 * 1e-6, openness within 1e-4 degrees (the library sums floats; the march,
 * doubles); nodata where the cell has none. */
static void check_grid(const char *what, const ss_grid *g, double curv_k)
{
    size_t n = (size_t)g->width * g->height;
    float *out = malloc(n * sizeof(float));
    ss_grid flipped = *g;
    flipped.z = malloc(n * sizeof(float));
    for (size_t i = 0; i < n; ++i)
        flipped.z[i] = -g->z[i];
    /* 8 directions from 0: the axes and diagonals; 12 from 3.7 deg: off
     * them; and 12 on a grid whose north is 1.3 deg from true north. */
    static const struct {
        int directions;
        double offset, north;
    } sets[] = {{8, 0.0, 0.0}, {12, 3.7, 0.0}, {12, 3.7, 1.3}};
    for (int term = SS_SKY_SVF_GEOMETRIC; term <= SS_SKY_OPENNESS_NEGATIVE; ++term) {
        double worst = 0.0;
        char err[300] = "";
        int ok = out != NULL && flipped.z != NULL;
        size_t wrong_nodata = 0;
        for (int s = 0; ok && s < 3; ++s) {
            ss_sweep_options opt =
                box_march_options(sets[s].directions, sets[s].offset, sets[s].north, curv_k);
            ok = library_sky("reference", g, &opt, (ss_sky_term)term, out, err);
            for (int r = 0; ok && r < g->height; ++r)
                for (int c = 0; c < g->width; ++c) {
                    size_t i = (size_t)r * g->width + c;
                    if (!isfinite(g->z[i])) {
                        wrong_nodata += out[i] != SS_NODATA;
                        continue;
                    }
                    double want = reference(g, &flipped, &opt, (ss_sky_term)term, curv_k, r, c);
                    double e = fabs(out[i] - want);
                    worst = e <= worst ? worst : isnan(e) ? INFINITY : e;
                }
        }
        double allowed = term >= SS_SKY_OPENNESS_POSITIVE ? 1e-4 : 1e-6;
        tap_ok(ok && worst <= allowed && wrong_nodata == 0,
               "%s%s: the %s by each cell's own ray is the box-model march's on every cell, "
               "along the axes and diagonals, off them and with a grid north (worst %.2g, at "
               "most %g); %zu nodata cells given a value%s%s",
               what, curv_k > 0 ? ", curved" : "", term_names[term], worst, allowed,
               wrong_nodata, err[0] ? ": " : "", err);
    }
    free(flipped.z);
    free(out);
}

typedef struct {
    float *out;
    int width;
} keep_rows;

static ss_status keep(void *user, int output, int index, int row0, int n_rows,
                      const float *values)
{
    (void)output, (void)index;
    keep_rows *k = user;
    memcpy(k->out + (size_t)row0 * k->width, values, sizeof(float) * n_rows * k->width);
    return SS_OK;
}

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    const ss_grid *g = user;
    memcpy(z, g->z + (size_t)row0 * g->width, sizeof(float) * n_rows * g->width);
    return SS_OK;
}

/* A DEM read in bands of 1, 7 and 33 rows gives the whole grid's sky bit
 * for bit, the radiative SVF (slopes from the rows around a band) too,
 * with the earth's curvature. */
static void check_bands(const char *what, const ss_grid *g)
{
    size_t n = (size_t)g->width * g->height;
    float *whole = malloc(n * sizeof(float)), *banded = malloc(n * sizeof(float));
    ss_sweep_options opt = box_march_options(12, 3.7, 0.0, 1.0 / (2.0 * 2000.0));
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    static const int band_rows[] = {1, 7, 33};
    size_t differ = 0;
    int ok = whole && banded;
    for (int term = SS_SKY_SVF_GEOMETRIC; ok && term <= SS_SKY_OPENNESS_NEGATIVE; ++term) {
        ss_source src = test_source(g, NULL, NULL, 0, NULL);
        src.z = g->z;
        keep_rows all = {whole, g->width};
        ok = ss_sky_rows(ctx, &src, &opt, (ss_sky_term)term, 0.0, NULL, keep, &all) == SS_OK;
        for (int b = 0; ok && b < 3; ++b) {
            ss_source bands = test_source(g, read_rows, (void *)g, band_rows[b], NULL);
            keep_rows part = {banded, g->width};
            for (size_t i = 0; i < n; ++i)
                banded[i] = NAN;
            ok = ss_sky_rows(ctx, &bands, &opt, (ss_sky_term)term, 0.0, NULL, keep, &part) ==
                 SS_OK;
            differ += ok && memcmp(whole, banded, n * sizeof(float)) != 0;
        }
    }
    tap_ok(ok && differ == 0,
           "%s: every sky term by each cell's own ray in bands of 1, 7 and 33 rows is the whole "
           "grid's bit for bit (%zu of 15 differ)%s%s",
           what, differ, ok ? "" : ": ", ok ? "" : ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    free(whole);
    free(banded);
}

/* OpenCL gives the C twin's answer (the rays run on the host), and
 * --box-sky lines walks the lines, whose answer differs. */
static void check_devices_and_lines(const char *what, const ss_grid *g)
{
    size_t n = (size_t)g->width * g->height;
    float *twin = malloc(n * sizeof(float)), *other = malloc(n * sizeof(float));
    ss_sweep_options opt = box_march_options(12, 3.7, 0.0, 0.0);
    char err[300] = "";
    int ok = twin && other && library_sky("reference", g, &opt, SS_SKY_SVF_RADIATIVE, twin, err);
    if (!test_have_pocl()) {
        tap_skip("the box sky view on OpenCL", "no PoCL device is listed");
    } else {
        int same = ok && library_sky(NULL, g, &opt, SS_SKY_SVF_RADIATIVE, other, err) &&
                   memcmp(twin, other, n * sizeof(float)) == 0;
        tap_ok(same, "%s: the radiative SVF by each cell's own ray is the same on OpenCL as on "
                     "the C twin, bit for bit%s%s",
               what, err[0] ? ": " : "", err);
    }
    opt.box_sky = SS_BOX_SKY_LINES;
    ok = ok && library_sky("reference", g, &opt, SS_SKY_SVF_RADIATIVE, other, err);
    double most = 0.0;
    for (size_t i = 0; ok && i < n; ++i)
        if (isfinite(g->z[i]) && isfinite(twin[i]) && isfinite(other[i]))
            most = fmax(most, fabs(twin[i] - other[i]));
    tap_ok(ok && most > 1e-4,
           "%s: --box-sky lines walks the box lines instead, off the rays by up to %.4f%s%s",
           what, most, err[0] ? ": " : "", err);
    free(twin);
    free(other);
}

/* The AVX2 lanes' tangents against the one-cell walk's, bit for bit, for
 * every group of four cells the lanes take, in 28 directions (the axes
 * and diagonals, and off them), heights and negated heights, with and
 * without curvature. */
static void check_lanes(const char *what, const ss_grid *g)
{
#if SS_SKY_LANES_AVX2
    if (!__builtin_cpu_supports("avx2")) {
        tap_skip(what, "this CPU has no AVX2");
        return;
    }
    size_t groups = 0, differ = 0;
    int ok = 1;
    for (int flip = 0; ok && flip < 2; ++flip) {
        float sign = flip ? -1.0f : 1.0f;
        ss_box_sky_tops *tops = ss_box_sky_tops_new(g, sign);
        ok = tops != NULL;
        for (int d = 0; ok && d < 28; ++d) {
            double az = d < 8 ? 45.0 * d : 3.7 + 18.0 * (d - 8);
            ss_sky_ray ray = {0};
            ok = ss_sky_ray_init(&ray, g, az);
            for (int bent = 0; ok && bent < 2; ++bent) {
                double curv_k = bent ? 1.0 / (2.0 * 2000.0) : 0.0;
                for (int r = 0; r < g->height; ++r)
                    for (int c = 0; c + SS_SKY_LANES <= g->width; c += SS_SKY_LANES) {
                        double lanes[SS_SKY_LANES];
                        ss_sky_tangents_avx2(g, &ray, tops, c, r, sign, curv_k, lanes);
                        for (int i = 0; i < SS_SKY_LANES; ++i) {
                            int at;
                            double one =
                                ss_sky_tangent(g, &ray, tops, c + i, r, sign, curv_k, &at);
                            differ += isfinite(g->z[(size_t)r * g->width + c + i]) &&
                                      memcmp(&one, &lanes[i], sizeof one) != 0;
                        }
                        ++groups;
                    }
            }
            ss_sky_ray_free(&ray);
        }
        ss_box_sky_tops_free(tops);
    }
    tap_ok(ok && groups > 0 && differ == 0,
           "%s: four cells in AVX2's lanes give the one-cell walk's tangents bit for bit "
           "(%zu groups of 4 in 28 directions, heights and negated, with and without "
           "curvature: %zu cells differ)",
           what, groups, differ);
#else
    tap_skip(what, "no AVX2 copy in this build (x86-64 GCC builds it)");
#endif
}

static void check_dsm(const char *name, const ss_grid *g, void *user)
{
    (void)user;
    check_grid(name, g, 0.0);
    check_lanes(name, g);
}

int main(void)
{
    ss_grid city = box_march_city(90);
    check_grid("a synthetic city", &city, 0.0);
    /* A radius of 2 km: curvature that matters across 90 m. */
    check_grid("a synthetic city", &city, 1.0 / (2.0 * 2000.0));
    check_bands("a synthetic city", &city);
    check_devices_and_lines("a synthetic city", &city);
    check_lanes("a synthetic city", &city);
    box_march_holes(&city);
    check_grid("a city with holes, 1 x 1.5 m cells", &city, 0.0);
    check_bands("a city with holes, 1 x 1.5 m cells", &city);
    check_lanes("a city with holes, 1 x 1.5 m cells", &city);
    ss_grid_free(&city);
    ss_grid row = box_march_strip(300, 1);
    check_grid("one row", &row, 0.0);
    ss_grid_free(&row);
    /* Rows of three pieces (box_sky_walk.h's SS_SKY_PIECE), the last
     * ending on a group of three cells and one alone. */
    ss_grid strip = box_march_strip(531, 7);
    check_grid("a strip of 531 x 7", &strip, 0.0);
    check_bands("a strip of 531 x 7", &strip);
    ss_grid_free(&strip);
    ss_grid column = box_march_strip(1, 300);
    check_grid("one column", &column, 0.0);
    ss_grid_free(&column);
    ss_grid tower = box_march_tower();
    check_grid("one tower on a plain", &tower, 0.0);
    check_bands("one tower on a plain", &tower);
    check_lanes("one tower on a plain", &tower);
    ss_grid_free(&tower);
    /* Rolling hills on a slope, 3 blocks by 3 and parts of them: low
     * horizons, so the walks pass over the blocks that cannot rise above
     * them, and walk on far up the slope and to the ridge. */
    ss_grid hills = box_march_hills();
    check_grid("rolling hills", &hills, 0.0);
    check_grid("rolling hills", &hills, 1.0 / (2.0 * 3000.0));
    check_bands("rolling hills", &hills);
    check_lanes("rolling hills", &hills);
    ss_grid_free(&hills);
    shared_dem_run("goteborg_kronenhuset_dsm_1m.tif", "the Gothenburg DSM", check_dsm, NULL);
    return tap_done();
}
