/* The box model's horizon rasters by each cell's own ray (src/core/
 * box_horizon.c through horizon_walk.c, the default on box lines) against
 * the independent box-model march of tests/box_march.c, cell by cell: the
 * angle, and the distance and height of a point that casts it (the cell's
 * own edge where nothing rises above it), with and without the earth's
 * curvature, along the axes and the diagonals and off them, on a
 * synthetic city, the same with nodata holes and cells longer one way,
 * one row, one column, a tower on a plain, rolling hills and the
 * Gothenburg DSM where ../shared/data has it. The
 * angles alone (four cells at a time in AVX2's lanes) are those given
 * with the distances bit for bit; bands of any height give the whole
 * grid's; OpenCL gives the C twin's; --box-sky lines walks the lines; an
 * infinite height is nodata, not a wall. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "box_march.h"
#include "box_sky_walk.h"
#include "shared_dem.h"
#include "tap.h"
#include "testlib.h"

/* Every direction's three rasters, direction after direction. */
typedef struct {
    size_t cells;
    float *angle, *dist, *cast;
} horizons;

static int keep_direction(int index, double azimuth_deg, const float *angle_deg,
                          const float *dist_m, const float *cast_height_m, void *user)
{
    (void)azimuth_deg;
    horizons *h = user;
    size_t at = (size_t)index * h->cells, bytes = h->cells * sizeof(float);
    memcpy(h->angle + at, angle_deg, bytes);
    if (dist_m)
        memcpy(h->dist + at, dist_m, bytes);
    if (cast_height_m)
        memcpy(h->cast + at, cast_height_m, bytes);
    return 1;
}

static int horizons_new(horizons *h, const ss_grid *g, int directions)
{
    h->cells = (size_t)g->width * g->height;
    size_t n = h->cells * directions;
    h->angle = malloc(n * sizeof(float));
    h->dist = calloc(n, sizeof(float));
    h->cast = calloc(n, sizeof(float));
    return h->angle && h->dist && h->cast;
}

static void horizons_free(horizons *h)
{
    free(h->angle);
    free(h->dist);
    free(h->cast);
}

/* The library's horizons on device (NULL: OpenCL's), want's outputs. */
static int library_horizons(const char *device, const ss_grid *g, const ss_sweep_options *opt,
                            int want, horizons *h, char *err)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, device);
    ss_status st = ss_horizon(ctx, g, opt, want, keep_direction, h);
    if (st != SS_OK)
        snprintf(err, 300, "%s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st == SS_OK;
}

/* What the cells' horizons got wrong, worst over the cells. */
typedef struct {
    double angle, dist, cast;
    double short_of; /* of the horizon, the point named as casting it, degrees */
    size_t nodata;   /* cells without a height given a value, or with one given none */
} worst_seen;

static void raise_to(double *worst, double e)
{
    *worst = e <= *worst ? *worst : isnan(e) ? INFINITY : e;
}

/* The angle against the march's horizon; the distance and casting height
 * name a point the ray shows a top at (the march's point nearest that
 * distance), and that point casts the horizon. The nearest such point is
 * what the library names, but two columns whose tangents tie exactly may
 * round either way, so the test asks only that it casts the horizon. */
static void check_cell(const ss_grid *g, const ss_sweep_options *opt, double curv_k,
                       const horizons *h, int k, int r, int c, worst_seen *w)
{
    size_t i = (size_t)r * g->width + c, at = (size_t)k * h->cells + i;
    if (!isfinite(g->z[i])) {
        w->nodata +=
            h->angle[at] != SS_NODATA || h->dist[at] != SS_NODATA || h->cast[at] != SS_NODATA;
        return;
    }
    w->nodata += h->angle[at] == SS_NODATA || h->dist[at] == SS_NODATA ||
                 h->cast[at] == SS_NODATA;
    double az = ss_direction_azimuth(opt, k) - opt->grid_north_deg;
    double want = box_march_horizon_curved_deg(g, r, c, az, curv_k);
    box_march_point p;
    double cast = h->cast[at] - g->z_origin_m; /* the library's is on the datum */
    box_march_point_near(g, r, c, az, curv_k, h->dist[at], cast, &p);
    raise_to(&w->angle, fabs(h->angle[at] - want));
    raise_to(&w->dist, fabs(h->dist[at] - p.dist_m) / fmax(1.0, p.dist_m));
    raise_to(&w->cast, fabs(cast - p.height_m));
    raise_to(&w->short_of, want - p.elevation_deg);
}

/* Every cell's horizon, its distance and its casting height against the
 * march in 8 directions from 0 (the axes and diagonals), 12 from 3.7 deg
 * and 12 on a grid whose north is 1.3 deg from true north; and the angles
 * asked alone equal to those, bit for bit. */
static void check_grid(const char *what, const ss_grid *g, double curv_k)
{
    static const struct {
        int directions;
        double offset, north;
    } sets[] = {{8, 0.0, 0.0}, {12, 3.7, 0.0}, {12, 3.7, 1.3}};
    worst_seen w = {0};
    size_t alone_differ = 0;
    char err[300] = "";
    int ok = 1;
    for (int s = 0; ok && s < 3; ++s) {
        ss_sweep_options opt =
            box_march_options(sets[s].directions, sets[s].offset, sets[s].north, curv_k);
        horizons all, alone;
        ok = horizons_new(&all, g, opt.directions) && horizons_new(&alone, g, opt.directions) &&
             library_horizons("reference", g, &opt, SS_HORIZON_DISTANCE | SS_HORIZON_CAST_HEIGHT,
                              &all, err) &&
             library_horizons("reference", g, &opt, 0, &alone, err);
        for (int k = 0; ok && k < opt.directions; ++k)
            for (int r = 0; r < g->height; ++r)
                for (int c = 0; c < g->width; ++c)
                    check_cell(g, &opt, curv_k, &all, k, r, c, &w);
        alone_differ +=
            ok && memcmp(all.angle, alone.angle, all.cells * opt.directions * sizeof(float)) != 0;
        horizons_free(&all);
        horizons_free(&alone);
    }
    tap_ok(ok && w.angle <= 1e-4 && w.dist <= 1e-6 && w.cast <= 1e-3 && w.short_of <= 1e-9 &&
               w.nodata == 0,
           "%s%s: each cell's own ray gives the box-model march's horizon (worst %.2g deg, at "
           "most 1e-4), and the distance and height of a point the ray shows a top at (worst "
           "%.2g relative, %.2g m) that casts it (short by %.2g deg at worst) on every cell; %zu "
           "cells with the wrong nodata%s%s",
           what, curv_k > 0 ? ", curved" : "", w.angle, w.dist, w.cast, w.short_of, w.nodata,
           err[0] ? ": " : "", err);
    tap_ok(ok && alone_differ == 0,
           "%s%s: the angles asked alone (%s) are those given with the distances, bit for bit "
           "(%zu of 3 direction sets differ)",
           what, curv_k > 0 ? ", curved" : "",
           ss_sky_lanes_here() ? "in AVX2's lanes" : "no AVX2 here: the one-cell walk both ways",
           alone_differ);
}

typedef struct {
    float *out[3]; /* angle, distance, casting height: direction after direction */
    int width, height;
} keep_rows;

static ss_status keep(void *user, int output, int index, int row0, int n_rows, const float *values)
{
    keep_rows *k = user;
    size_t at = ((size_t)index * k->height + row0) * k->width;
    memcpy(k->out[output] + at, values, sizeof(float) * n_rows * k->width);
    return SS_OK;
}

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    const ss_grid *g = user;
    memcpy(z, g->z + (size_t)row0 * g->width, sizeof(float) * n_rows * g->width);
    return SS_OK;
}

/* A DEM read in bands of 1, 7 and 33 rows gives the whole grid's horizons,
 * distances and casting heights bit for bit, with the earth's curvature. */
static void check_bands(const char *what, const ss_grid *g)
{
    ss_sweep_options opt = box_march_options(12, 3.7, 0.0, 1.0 / (2.0 * 2000.0));
    size_t n = (size_t)g->width * g->height * opt.directions;
    float *whole = malloc(3 * n * sizeof(float)), *banded = malloc(3 * n * sizeof(float));
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    static const int band_rows[] = {1, 7, 33};
    int want = SS_HORIZON_DISTANCE | SS_HORIZON_CAST_HEIGHT, ok = whole && banded;
    size_t differ = 0;
    ss_source src = test_source(g, NULL, NULL, 0, NULL);
    src.z = g->z;
    keep_rows all = {{whole, whole + n, whole + 2 * n}, g->width, g->height};
    ok = ok && ss_horizon_rows(ctx, &src, &opt, want, keep, &all) == SS_OK;
    for (int b = 0; ok && b < 3; ++b) {
        ss_source bands = test_source(g, read_rows, (void *)g, band_rows[b], NULL);
        keep_rows part = {{banded, banded + n, banded + 2 * n}, g->width, g->height};
        for (size_t i = 0; i < 3 * n; ++i)
            banded[i] = NAN;
        ok = ss_horizon_rows(ctx, &bands, &opt, want, keep, &part) == SS_OK;
        differ += ok && memcmp(whole, banded, 3 * n * sizeof(float)) != 0;
    }
    tap_ok(ok && differ == 0,
           "%s: the horizons, distances and casting heights by each cell's own ray in bands of "
           "1, 7 and 33 rows are the whole grid's bit for bit (%zu of 3 differ)%s%s",
           what, differ, ok ? "" : ": ", ok ? "" : ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    free(whole);
    free(banded);
}

/* OpenCL gives the C twin's horizons (the rays run on the host), and
 * --box-sky lines walks the lines, whose horizons differ. */
static void check_devices_and_lines(const char *what, const ss_grid *g)
{
    ss_sweep_options opt = box_march_options(12, 3.7, 0.0, 0.0);
    horizons twin, other;
    char err[300] = "";
    int want = SS_HORIZON_DISTANCE | SS_HORIZON_CAST_HEIGHT;
    int ok = horizons_new(&twin, g, opt.directions) && horizons_new(&other, g, opt.directions) &&
             library_horizons("reference", g, &opt, want, &twin, err);
    size_t n = twin.cells * opt.directions * sizeof(float);
    if (!test_have_pocl()) {
        tap_skip("the box horizons on OpenCL", "no PoCL device is listed");
    } else {
        int same = ok && library_horizons(NULL, g, &opt, want, &other, err) &&
                   memcmp(twin.angle, other.angle, n) == 0 &&
                   memcmp(twin.dist, other.dist, n) == 0 && memcmp(twin.cast, other.cast, n) == 0;
        tap_ok(same,
               "%s: the horizons by each cell's own ray are the same on OpenCL as on the "
               "C twin, bit for bit%s%s",
               what, err[0] ? ": " : "", err);
    }
    opt.box_sky = SS_BOX_SKY_LINES;
    ok = ok && library_horizons("reference", g, &opt, want, &other, err);
    double most = 0.0;
    for (size_t i = 0; ok && i < twin.cells * opt.directions; ++i)
        if (twin.angle[i] != SS_NODATA)
            most = fmax(most, fabs(twin.angle[i] - other.angle[i]));
    tap_ok(ok && most > 1e-3,
           "%s: --box-sky lines walks the box lines instead, off the rays by up to %.3f deg%s%s",
           what, most, err[0] ? ": " : "", err);
    horizons_free(&twin);
    horizons_free(&other);
}

/* Infinite heights are nodata (ss_grid_check counts them so), not walls:
 * the horizons, distances, casting heights and SVF on the given lines (box:
 * each cell's own ray; the others: the engine's walks) of a grid with
 * +-Inf in some cells are those with NaN there, bit for bit. */
static void check_infinities(const char *what, ss_grid *g, ss_line_model lines)
{
    ss_sweep_options opt = box_march_options(12, 3.7, 0.0, 0.0);
    opt.lines = lines;
    size_t n = (size_t)g->width * g->height;
    horizons with_inf, with_nan;
    float *svf_inf = malloc(n * sizeof(float)), *svf_nan = malloc(n * sizeof(float));
    char err[300] = "";
    int want = SS_HORIZON_DISTANCE | SS_HORIZON_CAST_HEIGHT;
    int ok = svf_inf && svf_nan && horizons_new(&with_inf, g, opt.directions) &&
             horizons_new(&with_nan, g, opt.directions);
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    for (int pass = 0; ok && pass < 2; ++pass) {
        for (size_t i = 0; i < n; i += 53)
            g->z[i] = pass ? NAN : i % 2 ? INFINITY : -INFINITY;
        ok = library_horizons("reference", g, &opt, want, pass ? &with_nan : &with_inf, err) &&
             ss_svf(ctx, g, &opt, SS_SVF_DEF_GEOMETRIC, pass ? svf_nan : svf_inf) == SS_OK;
    }
    size_t bytes = with_inf.cells * opt.directions * sizeof(float);
    int same = ok && memcmp(with_inf.angle, with_nan.angle, bytes) == 0 &&
               memcmp(with_inf.dist, with_nan.dist, bytes) == 0 &&
               memcmp(with_inf.cast, with_nan.cast, bytes) == 0 &&
               memcmp(svf_inf, svf_nan, n * sizeof(float)) == 0;
    tap_ok(same,
           "%s: +-Inf heights are nodata to %s, not walls: the horizons, "
           "distances, casting heights and SVF are those with NaN there, bit for bit%s%s",
           what, lines == SS_LINES_BOX ? "each cell's own ray" : "the engine's walks", err[0] ? ": " : "",
           err[0] ? err
           : ok   ? ""
                  : ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    free(svf_inf);
    free(svf_nan);
    horizons_free(&with_inf);
    horizons_free(&with_nan);
}

static void check_dsm(const char *name, const ss_grid *g, void *user)
{
    (void)user;
    check_grid(name, g, 0.0);
}

int main(void)
{
    ss_grid city = box_march_city(90);
    check_grid("a synthetic city", &city, 0.0);
    /* A radius of 2 km: curvature that matters across 90 m. */
    check_grid("a synthetic city", &city, 1.0 / (2.0 * 2000.0));
    check_bands("a synthetic city", &city);
    check_devices_and_lines("a synthetic city", &city);
    box_march_holes(&city);
    check_grid("a city with holes, 1 x 1.5 m cells", &city, 0.0);
    check_bands("a city with holes, 1 x 1.5 m cells", &city);
    check_infinities("a city with holes, 1 x 1.5 m cells", &city, SS_LINES_BOX);
    /* The engine's walks on the other line models read the same heights. */
    check_infinities("a city with holes, interpolated lines", &city, SS_LINES_INTERPOLATED);
    check_infinities("a city with holes, digital lines", &city, SS_LINES_DIGITAL);
    ss_grid_free(&city);
    ss_grid row = box_march_strip(300, 1);
    check_grid("one row", &row, 0.0);
    ss_grid_free(&row);
    /* Rows of three pieces (box_sky_walk.h's SS_SKY_PIECE), the last
     * ending on a group of three cells and one alone. */
    ss_grid strip = box_march_strip(531, 7);
    check_grid("a strip of 531 x 7", &strip, 0.0);
    ss_grid_free(&strip);
    ss_grid column = box_march_strip(1, 300);
    check_grid("one column", &column, 0.0);
    ss_grid_free(&column);
    ss_grid tower = box_march_tower();
    check_grid("one tower on a plain", &tower, 0.0);
    ss_grid_free(&tower);
    /* Rolling hills on a slope: low horizons, so the walks pass over the
     * blocks that cannot rise above them. */
    ss_grid hills = box_march_hills();
    check_grid("rolling hills", &hills, 1.0 / (2.0 * 3000.0));
    check_bands("rolling hills", &hills);
    ss_grid_free(&hills);
    shared_dem_run("goteborg_kronenhuset_dsm_1m.tif", "the Gothenburg DSM", check_dsm, NULL);
    return tap_done();
}
