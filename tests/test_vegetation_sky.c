/* Trees in the sky view (doc/vegetation.md, "svf"): the crowns' sweep
 * (ss_canopy_sky) against the closed form of an infinite hedge on flat
 * ground, and against an independent ray march over DSM, trunk and canopy
 * (steps of 0.1 cell, the nearest cell, heights at the cells' centres'
 * distances as digital lines take them) on a synthetic scene and on the
 * Gothenburg 1 m DSM and CDSM where ../shared/data has them (skipped
 * otherwise). The march runs twice: with crowns taken down to the ground
 * (the sweep's --trunk-gaps ignore, so what differs is the lines'
 * sampling) and with the gaps under crowns open (the knob's error). The
 * bands svf makes of the share (ss_canopy_svf_bands) on four cells. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "lines.h"
#include "tap.h"
#include "testlib.h"
#include "tree_scenes.h"

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
}

static double rad(double deg)
{
    return deg * M_PI / 180.0;
}

/* A horizon of rise t hides sin h (geometric) or sin^2 h (horizontal) of
 * one direction's sky, clipped at the horizontal. */
static double hidden(ss_svf_definition def, double t)
{
    if (!(t > 0.0))
        return 0.0;
    return def == SS_SVF_DEF_GEOMETRIC ? t / sqrt(1.0 + t * t) : t * t / (1.0 + t * t);
}

static int library_sky(const ss_grid *g, const ss_canopy *cn, int directions, ss_svf_definition def,
                       ss_trunk_gaps gaps, float *solid, float *crown)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = directions;
    int ok = ss_canopy_sky(ctx, g, cn, &opt, def, gaps, solid, crown) == SS_OK;
    if (!ok)
        tap_diag("library: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return ok;
}

/* The share a hedge of height H hides from d across, over all azimuths.
 * The direction at angle phi from the hedge's normal meets it at d / cos
 * phi, so its horizon rises H cos phi / d over the half of the azimuths
 * facing it: geometric (1/2pi) int sin h dphi = atan(H/d) / pi; horizontal
 * (1/2pi) int sin^2 h dphi = (1 - 1/sqrt(1 + (H/d)^2)) / 2. */
static double hedge_share(ss_svf_definition def, double H, double d)
{
    double a = H / d;
    return def == SS_SVF_DEF_GEOMETRIC ? atan(a) / M_PI : 0.5 * (1.0 - 1.0 / sqrt(1.0 + a * a));
}

/* A hedge one cell thick, H tall (trunk 0), along a whole column of flat
 * ground, seen from the cell d across: its centre line is d away, its
 * face d - 1/2. Digital lines take cells up to half a cell beside the ray,
 * so they meet the hedge between the two: the sweep's share lies between
 * the closed forms at d and d - 1/2 (with 0.001 for the directions'
 * sampling), and tends to the centre line's as d grows. */
static void hedge(void)
{
    const int width = 81, height = 801, col = 10, directions = 360;
    const double H = 10.0;
    ss_grid g = test_grid(width, height, 1, 1);
    size_t n = (size_t)width * height;
    float *canopy = malloc(n * sizeof(float)), *crown = malloc(n * sizeof(float));
    tree_hedge(&g, canopy, col, H);
    ss_canopy cn = {canopy, NULL, 0.0, 0.03};
    static const int ds[] = {3, 5, 10, 20, 40};
    for (int def = SS_SVF_DEF_GEOMETRIC; def <= SS_SVF_DEF_HORIZONTAL; ++def) {
        const char *name = def == SS_SVF_DEF_GEOMETRIC ? "geometric" : "horizontal";
        for (ss_trunk_gaps gaps = SS_TRUNK_GAPS_IGNORE; gaps <= SS_TRUNK_GAPS_OPEN; ++gaps) {
            int ok = library_sky(&g, &cn, directions, (ss_svf_definition)def, gaps, NULL, crown);
            int within = ok;
            double far_err = 0.0;
            for (size_t k = 0; ok && k < sizeof ds / sizeof *ds; ++k) {
                double centre = hedge_share((ss_svf_definition)def, H, ds[k]),
                       face = hedge_share((ss_svf_definition)def, H, ds[k] - 0.5);
                double got = crown[(size_t)(height / 2) * width + col + ds[k]];
                within = within && got >= centre - 0.001 && got <= face + 0.001;
                if (ds[k] >= 10)
                    far_err = fmax(far_err, fabs(got - centre));
                tap_diag("hedge %s, gaps %s, d = %d: crowns hide %.5f, closed form %.5f at the "
                         "centre line, %.5f at the face",
                         name, gaps ? "open" : "ignore", ds[k], got, centre, face);
            }
            tap_ok(within && far_err <= 0.0015,
                   "an infinite hedge 10 m tall, %s SVF, --trunk-gaps %s, %d directions: the "
                   "crowns' share between the closed forms at the centre line and the face at "
                   "3 to 40 m, within %.5f of the centre line's from 10 m (<= 0.0015)",
                   name, gaps ? "open" : "ignore", directions, far_err);
        }
    }
    free(canopy), free(crown);
    ss_grid_free(&g);
}

typedef struct {
    double lo, hi;
} span;

static int by_lo(const void *a, const void *b)
{
    double x = ((const span *)a)->lo, y = ((const span *)b)->lo;
    return (x > y) - (x < y);
}


/* The march from cell (r, c) along grid azimuth az: the share of the
 * direction's sky the surface hides (*solid), and the share crowns hide
 * above it, crowns down to the ground (*columns) or from their trunks
 * (*gaps, the union of the elevations each crowned sample hides). */
static void march(const ss_grid *g, const ss_canopy *cn, ss_svf_definition def, int r, int c,
                  double az, span *spans, double *solid, double *columns, double *gaps)
{
    size_t i = (size_t)r * g->width + c;
    double du = sin(rad(az)), dv = -cos(rad(az)), z = g->z[i];
    double ts = -HUGE_VAL, ttop = -HUGE_VAL;
    size_t n = 0;
    for (double d = 0.1;; d += 0.1) {
        int cc = (int)floor(c + 0.5 + d * du), rr = (int)floor(r + 0.5 + d * dv);
        if (cc < 0 || rr < 0 || cc >= g->width || rr >= g->height)
            break;
        if (cc == c && rr == r)
            continue;
        size_t j = (size_t)rr * g->width + cc;
        if (!isfinite(g->z[j]))
            continue;
        /* the cell's centre's distance along the azimuth */
        double along = (cc - c) * du * g->cell_x_m - (rr - r) * cos(rad(az)) * g->cell_y_m;
        if (!(along > 0))
            continue;
        ts = fmax(ts, (g->z[j] - z) / along);
        double top = cn->height_m[j], bottom = tree_trunk_at(cn, j);
        ttop = fmax(ttop, (g->z[j] + top - z) / along);
        if (top > bottom)
            spans[n++] = (span){(g->z[j] + bottom - z) / along, (g->z[j] + top - z) / along};
    }
    *solid = hidden(def, ts);
    *columns = hidden(def, fmax(ts, ttop)) - *solid;
    qsort(spans, n, sizeof *spans, by_lo);
    double sum = 0.0, lo = ts, hi = ts; /* the union's measure above ts, in shares */
    for (size_t k = 0; k < n; ++k) {
        double a = fmax(spans[k].lo, ts), b = spans[k].hi;
        if (b <= a)
            continue;
        if (a > hi) {
            sum += hidden(def, hi) - hidden(def, lo);
            lo = a;
        }
        hi = fmax(hi, b);
    }
    *gaps = sum + hidden(def, hi) - hidden(def, lo);
}

/* svfveg = 1 - the crowns' share, over every `every`-th cell each way:
 * the mean |difference| of --trunk-gaps ignore from the march with
 * crowns down to the ground, and of --trunk-gaps open from the march with
 * the gaps open; and the knob's error, ignore's from the open march. */
static void against_march(const char *what, const ss_grid *g, const ss_canopy *cn, int every)
{
    const int directions = 32;
    size_t n = (size_t)g->width * g->height;
    float *solid = malloc(n * sizeof(float)), *ignore = malloc(n * sizeof(float)),
          *open = malloc(n * sizeof(float));
    span *spans = malloc(sizeof(span) * 20 * (size_t)(g->width + g->height));
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = directions;
    double t0 = now_s();
    int ok =
        library_sky(g, cn, directions, SS_SVF_DEF_GEOMETRIC, SS_TRUNK_GAPS_IGNORE, solid, ignore);
    double t1 = now_s();
    ok = ok && library_sky(g, cn, directions, SS_SVF_DEF_GEOMETRIC, SS_TRUNK_GAPS_OPEN, NULL, open);
    double t2 = now_s();
    double ignore_err = 0.0, open_err = 0.0, knob_err = 0.0, solid_err = 0.0, crowned = 0.0;
    size_t cells = 0;
    for (int r = every / 2; ok && r < g->height; r += every)
        for (int c = every / 2; c < g->width; c += every) {
            size_t i = (size_t)r * g->width + c;
            if (!isfinite(g->z[i]))
                continue;
            double s = 0, col = 0, gap = 0;
            for (int d = 0; d < directions; ++d) {
                double s1, c1, g1;
                march(g, cn, SS_SVF_DEF_GEOMETRIC, r, c, ss_direction_azimuth(&opt, d), spans, &s1,
                      &c1, &g1);
                s += s1 / directions, col += c1 / directions, gap += g1 / directions;
            }
            ignore_err += fabs(ignore[i] - col);
            open_err += fabs(open[i] - gap);
            knob_err += fabs(ignore[i] - gap);
            solid_err += fabs(solid[i] - s);
            crowned += gap;
            ++cells;
        }
    double k = cells ? 1.0 / cells : NAN;
    tap_ok(ok && cells > 0 && crowned * k > 0.01 && ignore_err * k <= 0.01,
           "%s, %zu cells, 32 directions, --trunk-gaps ignore: svfveg within %.4f mean of the "
           "march with crowns down to the ground (<= 0.01; the solid share within %.4f)",
           what, cells, ignore_err * k, solid_err * k);
    tap_ok(ok && cells > 0 && open_err * k <= 0.01,
           "%s, --trunk-gaps open: svfveg within %.4f mean of the march with the gaps under "
           "crowns open (<= 0.01; crowns hide %.4f on average); ignore's error from it %.4f; "
           "sweeps %.3f s ignore, %.3f s open",
           what, open_err * k, crowned * k, knob_err * k, t1 - t0, t2 - t1);
    free(solid), free(ignore), free(open), free(spans);
}


/* 3 m hills, 12 buildings, 60 trees. */
static void synthetic_scene(void)
{
    const int n = 160;
    ss_grid g = test_grid(n, n, 1, 1);
    test_fill(&g, TERRAIN_SMOOTH, 3, 3.0);
    for (int k = 0; k < 12; ++k)
        for (int r = 15 * k % 140; r < 15 * k % 140 + 12; ++r)
            for (int c = 37 * k % 140; c < 37 * k % 140 + 15; ++c)
                g.z[(size_t)r * n + c] += 8.0f + 2 * k;
    float *height = malloc(sizeof(float) * (size_t)n * n);
    tree_plant(&g, height, 5, 50);
    ss_canopy cn = {height, NULL, 0.25, 0.03};
    against_march("a synthetic scene (3 m hills, 12 buildings, 50 trees)", &g, &cn, 5);
    free(height);
    ss_grid_free(&g);
}

static void gothenburg(void)
{
    ss_dem d;
    float *height;
    int found = tree_gothenburg(&d, &height);
    if (found == 0) {
        tap_skip("the Gothenburg DSM and CDSM", "../shared/data is not here");
        tap_skip("the Gothenburg DSM and CDSM, trunk gaps", "../shared/data is not here");
    }
    if (found <= 0)
        return;
    ss_canopy cn = {height, NULL, 0.25, 0.03};
    against_march("the Gothenburg 1 m DSM and CDSM", &d.grid, &cn, 4);
    free(height);
    ss_dem_free(&d);
}

static void refusals(void)
{
    ss_grid g = test_grid(4, 4, 1, 1);
    test_fill(&g, TERRAIN_SMOOTH, 1, 1.0);
    float h[16] = {0}, out[16];
    ss_canopy cn = {h, NULL, 0.25, 0.03};
    ss_ctx *ctx = ss_ctx_new();
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 8;
    tap_ok(ss_canopy_sky(ctx, &g, &cn, &opt, SS_SVF_DEF_RADIATIVE, SS_TRUNK_GAPS_IGNORE, NULL, out) ==
               SS_ERR_ARGUMENT,
           "the radiative definition is refused: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    ss_grid_free(&g);
}

/* The crowns' top horizon (ss_canopy_top_horizon) against brute force on
 * the same digital lines: every cell against every crown top ahead of it
 * on its line, the distance walked between them from the cursor. */
static void crown_horizon(const char *what, const ss_grid *g, const ss_canopy *cn)
{
    size_t n = (size_t)g->width * g->height, wrong = 0, seen = 0;
    float *deg = malloc(n * sizeof(float));
    size_t *cell = malloc(sizeof(size_t) * n);
    double *w = malloc(sizeof(double) * n);
    ss_ctx *ctx = ss_ctx_new();
    const double azimuths[] = {0, 37.5, 90, 201, 333.3};
    for (size_t a = 0; a < sizeof azimuths / sizeof *azimuths; ++a) {
        if (ss_canopy_top_horizon(ctx, g, cn, azimuths[a], deg) != SS_OK) {
            wrong = n;
            break;
        }
        ss_line_set ls;
        ss_line_set_for_azimuth(&ls, g->width, g->height, g->cell_x_m, g->cell_y_m, azimuths[a],
                                SS_LINE_MODEL_DIGITAL);
        for (int line = 0; line < ss_line_count(&ls); ++line) {
            int m = 0;
            ss_line_cursor c = ss_line_cursor_start(&ls, line);
            while (ss_line_cursor_next(&c))
                if (isfinite(g->z[c.cell]))
                    cell[m] = c.cell, w[m++] = c.walked_m;
            for (int p = 0; p < m; ++p) {
                double best = -90.0;
                for (int q = 0; q < p; ++q)
                    if (cn->height_m[cell[q]] > 0)
                        best = fmax(best, atan2(g->z[cell[q]] + cn->height_m[cell[q]] -
                                                    g->z[cell[p]],
                                                w[p] - w[q]) *
                                              180.0 / M_PI);
                seen += best > -90.0;
                wrong += fabs(deg[cell[p]] - best) > 1e-4;
            }
        }
    }
    tap_ok(wrong == 0 && seen > 0,
           "%s: the crowns' top horizon equals brute force on its lines in 5 directions (%zu "
           "cells differ; %zu with a crown ahead)",
           what, wrong, seen);
    free(deg), free(cell), free(w);
    ss_ctx_free(ctx);
}

/* svfveg and svfbuveg from svf and the crown share (ss_canopy_svf_bands):
 * the share clamped to the svf, nodata kept, in place over the share. */
static void svf_bands(void)
{
    const float svf[4] = {0.8f, 0.5f, SS_NODATA, 1.0f};
    float share[4] = {0.25f, 0.75f, SS_NODATA, 0.0f}, total[4];
    ss_canopy_svf_bands(4, svf, share, 0.2, share, total);
    const float veg_want[4] = {0.75f, 0.5f, SS_NODATA, 1.0f};
    const float total_want[4] = {(float)(0.8f - 0.25 * 0.8), (float)(0.5f - 0.5 * 0.8), SS_NODATA,
                                 1.0f};
    tap_ok(memcmp(share, veg_want, sizeof share) == 0 &&
               memcmp(total, total_want, sizeof total) == 0,
           "ss_canopy_svf_bands: svfveg 1 - min(share, svf), svfbuveg svf - min(share, svf)(1 - "
           "T), nodata kept, in place (svfveg %g %g %g %g, svfbuveg %g %g %g %g)",
           share[0], share[1], share[2], share[3], total[0], total[1], total[2], total[3]);
}

int main(void)
{
    svf_bands();
    refusals();
    hedge();
    synthetic_scene();
    gothenburg();
    {
        const int n = 90;
        ss_grid g = test_grid(n, n, 1, 1);
        test_fill(&g, TERRAIN_SMOOTH, 9, 6.0);
        float *height = malloc(sizeof(float) * (size_t)n * n);
        tree_plant(&g, height, 3, 20);
        ss_canopy cn = {height, NULL, 0.25, 0.03};
        crown_horizon("6 m hills, 20 trees", &g, &cn);
        free(height);
        ss_grid_free(&g);
    }
    return tap_done();
}
