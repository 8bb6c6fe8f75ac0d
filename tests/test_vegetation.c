/* Trees (doc/vegetation.md): the crown sweep (ss_canopy_crossed) against
 * closed forms for a cylindrical crown on flat ground; against the solid
 * sweep where crowns stand on the ground (trunk 0: crowns are columns), on
 * digital and box lines, exactly; against brute force on its own digital
 * lines, exactly; and against an independent ray march over DSM, trunk and
 * canopy (steps of 0.05 cell, the nearest cell) on synthetic scenes and on
 * the Gothenburg 1 m DSM and CDSM where ../shared/data has them (skipped
 * otherwise): box lines (the march's heights where the ray is) agree on at
 * least 99.5 % of cells, digital lines (the march's heights at cell
 * centres) are held at the floors they reach. Refusals of bad canopies are
 * checked too. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "testlib.h"
#include "tree_scenes.h"

static const double suns[][2] = {{117, 25}, {203, 40}, {251, 15}, {331, 30}};

static double rad(double deg)
{
    return deg * M_PI / 180.0;
}

/* Classes 0 lit, 1 solid, 2 vegetation from the library: the solid sweep
 * on digital lines without curvature, then the crowns. */
static int box_model; /* library_classes and the march take box lines and columns */

static int library_classes(const ss_grid *g, const ss_canopy *cn, double az, double el,
                           float *klass, unsigned char *crossed_out)
{
    size_t n = (size_t)g->width * g->height;
    ss_ctx *ctx = ss_ctx_new();
    /* The C twin: box shadows, as the crowns, by each cell's own ray. */
    ss_ctx_use_device(ctx, "reference");
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = box_model ? SS_LINES_BOX : SS_LINES_DIGITAL;
    opt.earth_radius_m = 0.0;
    float *sunlit = malloc(n * sizeof(float)), *fraction = malloc(n * sizeof(float));
    unsigned char *crossed = malloc(n);
    int ok = ss_cast_shadow(ctx, g, &opt, az, el, NULL, sunlit, NULL) == SS_OK &&
             ss_canopy_crossed(ctx, g, cn, &opt, az, el, crossed) == SS_OK;
    if (ok)
        ss_canopy_classes(cn, n, sunlit, crossed, klass, fraction);
    if (ok && crossed_out)
        memcpy(crossed_out, crossed, n);
    else
        tap_diag("library: %s", ss_ctx_message(ctx));
    free(sunlit), free(fraction), free(crossed);
    ss_ctx_free(ctx);
    return ok;
}


/* The march: from cell (r, c)'s centre at its height toward the sun, the
 * nearest cell every 0.05 cell, its height at its centre (as digital lines
 * take it: the ray's height at the centre's distance along the azimuth);
 * solid where a cell stands above the ray, vegetation where the ray passes
 * strictly inside another cell's crown. */
static int march_class(const ss_grid *g, const ss_canopy *cn, double zmax, int r, int c,
                       double az, double el)
{
    size_t i = (size_t)r * g->width + c;
    double du = sin(rad(az)) / g->cell_x_m, dv = -cos(rad(az)) / g->cell_y_m, t = tan(rad(el));
    double step = 0.05 * fmin(g->cell_x_m, g->cell_y_m), z = g->z[i];
    int crossed = 0;
    for (double d = step;; d += step) {
        int cc = (int)floor(c + 0.5 + d * du), rr = (int)floor(r + 0.5 + d * dv);
        if (cc < 0 || rr < 0 || cc >= g->width || rr >= g->height || z + d * t > zmax)
            break;
        double along = (cc - c) * g->cell_x_m * sin(rad(az)) - (rr - r) * g->cell_y_m * cos(rad(az));
        double ray = z + (box_model ? d : along) * t; /* box: the ray where it is */
        size_t j = (size_t)rr * g->width + cc;
        if (j == i || !isfinite(g->z[j]))
            continue;
        if (g->z[j] > ray)
            return 1;
        double top = g->z[j] + cn->height_m[j], bottom = g->z[j] + tree_trunk_at(cn, j);
        crossed |= cn->height_m[j] > 0 && ray > bottom && ray < top;
    }
    return crossed ? 2 : 0;
}

static double zmax_of(const ss_grid *g, const ss_canopy *cn)
{
    double m = -INFINITY;
    for (size_t i = 0; i < (size_t)g->width * g->height; ++i)
        if (isfinite(g->z[i]))
            m = fmax(m, g->z[i] + cn->height_m[i]);
    return m;
}

/* The crowns crossed by brute force on the engine's digital lines (the
 * sweep's geometry, not its union of intervals: tree_brute_paths). Returns
 * the cells where the sweep differs: crossed or not, and Beer-Lambert's
 * path (ss_canopy_path), which must be the brute force's. */
static size_t brute_on_lines(const ss_grid *g, const ss_canopy *cn, double az, double el,
                             const unsigned char *crossed, const float *path_m)
{
    size_t n = (size_t)g->width * g->height, wrong = 0;
    double *path = malloc(n * sizeof(double));
    tree_brute_paths(g, cn, az, el, path);
    for (size_t i = 0; i < n; ++i)
        wrong += isfinite(g->z[i]) && ((path[i] > 0.0) != crossed[i] ||
                                       fabs(path_m[i] - path[i]) > 1e-4 * (1 + path[i]));
    free(path);
    return wrong;
}

/* The sweep against brute force on its own lines (exactly), and the
 * library's classes against the march over every cell: at least `floor`
 * percent agree (digital lines take cells up to half a cell beside the
 * ray, doc/vegetation.md). */
static void against_march(const char *what, const ss_grid *g, const ss_canopy *cn, double floor)
{
    size_t n = (size_t)g->width * g->height;
    float *klass = malloc(n * sizeof(float));
    unsigned char *crossed = malloc(n);
    double zmax = zmax_of(g, cn);
    for (size_t s = 0; s < sizeof suns / sizeof *suns; ++s) {
        double az = suns[s][0], el = suns[s][1];
        if (!library_classes(g, cn, az, el, klass, crossed)) {
            tap_ok(0, "%s, sun %g/%g: the library failed", what, az, el);
            continue;
        }
        size_t wrong = 0, on_path = 0;
        if (!box_model) {
            ss_ctx *ctx = ss_ctx_new();
            float *path_m = malloc(n * sizeof(float));
            if (ss_canopy_path(ctx, g, cn, az, el, path_m) != SS_OK)
                wrong = n;
            for (size_t i = 0; wrong == 0 && i < n; ++i)
                on_path += isfinite(g->z[i]) && path_m[i] > 0;
            wrong += brute_on_lines(g, cn, az, el, crossed, path_m);
            tap_ok(wrong == 0 && on_path > 0,
                   "%s, sun %g/%g: the crown sweep and Beer-Lambert's paths equal brute force "
                   "on their lines (%zu cells differ; %zu with a path)",
                   what, az, el, wrong, on_path);
            free(path_m);
            ss_ctx_free(ctx);
        }
        size_t same = 0, valid = 0, veg = 0, veg_same = 0;
        for (int r = 0; r < g->height; ++r)
            for (int c = 0; c < g->width; ++c) {
                size_t i = (size_t)r * g->width + c;
                if (!isfinite(g->z[i]))
                    continue;
                int m = march_class(g, cn, zmax, r, c, az, el);
                ++valid;
                same += m == (int)klass[i];
                veg += m == 2;
                veg_same += m == 2 && klass[i] == 2.0f;
            }
        double agree = 100.0 * same / valid;
        tap_ok(agree >= floor && veg > 0,
               "%s, sun %g/%g: classes agree with the march on %.3f %% of cells (>= %g); "
               "%zu march cells in vegetation shadow, %.2f %% of them found",
               what, az, el, agree, floor, veg, veg ? 100.0 * veg_same / veg : 0.0);
    }
    free(klass);
    free(crossed);
}

/* A cylinder of radius R from B to H above flat ground at the grid's
 * centre; the crown raster and explicit trunks. */
static void cylinder(ss_grid *g, float *height, float *trunk, double R, double B, double H)
{
    int n = g->width;
    tree_cylinder(g, height, n / 2 + 0.5, n / 2 + 0.5, R, H);
    for (size_t i = 0; i < (size_t)n * n; ++i)
        trunk[i] = height[i] > 0.0f ? (float)B : 0.0f;
}

static size_t count_set(const unsigned char *v, size_t n)
{
    size_t k = 0;
    for (size_t i = 0; i < n; ++i)
        k += v[i] != 0;
    return k;
}

/* The shadow of a cylinder (R, B, H) under a sun at elevation e is the
 * crown's disc swept from B / tan e to H / tan e away from the sun: its
 * area is the disc's plus 2 R (H - B) / tan e. The raster's disc stands
 * for the disc. Rasterization: each line across the shadow (2R + 1 of
 * them, 1 / cos a apart, a the azimuth's angle to the lines' axis) may
 * gain or lose a cell at either end. Forgetting the trunk would lose 2R B
 * / tan e cells, over 100. */
static void cylinder_closed_form(void)
{
    const int n = 240;
    ss_grid g = test_grid(n, n, 1, 1);
    size_t cells = (size_t)n * n;
    float *height = malloc(cells * sizeof(float)), *trunk = malloc(cells * sizeof(float));
    unsigned char *crossed = malloc(cells);
    const double R = 8.5, B = 3, H = 12;
    cylinder(&g, height, trunk, R, B, H);
    size_t disc = 0;
    for (size_t i = 0; i < cells; ++i)
        disc += height[i] > 0;
    ss_canopy cn = {height, trunk, 0.0, 0.03};
    ss_ctx *ctx = ss_ctx_new();
    for (size_t s = 0; s < sizeof suns / sizeof *suns; ++s) {
        double az = suns[s][0], el = suns[s][1];
        double want = disc + 2 * R * (H - B) / tan(rad(el));
        double a = fmax(fabs(sin(rad(az))), fabs(cos(rad(az))));
        double slack = 2 * (2 * R + 1) / a;
        ss_canopy_crossed(ctx, &g, &cn, NULL, az, el, crossed);
        double got = (double)count_set(crossed, cells);
        tap_ok(fabs(got - want) <= slack,
               "cylinder R %g from %g to %g m, sun %g/%g: %.0f cells shaded, closed form %.1f "
               "(%+.2f %%, within %.0f cells)",
               R, B, H, az, el, got, want, 100.0 * (got - want) / want, slack);
    }
    /* Box lines: the crown is its cells' squares, whose shadow is their
     * union's area plus its width w across the sun times (H - B) / tan e;
     * the cells' centres sample it, within a cell at each end of each line
     * across it (w + 1 lines, 1 / cos a apart). */
    ss_sweep_options box;
    ss_sweep_options_default(&box);
    box.lines = SS_LINES_BOX;
    for (size_t s = 0; s < sizeof suns / sizeof *suns; ++s) {
        double az = suns[s][0], el = suns[s][1], lo = INFINITY, hi = -INFINITY;
        for (int r = 0; r < n; ++r) /* the squares' corners across the sun */
            for (int c = 0; c < n; ++c)
                for (int k = 0; height[(size_t)r * n + c] > 0 && k < 4; ++k) {
                    double x = c + (k & 1), y = r + (k >> 1);
                    double across = x * cos(rad(az)) + y * sin(rad(az));
                    lo = fmin(lo, across), hi = fmax(hi, across);
                }
        double want = disc + (hi - lo) * (H - B) / tan(rad(el));
        double a = fmax(fabs(sin(rad(az))), fabs(cos(rad(az))));
        double slack = 2 * (hi - lo + 1) / a;
        ss_canopy_crossed(ctx, &g, &cn, &box, az, el, crossed);
        double got = (double)count_set(crossed, cells);
        tap_ok(fabs(got - want) <= slack,
               "box lines, cylinder R %g from %g to %g m, sun %g/%g: %.0f cells shaded, closed "
               "form %.1f (%+.2f %%, within %.0f cells)",
               R, B, H, az, el, got, want, 100.0 * (got - want) / want, slack);
    }
    /* The same crown by the trunk ratio B / H gives the same cells. */
    unsigned char *by_ratio = malloc(cells);
    ss_canopy ratio = {height, NULL, B / H, 0.03};
    ss_canopy_crossed(ctx, &g, &ratio, NULL, 117, 25, by_ratio);
    ss_canopy_crossed(ctx, &g, &cn, NULL, 117, 25, crossed);
    tap_ok(memcmp(by_ratio, crossed, cells) == 0, "a trunk ratio B / H shades as trunks of B");
    free(by_ratio);
    ss_ctx_free(ctx);
    free(height), free(trunk), free(crossed);
    ss_grid_free(&g);
}

/* A slim crown high on its trunk: light passes under it. Down-sun of its
 * edge the ray from a cell at distance k meets the crown over (k, k + 2R)
 * and its heights over (B, H) / tan e: lit close by (k + 2R < B / tan e),
 * shaded further (past B / tan e - 2R up to H / tan e), lit again beyond. */
static void light_under_the_crown(void)
{
    const int n = 120;
    ss_grid g = test_grid(n, n, 1, 1);
    size_t cells = (size_t)n * n;
    float *height = malloc(cells * sizeof(float)), *trunk = malloc(cells * sizeof(float));
    unsigned char *crossed = malloc(cells);
    const double R = 1.5, B = 8, H = 12, az = 180, el = 30; /* sun due south */
    cylinder(&g, height, trunk, R, B, H);
    ss_canopy cn = {height, trunk, 0.0, 0.03};
    ss_ctx *ctx = ss_ctx_new();
    ss_canopy_crossed(ctx, &g, &cn, NULL, az, el, crossed);
    double t = tan(rad(el));
    int lit_near = 1, shaded_mid = 1, lit_far = 1;
    /* Down-sun is north: rows above the crown's centre row n / 2. */
    for (int k = 1; k < 50; ++k) {
        int r = n / 2 - 1 - k; /* k cells beyond the crown's northern edge row n/2 - 1 */
        double d_edge = k;     /* distance to the crown's cells n/2 - 1 .. n/2 + 1 */
        int hit = crossed[(size_t)r * n + n / 2];
        if (d_edge + 3 < B / t - 1)
            lit_near &= !hit;
        else if (d_edge + 3 > B / t + 1 && d_edge < H / t - 1)
            shaded_mid &= hit;
        else if (d_edge > H / t + 1)
            lit_far &= !hit;
    }
    tap_ok(lit_near && !crossed[(size_t)(n / 2 - 2) * n + n / 2],
           "light passes under a crown whose trunk (%g m) is above the ray: the cells next to "
           "it down-sun are lit",
           B);
    tap_ok(shaded_mid && lit_far, "further down-sun the crown shades, then no longer");
    ss_ctx_free(ctx);
    free(height), free(trunk), free(crossed);
    ss_grid_free(&g);
}


/* Trunk 0: every crown is a column from the ground, so the solid sweep of
 * DSM + canopy shades exactly the cells that the sweep of the DSM or the
 * crowns shade (cells without a crown; those with one have another
 * surface there). */
static void columns_equal_crowns(int box)
{
    box_model = box;
    const int n = 160;
    ss_grid g = test_grid(n, n, 1, 1), raised = test_grid(n, n, 1, 1);
    test_fill(&g, TERRAIN_SMOOTH, 7, 15.0);
    size_t cells = (size_t)n * n;
    float *height = malloc(cells * sizeof(float)), *a = malloc(cells * sizeof(float)),
          *b = malloc(cells * sizeof(float));
    tree_plant(&g, height, 11, 40);
    for (size_t i = 0; i < cells; ++i)
        raised.z[i] = g.z[i] + height[i];
    ss_canopy cn = {height, NULL, 0.0, 0.0}, none = {height, NULL, 0.0, 0.0};
    float *zero = calloc(cells, sizeof(float));
    none.height_m = zero;
    for (size_t s = 0; s < sizeof suns / sizeof *suns; ++s) {
        double az = suns[s][0], el = suns[s][1];
        library_classes(&g, &cn, az, el, a, NULL);
        library_classes(&raised, &none, az, el, b, NULL);
        size_t same = 0, free_cells = 0, shaded = 0;
        for (size_t i = 0; i < cells; ++i) {
            if (height[i] > 0)
                continue;
            ++free_cells;
            shaded += a[i] != 0;
            same += (a[i] != 0) == (b[i] != 0);
        }
        tap_ok(same == free_cells && shaded > 0,
               "%strunk 0, sun %g/%g: crowns shade as solid columns on %zu of %zu cells (%zu "
               "shaded)",
               box ? "box lines, " : "", az, el, same, free_cells, shaded);
    }
    box_model = 0;
    free(zero), free(height), free(a), free(b);
    ss_grid_free(&g);
    ss_grid_free(&raised);
}

/* Hills of `relief` metres (0: flat ground), 12 buildings, 60 trees. */
static void synthetic_scene(const char *what, double relief, int box, double floor)
{
    const int n = 200;
    ss_grid g = test_grid(n, n, 1, 1);
    test_fill(&g, TERRAIN_SMOOTH, 3, relief > 0 ? relief : 1.0);
    for (size_t i = 0; relief == 0 && i < (size_t)n * n; ++i)
        g.z[i] = 0.0f;
    for (int k = 0; k < 12; ++k) /* buildings */
        for (int r = 15 * k % 170; r < 15 * k % 170 + 12; ++r)
            for (int c = 37 * k % 180; c < 37 * k % 180 + 15; ++c)
                g.z[(size_t)r * n + c] += 8.0f + 2 * k;
    float *height = malloc(sizeof(float) * (size_t)n * n);
    tree_plant(&g, height, 5, 60);
    ss_canopy cn = {height, NULL, 0.25, 0.03};
    box_model = box;
    against_march(what, &g, &cn, floor);
    box_model = 0;
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
    }
    if (found <= 0)
        return;
    ss_canopy cn = {height, NULL, 0.25, 0.03};
    against_march("the Gothenburg 1 m DSM and CDSM", &d.grid, &cn, 98.0);
    box_model = 1;
    against_march("box lines, the Gothenburg 1 m DSM and CDSM", &d.grid, &cn, 99.5);
    box_model = 0;
    free(height);
    ss_dem_free(&d);
}

static void refusals(void)
{
    ss_grid g = test_grid(4, 4, 1, 1);
    test_fill(&g, TERRAIN_SMOOTH, 1, 1.0);
    float h[16] = {0}, t[16] = {0};
    ss_canopy cn = {h, t, 0.25, 0.03};
    ss_ctx *ctx = ss_ctx_new();
    h[5] = -1.0f;
    tap_ok(ss_canopy_check(ctx, &g, &cn) == SS_ERR_INPUT, "a canopy below 0 is refused: %s",
           ss_ctx_message(ctx));
    h[5] = 5.0f, t[5] = 6.0f;
    tap_ok(ss_canopy_check(ctx, &g, &cn) == SS_ERR_INPUT,
           "a trunk above its canopy is refused: %s", ss_ctx_message(ctx));
    t[5] = 1.0f, cn.transmissivity = 1.5;
    tap_ok(ss_canopy_check(ctx, &g, &cn) == SS_ERR_ARGUMENT,
           "transmissivity 1.5 is refused: %s", ss_ctx_message(ctx));
    cn.transmissivity = 0.5;
    tap_ok(ss_canopy_check(ctx, &g, &cn) == SS_OK, "a good canopy passes");
    float path[2] = {2.0f, SS_NODATA}, fraction[2];
    tap_ok(ss_canopy_path_fraction(ctx, 0.5, 1.0, 2, path, fraction) == SS_OK &&
               fabs(fraction[0] - exp(-1.0)) < 1e-7 && fraction[1] == SS_NODATA &&
               ss_canopy_path_fraction(ctx, 0.5, 0.0, 2, path, fraction) == SS_ERR_ARGUMENT &&
               ss_canopy_path_fraction(ctx, 1.5, 1.0, 2, path, fraction) == SS_ERR_ARGUMENT,
           "Beer-Lambert: exp(-G LAD path), nodata kept; a leaf area density of 0 or an "
           "extinction of 1.5 refused: %s",
           ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    ss_grid_free(&g);
}

int main(void)
{
    refusals();
    cylinder_closed_form();
    light_under_the_crown();
    columns_equal_crowns(0);
    columns_equal_crowns(1);
    synthetic_scene("a synthetic scene (3 m hills, 12 buildings, 60 trees)", 3.0, 0, 94.0);
    synthetic_scene("box lines, a synthetic city (flat, 12 buildings, 60 trees)", 0.0, 1, 99.5);
    gothenburg();
    return tap_done();
}
