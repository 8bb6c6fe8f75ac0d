/* City DSMs as flat-topped columns (the box model of UMEP and SOLWEIG): an
 * independent ray march from each cell's top centre through every column
 * the sun's ray crosses (an exact cell traversal, Amanatides & Woo 1987)
 * against skysweep's cast shadows, at suns off the grid axes, on a
 * synthetic city of boxes and on the Gothenburg 1 m DSM where ../shared/data
 * has it (skipped otherwise). The march itself is checked first against a
 * single box's closed-form shadow. skysweep has no box line model yet
 * (doc/model.md, "City DSMs"): the agreement of its two line models is
 * held at the floors measured on 2026-12-02, so that it cannot get worse
 * unnoticed. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_io.h"
#include "tap.h"
#include "testlib.h"

/* 1 where the box-model ray from cell (r, c) toward the sun (azimuth az,
 * elevation el) passes above every column it crosses, else 0. */
static int box_lit(const ss_grid *g, int r, int c, double az, double el, double z_max)
{
    double z0 = g->z[(size_t)r * g->width + c];
    double tan_el = tan(el * M_PI / 180);
    double dx = sin(az * M_PI / 180) / g->cell_x_m;  /* columns per metre */
    double dy = -cos(az * M_PI / 180) / g->cell_y_m; /* rows per metre (north: up) */
    int ci = c, ri = r, sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
    /* Distances (metres) to the next column and row boundaries, and between them. */
    double tx = fabs(dx) > 1e-12 ? 0.5 / fabs(dx) : INFINITY;
    double ty = fabs(dy) > 1e-12 ? 0.5 / fabs(dy) : INFINITY;
    double step_x = fabs(dx) > 1e-12 ? 1.0 / fabs(dx) : INFINITY;
    double step_y = fabs(dy) > 1e-12 ? 1.0 / fabs(dy) : INFINITY;
    for (;;) {
        double t;
        if (tx < ty) {
            t = tx;
            ci += sx;
            tx += step_x;
        } else {
            t = ty;
            ri += sy;
            ty += step_y;
        }
        if (ci < 0 || ri < 0 || ci >= g->width || ri >= g->height || z0 + tan_el * t > z_max)
            return 1;
        float h = g->z[(size_t)ri * g->width + ci];
        if (isfinite(h) && h - z0 > tan_el * t)
            return 0;
    }
}

/* A synthetic city: flat ground with boxes of 6..40 m sides and 4..45 m. */
static ss_grid city(int n)
{
    ss_grid g = test_grid(n, n, 1, 1);
    for (size_t i = 0; i < (size_t)n * n; ++i)
        g.z[i] = 0.0f;
    unsigned s = 7;
    for (int b = 0; b < n * n / 600; ++b) {
        s = s * 1103515245u + 12345u;
        int w = 6 + (int)(s >> 16) % 35;
        s = s * 1103515245u + 12345u;
        int h = 6 + (int)(s >> 16) % 35;
        s = s * 1103515245u + 12345u;
        int c0 = (int)(s >> 16) % n, r0 = (int)((s >> 4) % (unsigned)n);
        s = s * 1103515245u + 12345u;
        float top = 4.0f + (float)((s >> 16) % 41);
        for (int r = r0; r < r0 + h && r < n; ++r)
            for (int c = c0; c < c0 + w && c < n; ++c)
                g.z[(size_t)r * n + c] = top;
    }
    return g;
}

static const char *model_names[] = {"interpolated", "digital"};
/* Measured floors (worst of the four suns), 2026-12-02: the synthetic city
 * 97.22 % and 98.77 %, Gothenburg 90.99 % and 94.18 %. */
static const double city_floor[] = {0.970, 0.985}, goteborg_floor[] = {0.905, 0.940};

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
        wrong += box_lit(&g, r, c, 45, 30, 20.0) != want_lit;
    }
    tap_ok(wrong == 0, "the box march shadows the cells down-sun of a box's corner exactly within "
           "H / tan(e) of it (%d of 39 wrong)", wrong);
    ss_grid_free(&g);
}

/* The share of valid cells where skysweep's shadow equals the box march. */
static double agreement(const ss_grid *g, ss_line_model lines, double az, double el, char *err)
{
    size_t n = (size_t)g->width * g->height;
    float *lit = malloc(n * sizeof(float));
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = lines;
    double z_max = -INFINITY;
    for (size_t i = 0; i < n; ++i)
        if (isfinite(g->z[i]) && g->z[i] > z_max)
            z_max = g->z[i];
    double share = NAN;
    if (ss_cast_shadow(ctx, g, &opt, az, el, NULL, lit, NULL) == SS_OK) {
        size_t same = 0, valid = 0;
        for (int r = 0; r < g->height; ++r)
            for (int c = 0; c < g->width; ++c) {
                size_t i = (size_t)r * g->width + c;
                if (!isfinite(g->z[i]))
                    continue;
                valid++;
                same += (lit[i] == 1.0f) == box_lit(g, r, c, az, el, z_max);
            }
        share = (double)same / (double)valid;
    } else {
        snprintf(err, 300, "%s", ss_ctx_message(ctx));
    }
    ss_ctx_free(ctx);
    free(lit);
    return share;
}

static void compare(const char *what, const ss_grid *g, const double *floors)
{
    const double suns[][2] = {{117, 25}, {203, 40}, {251, 15}, {331, 30}};
    for (int m = 0; m < 2; ++m) {
        double worst = 1, sum = 0;
        char err[300] = "";
        for (int k = 0; k < 4; ++k) {
            double a = agreement(g, (ss_line_model)m, suns[k][0], suns[k][1], err);
            worst = fmin(worst, a);
            sum += a;
        }
        tap_ok(worst >= floors[m],
               "%s, %s lines: the shadows of 4 off-axis suns agree with the box-model march on "
               "%.2f %% of cells on average, %.2f %% at worst (floor %.1f %%)%s%s",
               what, model_names[m], 100 * sum / 4, 100 * worst, 100 * floors[m],
               err[0] ? ": " : "", err);
    }
}

int main(void)
{
    march_closed_form();
    ss_grid g = city(300);
    compare("a synthetic city (300 m, boxes of 4..45 m)", &g, city_floor);
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
        ss_dem_free(&dem);
    } else {
        tap_ok(0, "cannot read %s: %s", path, ss_ctx_message(ctx));
    }
    ss_ctx_free(ctx);
    return tap_done();
}
