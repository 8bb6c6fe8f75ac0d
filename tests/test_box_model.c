/* City DSMs as flat-topped columns (the box model of UMEP and SOLWEIG):
 * skysweep's cast shadows against an independent box-model ray march
 * (tests/box_march.c) at suns off the grid axes, on a synthetic city of
 * boxes and on the Gothenburg 1 m DSM where ../shared/data has it (skipped
 * otherwise). The march itself is checked first against a single box's
 * closed-form shadow. Box shadows by each cell's own ray (the default,
 * src/core/box_shadow.c) must agree on every cell; the box lines' own
 * shadows (doc/model.md, "City DSMs") on at least 99.5 % of cells for
 * every sun, exactly on the grid's axes, better with more lines per cell,
 * hillshade's cast shadows too (by each cell's own ray, exact),
 * and the same on OpenCL as on the C twin; the interpolated and digital models are held at the floors
 * measured on 2026-12-02, so that they cannot get worse unnoticed. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "box_march.h"
#include "dem_io.h"
#include "skysweep_sites.h"
#include "tap.h"
#include "testlib.h"

/* The OpenCL comparison leaves PoCL's device threads running at exit,
 * where LeakSanitizer's tracer crashed under the sanitizer build ("Tracer
 * caught signal 11", google/sanitizers#1353) before the TAP plan was
 * flushed. Leak checks are off for this program only (sanitizer builds read
 * this hook; others ignore it); the box walk's allocations are the engine's,
 * which tests/test_banded checks for leaks on the same lines. Address and
 * undefined-behaviour checks stay on. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "detect_leaks=0";
}

static const double suns[][2] = {{117, 25}, {203, 40}, {251, 15}, {331, 30}};

/* One box of height H on flat ground, the sun along a diagonal: the march
 * shadows a ground cell exactly when its ray meets the box below H, which
 * for a cell straight down-sun of the box's corner is the closed form
 * distance < H / tan(el) from the corner. */
static void march_closed_form(void)
{
    const int n = 120;
    ss_grid g = test_grid(n, n, 1, 1);
    for (size_t i = 0; i < (size_t)n * n; ++i)
        g.z[i] = 0.0f;
    for (int r = 40; r < 60; ++r)
        for (int c = 60; c < 80; ++c)
            g.z[(size_t)r * n + c] = 20.0f;
    /* The sun in the north-east (45 deg) at 30 deg: cells south-west of the
     * box's south-west corner (60, 60) along the diagonal are shadowed while
     * their distance to that corner is below 20 / tan 30 = 34.64 m. */
    int wrong = 0;
    for (int k = 1; k < 40; ++k) {
        int r = 59 + k, c = 60 - k; /* centres at (c + 0.5, r + 0.5) */
        double to_corner = hypot(60.0 - (c + 0.5), (r + 0.5) - 60.0);
        int want_lit = to_corner > 20.0 / tan(30 * M_PI / 180);
        wrong += box_march_lit(&g, r, c, 45, 30, 20.0) != want_lit;
    }
    tap_ok(wrong == 0, "the box march shadows the cells down-sun of a box's corner exactly within "
           "H / tan(e) of it (%d of 39 wrong)", wrong);
    ss_grid_free(&g);
}

/* Box lines' own shadows where box_lines > 0 (the families' walks), else
 * the default: each cell's own ray. */
static ss_sweep_options options(ss_line_model lines, int box_lines)
{
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = lines;
    if (box_lines > 0) {
        opt.box_lines = box_lines;
        opt.box_shadows = SS_BOX_SHADOWS_LINES;
        opt.box_sky = SS_BOX_SKY_LINES;
    }
    return opt;
}

/* The agreement of a line model over the four suns: mean and worst. */
static void agreement_of(const ss_grid *g, const ss_sweep_options *opt, double *mean,
                         double *worst, char *err)
{
    *worst = 1;
    *mean = 0;
    for (int k = 0; k < 4; ++k) {
        double a = box_march_agreement(g, opt, suns[k][0], suns[k][1], err);
        *worst = isnan(a) ? a : fmin(*worst, a);
        *mean += a / 4;
    }
}

static void compare(const char *what, const ss_grid *g, const double floors[3])
{
    for (int m = 0; m < 3; ++m) {
        ss_sweep_options opt = options((ss_line_model)m, m == SS_LINES_BOX ? 32 : 0);
        char err[300] = "";
        double mean, worst;
        agreement_of(g, &opt, &mean, &worst, err);
        tap_ok(worst >= floors[m],
               "%s, %s lines: the shadows of 4 off-axis suns agree with the box-model march on "
               "%.2f %% of cells on average, %.2f %% at worst (floor %.1f %%)%s%s",
               what, ss_line_model_name(opt.lines), 100 * mean, 100 * worst, 100 * floors[m],
               err[0] ? ": " : "", err);
    }
}

/* The default box shadows: each cell's own ray, exact. */
static void box_march_exact(const char *what, const ss_grid *g)
{
    ss_sweep_options opt = options(SS_LINES_BOX, 0);
    char err[300] = "";
    double mean, worst;
    agreement_of(g, &opt, &mean, &worst, err);
    tap_ok(worst == 1.0,
           "%s, box shadows by each cell's own ray: the shadows of 4 off-axis suns agree with "
           "the box-model march on every cell (worst %.4f %%)%s%s",
           what, 100 * worst, err[0] ? ": " : "", err);
}

/* Rows of a shade into a whole grid. */
typedef struct {
    float *shade;
    int width;
} shade_rows;

static ss_status keep_shade(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)output, (void)index;
    shade_rows *s = user;
    memcpy(s->shade + (size_t)row0 * s->width, values, sizeof(float) * n_rows * s->width);
    return SS_OK;
}

/* hillshade's cast shadows on box lines (the C twin): 1 on exactly the
 * cells the march shades, gdaldem's shade (no cast shadows) elsewhere, by
 * each cell's own ray (its counter moves); the families' walks agree on
 * at least 99.5 % of cells. */
static void hillshade_cast_exact(const char *what, const ss_grid *g)
{
    size_t n = (size_t)g->width * g->height;
    float *plain = malloc(n * sizeof(float)), *cast = malloc(n * sizeof(float)),
          *lines = malloc(n * sizeof(float));
    ss_source src = test_source(g, NULL, NULL, 0, NULL);
    src.z = g->z; /* held whole */
    ss_hillshade_options ho = {.azimuth_deg = 251, .altitude_deg = 15, .z_factor = 1};
    ss_sweep_options opt = options(SS_LINES_BOX, 0), walked = options(SS_LINES_BOX, 32);
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    shade_rows p = {plain, g->width}, c = {cast, g->width}, l = {lines, g->width};
    int ok = ss_hillshade_rows(ctx, &src, &opt, &ho, keep_shade, &p) == SS_OK;
    ho.cast_shadows = 1;
    ok = ok && ss_hillshade_rows(ctx, &src, &opt, &ho, keep_shade, &c) == SS_OK;
    uint64_t marched_steps = ss_ctx_counters(ctx).box_march_steps;
    ok = ok && ss_hillshade_rows(ctx, &src, &walked, &ho, keep_shade, &l) == SS_OK;
    double z_max = box_march_top(g);
    size_t wrong = 0, shaded = 0, valid = 0, lines_same = 0;
    for (int r = 0; ok && r < g->height; ++r)
        for (int col = 0; col < g->width; ++col) {
            size_t i = (size_t)r * g->width + col;
            if (!isfinite(g->z[i]))
                continue;
            int lit = box_march_lit(g, r, col, ho.azimuth_deg, ho.altitude_deg, z_max);
            ++valid;
            shaded += !lit;
            wrong += cast[i] != (lit ? plain[i] : 1.0f);
            lines_same += lines[i] == cast[i];
        }
    tap_ok(ok && wrong == 0 && shaded > 0 && marched_steps == 1,
           "%s, hillshade --cast-shadows on box lines: each cell's own ray, 1 on the march's %zu "
           "shaded cells and the plain shade elsewhere (%zu of %zu cells differ)%s%s",
           what, shaded, wrong, valid, ok ? "" : ": ", ok ? "" : ss_ctx_message(ctx));
    tap_ok(ok && lines_same >= 0.995 * valid,
           "%s, hillshade --cast-shadows on 32 box lines' walks: the same shade on %.3f %% of "
           "cells", what, valid ? 100.0 * lines_same / valid : 0.0);
    ss_ctx_free(ctx);
    free(plain), free(cast), free(lines);
}

/* The march runs on the host whatever the device: ss_cast_shadow and
 * hillshade's cast shadows on box lines give the C twin's answer on
 * OpenCL, cell for cell, and march there (the counter moves). */
static void marched_on_every_device(const char *what, const ss_grid *g)
{
    if (!test_have_pocl()) {
        tap_skip("the box shadows' march on OpenCL", "no PoCL device");
        return;
    }
    size_t n = (size_t)g->width * g->height;
    const char *devices[] = {"reference", "Portable"};
    float *lit[2], *shade[2];
    ss_source src = test_source(g, NULL, NULL, 0, NULL);
    src.z = g->z; /* held whole */
    ss_sweep_options opt = options(SS_LINES_BOX, 0);
    ss_hillshade_options ho = {
        .azimuth_deg = 251, .altitude_deg = 15, .z_factor = 1, .cast_shadows = 1};
    int ok = 1;
    uint64_t marched = 0;
    char err[300] = "";
    for (int k = 0; k < 2; ++k) {
        lit[k] = malloc(n * sizeof(float));
        shade[k] = malloc(n * sizeof(float));
        ss_ctx *ctx = ss_ctx_new();
        ss_ctx_use_device(ctx, devices[k]);
        shade_rows rows = {shade[k], g->width};
        ok = ok && lit[k] && shade[k] &&
             ss_cast_shadow(ctx, g, &opt, 117, 25, NULL, lit[k], NULL) == SS_OK &&
             ss_hillshade_rows(ctx, &src, &opt, &ho, keep_shade, &rows) == SS_OK;
        if (!ok && !err[0])
            snprintf(err, sizeof err, "%s", ss_ctx_message(ctx));
        if (k == 1)
            marched = ss_ctx_counters(ctx).box_march_steps;
        ss_ctx_free(ctx);
    }
    size_t lit_differ = 0, shade_differ = 0;
    for (size_t i = 0; ok && i < n; ++i) {
        lit_differ += memcmp(&lit[0][i], &lit[1][i], sizeof(float)) != 0;
        shade_differ += memcmp(&shade[0][i], &shade[1][i], sizeof(float)) != 0;
    }
    tap_ok(ok && lit_differ == 0 && shade_differ == 0 && marched == 2,
           "%s, box shadows on OpenCL: each cell's own ray (%llu marches), the C twin's "
           "shadow on every cell (%zu differ) and hillshade's cast shade (%zu differ)%s%s",
           what, (unsigned long long)marched, lit_differ, shade_differ, err[0] ? ": " : "", err);
    for (int k = 0; k < 2; ++k)
        free(lit[k]), free(shade[k]);
}

/* Rows of a grid for a source read in bands; rows from fail_at on fail. */
typedef struct {
    const ss_grid *g;
    int fail_at;
} grid_reader;

static ss_status read_grid_rows(void *user, int row0, int n_rows, float *z)
{
    const grid_reader *r = user;
    if (row0 + n_rows > r->fail_at)
        return SS_ERR_INPUT;
    memcpy(z, r->g->z + (size_t)row0 * r->g->width, sizeof(float) * n_rows * r->g->width);
    return SS_OK;
}

/* One sun for every cell: azimuth 117, elevation 25 degrees. */
static ss_status one_sun(ss_ctx *ctx, int index, int row0, int n_rows, ss_sun_step *step,
                         void *user)
{
    (void)ctx, (void)index, (void)row0, (void)n_rows, (void)user;
    memset(step, 0, sizeof *step);
    step->azimuth_deg = step->grid_azimuth_deg = 117.0;
    step->elevation_deg = step->apparent_elevation_deg = 25.0;
    return SS_OK;
}

static ss_status keep_sunlit(void *user, int output, int index, int row0, int n_rows,
                             const float *values)
{
    return output == SS_OUT_SUNLIT ? keep_shade(user, output, index, row0, n_rows, values)
                                   : SS_OK;
}

/* Box shadows by each cell's own ray in bands (a DEM read band by band,
 * its heights held whole for the march): the shadow product and
 * hillshade's cast shade give the whole grid's answer bit for bit, for
 * bands of 1, 7 and 64 rows, and march (the counter moves); a reader that
 * fails stops the run with a message, and so does a DEM of nodata alone. */
static void marched_in_bands(const char *what, const ss_grid *g)
{
    size_t n = (size_t)g->width * g->height;
    float *lit = malloc(n * sizeof(float)), *shade = malloc(n * sizeof(float)),
          *lit_b = malloc(n * sizeof(float)), *shade_b = malloc(n * sizeof(float));
    ss_sweep_options opt = options(SS_LINES_BOX, 0);
    ss_hillshade_options ho = {
        .azimuth_deg = 251, .altitude_deg = 15, .z_factor = 1, .cast_shadows = 1};
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    ss_source whole = test_source(g, NULL, NULL, 0, NULL);
    whole.z = g->z;
    shade_rows whole_rows = {shade, g->width};
    int ok = lit && shade && lit_b && shade_b &&
             ss_cast_shadow(ctx, g, &opt, 117, 25, NULL, lit, NULL) == SS_OK &&
             ss_hillshade_rows(ctx, &whole, &opt, &ho, keep_shade, &whole_rows) == SS_OK;
    static const int band_rows[] = {1, 7, 64};
    size_t differ = 0;
    uint64_t before = ss_ctx_counters(ctx).box_march_steps;
    grid_reader reader = {g, g->height};
    for (int b = 0; ok && b < 3; ++b) {
        ss_source src = test_source(g, read_grid_rows, &reader, band_rows[b], NULL);
        shade_rows lit_rows = {lit_b, g->width}, shade_rows_b = {shade_b, g->width};
        for (size_t i = 0; i < n; ++i)
            lit_b[i] = shade_b[i] = NAN;
        ok = ss_shadow_rows(ctx, &src, &opt, one_sun, NULL, keep_sunlit, &lit_rows) == SS_OK &&
             ss_hillshade_rows(ctx, &src, &opt, &ho, keep_shade, &shade_rows_b) == SS_OK;
        differ += ok && (memcmp(lit, lit_b, n * sizeof(float)) != 0 ||
                         memcmp(shade, shade_b, n * sizeof(float)) != 0);
    }
    uint64_t marched = ss_ctx_counters(ctx).box_march_steps - before;
    char err[300] = "";
    if (!ok)
        snprintf(err, sizeof err, "%s", ss_ctx_message(ctx));
    reader.fail_at = g->height / 2;
    ss_source failing = test_source(g, read_grid_rows, &reader, 16, NULL);
    shade_rows sink = {lit_b, g->width};
    int refused = ss_shadow_rows(ctx, &failing, &opt, one_sun, NULL, keep_sunlit, &sink) != SS_OK &&
                  strstr(ss_ctx_message(ctx), "could not read DEM rows") != NULL;
    /* A DEM read in bands with no valid height is refused, as the engine
     * refuses one. */
    ss_grid holes = test_grid(g->width, g->height, g->cell_x_m, g->cell_y_m);
    for (size_t i = 0; i < n; ++i)
        holes.z[i] = NAN;
    grid_reader no_heights = {&holes, holes.height};
    ss_source empty = test_source(&holes, read_grid_rows, &no_heights, 16, NULL);
    refused = refused &&
              ss_shadow_rows(ctx, &empty, &opt, one_sun, NULL, keep_sunlit, &sink) == SS_ERR_INPUT &&
              strstr(ss_ctx_message(ctx), "no valid height") != NULL;
    ss_grid_free(&holes);
    tap_ok(ok && differ == 0 && marched == 6 && refused,
           "%s, box shadows in bands of 1, 7 and 64 rows: shadow and hillshade's cast shade are "
           "the whole grid's bit for bit (%zu of 3 band heights differ), by each cell's own ray "
           "(%llu marches, want 6); a failing reader and a DEM of nodata are reported (%s)%s%s",
           what, differ, (unsigned long long)marched, refused ? "yes" : "no", err[0] ? ": " : "",
           err);
    ss_ctx_free(ctx);
    free(lit), free(shade), free(lit_b), free(shade_b);
}

/* Suns along the axes: a line of slope 0 runs through the centres of the
 * cells it delivers to, so box lines are the march itself. (Along the
 * diagonals rays run through cell corners, where the march and the lines
 * each break the tie their own way.) */
static void box_on_axes(const ss_grid *g)
{
    const double az[] = {0, 90, 180, 270};
    ss_sweep_options opt = options(SS_LINES_BOX, 32);
    double worst = 1;
    char err[300] = "";
    for (int k = 0; k < 4; ++k)
        worst = fmin(worst, box_march_agreement(g, &opt, az[k], 20 + 7 * k, err));
    tap_ok(worst == 1.0,
           "box lines: suns along the grid's axes shadow exactly the cells the march does "
           "(worst %.4f %% of cells)%s%s",
           100 * worst, err[0] ? ": " : "", err);
}

/* A cell's line runs at most 1 / (2N) cell beside its centre: more lines
 * per cell leave fewer cells whose ray passes a column's corner on the
 * other side. */
static void box_lines_converge(const ss_grid *g)
{
    const int counts[] = {1, 4, 16, 64};
    double mean[4];
    char err[300] = "";
    int rising = 1;
    for (int k = 0; k < 4; ++k) {
        ss_sweep_options opt = options(SS_LINES_BOX, counts[k]);
        double worst;
        agreement_of(g, &opt, &mean[k], &worst, err);
        rising &= k == 0 || mean[k] > mean[k - 1];
    }
    tap_ok(rising && mean[3] >= 0.999,
           "box lines: agreement rises with the lines per cell: 1: %.2f %%, 4: %.2f %%, 16: "
           "%.2f %%, 64: %.3f %% (at least 99.9 %%)%s%s",
           100 * mean[0], 100 * mean[1], 100 * mean[2], 100 * mean[3], err[0] ? ": " : "", err);
}

/* OpenCL runs the same headers: the same horizons (float rounding) and
 * distances on box lines. */
static void box_devices_agree(const ss_grid *g)
{
    size_t n = (size_t)g->width * g->height;
    float *a[2], *d[2];
    char err[2][512] = {"", ""};
    const char *devs[] = {"reference", NULL};
    int ok = 1;
    for (int k = 0; k < 2; ++k) {
        a[k] = malloc(n * sizeof(float));
        d[k] = malloc(n * sizeof(float));
        ok &= test_lib_horizon(devs[k], g, 117, 0, 0, SS_LINES_BOX, a[k], d[k], err[k],
                               sizeof err[k]) == SS_OK;
    }
    double worst = 0, worst_d = 0;
    for (size_t i = 0; ok && i < n; ++i) {
        worst = fmax(worst, fabs(a[0][i] - a[1][i]));
        worst_d = fmax(worst_d, fabs(d[0][i] - d[1][i]));
    }
    tap_ok(ok && worst <= 1e-4 && worst_d <= 1e-3,
           "box lines: OpenCL's horizons equal the C twin's within %.2g deg (at most 1e-4) and "
           "distances within %.2g m %s%s",
           worst, worst_d, err[0][0] ? err[0] : "", err[1]);
    for (int k = 0; k < 2; ++k) {
        free(a[k]);
        free(d[k]);
    }
}

/* The sky-view factor differs from the box model's as the shadows do:
 * mean |SVF - the march's| over 16 directions off the diagonals (there
 * rays run through cell corners, a tie each breaks its own way). */
static void box_svf(const char *what, const ss_grid *g)
{
    double error[3];
    char err[300] = "";
    for (int m = 0; m < 3; ++m) { /* digital lines, box lines, each cell's own ray */
        ss_sweep_options opt = options(m ? SS_LINES_BOX : SS_LINES_DIGITAL, m == 1 ? 32 : 0);
        opt.directions = 16;
        opt.offset_deg = 5;
        error[m] = box_march_svf_error(g, &opt, NULL, err);
    }
    tap_ok(error[1] <= 1e-3 && error[1] <= error[0] / 5 && error[2] <= 1e-6,
           "%s: the geometric SVF of 32 box lines is off the box model's by %.5f on average (at "
           "most 0.001), digital lines' by %.5f, each cell's own ray's (the default) by %.2g (at "
           "most 1e-6)%s%s",
           what, error[1], error[0], error[2], err[0] ? ": " : "", err);
}

/* What box lines do not model is refused in one line naming them:
 * radius-limited horizons and site horizons. */
static void box_refusals(const ss_grid *g)
{
    ss_sweep_options opt = options(SS_LINES_BOX, 32);
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    float *out = malloc(sizeof(float) * (size_t)g->width * g->height);
    ss_status st = ss_openness(ctx, g, &opt, 0, 30.0, out);
    tap_ok(st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), "box"),
           "box lines: a radius-limited openness is refused: %s", ss_ctx_message(ctx));
    ss_point_grid *pg = NULL;
    ss_point_site site = {.col = 20.5, .row = 30.5};
    ss_point_horizon_result res[32];
    st = ss_point_grid_new(ctx, g, &pg);
    if (st == SS_OK)
        st = ss_point_horizon(ctx, pg, &opt, &site, res);
    tap_ok(st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), "box"),
           "box lines: site horizons are refused: %s", ss_ctx_message(ctx));
    ss_point_grid_free(pg);
    st = ss_bare_pass(ctx, g, 30, SS_LINES_BOX, out);
    tap_ok(st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), "box"),
           "box lines: the bare pass is refused: %s", ss_ctx_message(ctx));
    ss_grid flat = test_grid(20, 20, 1, 2.5);
    for (int i = 0; i < 400; ++i)
        flat.z[i] = 0.0f;
    st = ss_cast_shadow(ctx, &flat, &opt, 117, 25, NULL, out, NULL);
    tap_ok(st == SS_ERR_ARGUMENT && strstr(ss_ctx_message(ctx), "twice"),
           "box lines: cells 2.5 times as long as wide are refused: %s", ss_ctx_message(ctx));
    /* Each cell's own ray takes any cell shape. */
    for (int i = 0; i < 400; i += 7)
        flat.z[i] = (float)(i % 13);
    ss_sweep_options own = options(SS_LINES_BOX, 0);
    char err[300] = "";
    double a = box_march_agreement(&flat, &own, 117, 25, err);
    tap_ok(a == 1.0,
           "box shadows by each cell's own ray on cells 2.5 times as long as wide: the march's "
           "on %.2f %% of cells%s%s",
           100 * a, err[0] ? ": " : "", err);
    ss_grid_free(&flat);
    free(out);
    ss_ctx_free(ctx);
}

/* Measured floors (worst of the four suns), 2026-12-02: the synthetic city
 * 97.22 % and 98.77 %, Gothenburg 90.99 % and 94.18 %; box lines must meet
 * 99.5 % (issue 18). */
static const double city_floor[] = {0.970, 0.985, 0.995}, goteborg_floor[] = {0.905, 0.940, 0.995};

int main(void)
{
    march_closed_form();
    ss_grid g = box_march_city(300);
    compare("a synthetic city (300 m, boxes of 4..45 m)", &g, city_floor);
    box_march_exact("a synthetic city", &g);
    hillshade_cast_exact("a synthetic city", &g);
    marched_in_bands("a synthetic city", &g);
    marched_on_every_device("a synthetic city", &g);
    box_on_axes(&g);
    box_lines_converge(&g);
    box_devices_agree(&g);
    box_refusals(&g);
    box_svf("a synthetic city", &g);
    ss_grid_free(&g);
    const char *path = TOP_SRCDIR "/../shared/data/goteborg_kronenhuset_dsm_1m.tif";
    FILE *f = fopen(path, "rb");
    if (!f) {
        tap_skip("the Gothenburg DSM", "../shared/data is not here");
        return tap_done();
    }
    fclose(f);
    ss_ctx *ctx = ss_ctx_new();
    ss_dem dem;
    const char *paths[] = {path};
    if (ss_dem_read(ctx, paths, 1, NULL, &dem) == SS_OK) {
        compare("the Gothenburg 1 m DSM", &dem.grid, goteborg_floor);
        box_march_exact("the Gothenburg 1 m DSM", &dem.grid);
        hillshade_cast_exact("the Gothenburg 1 m DSM", &dem.grid);
        marched_in_bands("the Gothenburg 1 m DSM", &dem.grid);
        marched_on_every_device("the Gothenburg 1 m DSM", &dem.grid);
        box_svf("the Gothenburg 1 m DSM", &dem.grid);
        ss_dem_free(&dem);
    } else {
        tap_ok(0, "cannot read %s: %s", path, ss_ctx_message(ctx));
    }
    ss_ctx_free(ctx);
    return tap_done();
}
