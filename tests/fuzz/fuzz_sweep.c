/* Fuzz target: the sweep and its products (ss_svf in its three definitions,
 * ss_horizon with distances, ss_bare_pass) on small grids whose size, cell
 * size, options and heights come from the fuzzer's bytes. Heights are drawn
 * from the awkward values first: NaN, +-Inf, +-1e38, denormals, -0, +-1e7
 * (the plausibility limit) and just beyond it, -9999, plus raw floats; an
 * input that ends early leaves the rest of the grid nodata.
 *
 * Layout: w, h (1..20 each; 1..64 with the openness radius of 24 cells),
 * flags (bit 0 digital lines, bit 1 distances,
 * bits 2-3 SVF definition, 3 = an invalid one), directions (byte % 12,
 * 0 invalid; >= 250: a million and one), offset (int16 / 90 degrees), cell
 * sizes (two nibbles into a table with 0, -1, NaN, Inf, 1e-6, 1e7, ...),
 * earth radius and refraction (3 bits each into tables with invalid
 * values) and, in the same byte's top two bits, the radius of a positive
 * openness within a radius (none; 2.5 cells: scanned windows; 24 cells on
 * grids of up to 64 cells a side: lines longer than the radius, whose
 * windows take the previous chunk's suffix hulls and the prefix hulls;
 * NaN: refused), then one code byte per cell (+ 4 bytes for a raw float).
 *
 * Checked: the status is SS_OK exactly when the grid and the options pass
 * their checks, else SS_ERR_INPUT / SS_ERR_ARGUMENT with a one-line
 * message; every output cell is SS_NODATA where the height is not finite
 * and a finite value in range elsewhere (SVF 0..1, horizon -90..90 deg,
 * distance >= 0, openness 0..180 deg); and on tame grids (finite |z| <=
 * 1000 m, cells of 1..1e4 m) the horizon equals the brute force of
 * tests/testlib.c.
 *
 * Built with -DFUZZ_SWEEP_OPENCL it also runs the default OpenCL device and
 * requires the same answers as the C reference (up to float rounding). */
#include "config.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "skysweep.h"
#include "../testlib.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct {
    const uint8_t *p;
    size_t n;
} reader;

static int take(reader *r, uint8_t *b)
{
    if (!r->n)
        return 0;
    *b = *r->p++;
    r->n--;
    return 1;
}

static float take_float(reader *r)
{
    uint8_t b[4] = {0, 0, 0, 0};
    for (int i = 0; i < 4; ++i)
        take(r, &b[i]);
    float f;
    memcpy(&f, b, sizeof f);
    return f;
}

static const double cell_table[16] = {1,    30,   0.5,      1e-6, 1e7,      2.5,  1000, 1e-3,
                                      0,    -1,   NAN,      INFINITY, 5e-7, 1.1e7, 4.9e-324, 90};
static const double radius_table[8] = {0, 0, 6371000, 1e3, 1e9, 999, NAN, -6371000};
/* Openness radii in cells (of the larger cell size), NaN refused. */
static const double openness_cells[4] = {0, 2.5, 24, NAN};
static const double refraction_table[8] = {0, 0.13, 0.99, 0.999999, 1, -0.1, NAN, 0.5};

static float height_of(uint8_t code, reader *r)
{
    switch (code & 15) {
    case 0: return NAN;
    case 1: return INFINITY;
    case 2: return -INFINITY;
    case 3: return 1e38f;
    case 4: return -1e38f;
    case 5: return 1e-45f;       /* smallest denormal */
    case 6: return -0.0f;
    case 7: return 1e7f;         /* the plausibility limit */
    case 8: return -1e7f;
    case 9: return 10000001.0f;  /* just beyond it */
    case 10: return -9999.0f;    /* the nodata value, as a height */
    case 11: return FLT_MIN / 3; /* a denormal */
    case 12:
    case 13: return (float)(code >> 4) * ((code & 1) ? 7.5f : -3.0f);
    default: return take_float(r);
    }
}

typedef struct {
    const ss_grid *g;
    int want_dist;
    int calls;
    float *angle_copy; /* direction 0, for the brute-force comparison */
} sink_state;

static int check_sink(int index, double azimuth_deg, const float *angle, const float *dist,
                      const float *cast, void *user)
{
    sink_state *s = user;
    const ss_grid *g = s->g;
    size_t n = (size_t)g->width * g->height;
    FUZZ_CHECK(index == s->calls, "direction %d after %d", index, s->calls);
    FUZZ_CHECK(azimuth_deg >= 0 && azimuth_deg < 360, "azimuth %g", azimuth_deg);
    FUZZ_CHECK((dist != NULL) == (s->want_dist != 0), "distance grid %p", (const void *)dist);
    FUZZ_CHECK((cast != NULL) == (s->want_dist != 0), "casting height grid %p", (const void *)cast);
    for (size_t c = 0; c < n; ++c) {
        if (!isfinite(g->z[c])) {
            FUZZ_CHECK(angle[c] == SS_NODATA && (!dist || dist[c] == SS_NODATA) &&
                           (!cast || cast[c] == SS_NODATA),
                       "nodata cell %zu: angle %g", c, (double)angle[c]);
            continue;
        }
        FUZZ_CHECK(isfinite(angle[c]) && angle[c] >= -90.001f && angle[c] <= 90.001f,
                   "cell %zu (z %g): horizon %g deg", c, (double)g->z[c], (double)angle[c]);
        if (dist)
            FUZZ_CHECK(isfinite(dist[c]) && dist[c] >= 0, "cell %zu: distance %g", c,
                       (double)dist[c]);
        /* A caster exactly where a distance is, at a finite height. */
        if (cast)
            FUZZ_CHECK(dist[c] == 0 ? cast[c] == SS_NODATA : isfinite(cast[c]),
                       "cell %zu: distance %g, casting height %g", c, (double)dist[c],
                       (double)cast[c]);
    }
    if (index == 0 && s->angle_copy)
        memcpy(s->angle_copy, angle, n * sizeof *angle);
    s->calls++;
    return 1;
}

static void check_status(ss_ctx *ctx, ss_status st, ss_status want, const char *what)
{
    FUZZ_CHECK(st == want, "%s: status %d, want %d (%s)", what, (int)st, (int)want,
               ss_ctx_message(ctx));
    if (st != SS_OK) {
        const char *m = ss_ctx_message(ctx);
        FUZZ_CHECK(m[0] && !strchr(m, '\n'), "%s: message '%s'", what, m);
    }
}

/* Runs the products on one device; fills svf and horizon (direction 0). */
static void run_products(const char *device, const ss_grid *g, const ss_sweep_options *opt,
                         int definition, int want_dist, double radius_m, ss_status want,
                         ss_status want_bare, float *svf, float *angle0, float *open)
{
    /* One context per device for the whole run: an OpenCL context keeps its
     * built kernels, as a long CLI run does. */
    static ss_ctx *contexts[2];
    int k = device ? 0 : 1;
    if (!contexts[k]) {
        contexts[k] = ss_ctx_new();
        ss_ctx_use_device(contexts[k], device);
    }
    ss_ctx *ctx = contexts[k];
    size_t n = (size_t)g->width * g->height;
    /* Choice 3 is no definition: refused whatever the grid. */
    ss_status st = ss_svf(ctx, g, opt, (ss_svf_definition)(definition > 2 ? 7 : definition), svf);
    check_status(ctx, st, definition > 2 ? SS_ERR_ARGUMENT : want, "ss_svf");
    for (size_t c = 0; st == SS_OK && c < n; ++c) {
        if (!isfinite(g->z[c]))
            FUZZ_CHECK(svf[c] == SS_NODATA, "nodata cell %zu: svf %g", c, (double)svf[c]);
        else
            FUZZ_CHECK(svf[c] >= 0 && svf[c] <= 1, "cell %zu (z %g): svf %g", c,
                       (double)g->z[c], (double)svf[c]);
    }
    sink_state s = {g, want_dist, 0, angle0};
    st = ss_horizon(ctx, g, opt, want_dist ? SS_HORIZON_DISTANCE | SS_HORIZON_CAST_HEIGHT : 0,
                    check_sink, &s);
    check_status(ctx, st, want, "ss_horizon");
    if (st == SS_OK)
        FUZZ_CHECK(s.calls == opt->directions, "%d of %d directions", s.calls, opt->directions);
    /* Openness within a radius: the radius walks (ss_passes.h). */
    st = ss_openness(ctx, g, opt, 0, radius_m, open);
    check_status(ctx, st, isnan(radius_m) ? SS_ERR_ARGUMENT : want, "ss_openness");
    for (size_t c = 0; st == SS_OK && c < n; ++c) {
        if (!isfinite(g->z[c]))
            FUZZ_CHECK(open[c] == SS_NODATA, "nodata cell %zu: openness %g", c, (double)open[c]);
        else
            FUZZ_CHECK(open[c] >= 0 && open[c] <= 180, "cell %zu (z %g), radius %g m: openness %g",
                       c, (double)g->z[c], radius_m, (double)open[c]);
    }
    float *bare = calloc(n, sizeof *bare);
    st = ss_bare_pass(ctx, g, opt->offset_deg, opt->lines, bare);
    check_status(ctx, st, want_bare, "ss_bare_pass");
    free(bare);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    uint8_t bw = 0, bh = 0, flags = 0, bd = 0, o0 = 0, o1 = 0, cells = 0, curv = 0;
    take(&r, &bw);
    take(&r, &bh);
    take(&r, &flags);
    take(&r, &bd);
    take(&r, &o0);
    take(&r, &o1);
    take(&r, &cells);
    take(&r, &curv);
    int radius_cells = curv >> 6, side = radius_cells == 2 ? 64 : 20;
    int w = 1 + bw % side, h = 1 + bh % side;
    int definition = (flags >> 2) & 3, want_dist = (flags >> 1) & 1;
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = (flags & 1) ? SS_LINES_DIGITAL : SS_LINES_INTERPOLATED;
    opt.directions = bd >= 250 ? 1000001 : bd % 12;
    opt.offset_deg = (double)(int16_t)(o0 | (o1 << 8)) / 90.0;
    opt.earth_radius_m = radius_table[curv & 7];
    opt.refraction_k = refraction_table[(curv >> 3) & 7];

    ss_ctx *ctx = ss_ctx_new();
    ss_grid g;
    ss_status st = ss_grid_alloc(ctx, &g, w, h, cell_table[cells & 15], cell_table[cells >> 4]);
    FUZZ_CHECK(st == SS_OK, "grid_alloc %d x %d: %s", w, h, ss_ctx_message(ctx));
    size_t n = (size_t)w * h;
    for (size_t c = 0; c < n; ++c) {
        uint8_t code;
        if (!take(&r, &code))
            break; /* the rest stays NAN (nodata) */
        g.z[c] = height_of(code, &r);
    }
    ss_status opt_st = ss_sweep_options_check(ctx, &opt);
    ss_status grid_st = ss_grid_check(ctx, &g, NULL);
    FUZZ_CHECK(opt_st == SS_OK || opt_st == SS_ERR_ARGUMENT, "options status %d", (int)opt_st);
    FUZZ_CHECK(grid_st == SS_OK || grid_st == SS_ERR_INPUT, "grid status %d: %s", (int)grid_st,
               ss_ctx_message(ctx));
    ss_status want = opt_st != SS_OK ? opt_st : grid_st;
    /* The bare pass takes one azimuth (reduced mod 360) and the line model
     * only: the grid decides. */
    ss_status want_bare = grid_st;

    /* The openness radius in cells of the larger size (of 1 m where that is
     * not finite: the grid's check refuses such a grid). */
    double cell_m = fmax(fabs(g.cell_x_m), fabs(g.cell_y_m));
    double radius_m = openness_cells[radius_cells] * (isfinite(cell_m) ? cell_m : 1.0);
    float *svf = malloc(n * sizeof *svf), *angle = malloc(n * sizeof *angle),
          *open = malloc(n * sizeof *open);
    run_products("reference", &g, &opt, definition, want_dist, radius_m, want, want_bare, svf,
                 angle, open);

#ifdef FUZZ_SWEEP_OPENCL
    {
        float *svf_cl = malloc(n * sizeof *svf_cl), *angle_cl = malloc(n * sizeof *angle_cl),
              *open_cl = malloc(n * sizeof *open_cl);
        run_products(NULL, &g, &opt, definition, want_dist, radius_m, want, want_bare, svf_cl,
                     angle_cl, open_cl);
        for (size_t c = 0; want == SS_OK && c < n; ++c) {
            if (definition <= 2)
                FUZZ_CHECK(fabsf(svf[c] - svf_cl[c]) <= 1e-4f,
                           "cell %zu: svf reference %.9g, OpenCL %.9g", c, (double)svf[c],
                           (double)svf_cl[c]);
            FUZZ_CHECK(fabsf(angle[c] - angle_cl[c]) <= 1e-3f,
                       "cell %zu: horizon reference %.9g, OpenCL %.9g", c, (double)angle[c],
                       (double)angle_cl[c]);
            if (!isnan(radius_m))
                FUZZ_CHECK(fabsf(open[c] - open_cl[c]) <= 1e-3f,
                           "cell %zu: openness within %g m, reference %.9g, OpenCL %.9g", c,
                           radius_m, (double)open[c], (double)open_cl[c]);
        }
        free(svf_cl);
        free(angle_cl);
        free(open_cl);
    }
#endif

    /* Tame grids: the first direction against the brute force. */
    int tame = want == SS_OK && g.cell_x_m >= 1 && g.cell_x_m <= 1e4 && g.cell_y_m >= 1 &&
               g.cell_y_m <= 1e4;
    for (size_t c = 0; tame && c < n; ++c)
        tame = !isfinite(g.z[c]) || fabsf(g.z[c]) <= 1000.0f;
    if (tame) {
        double *ref = malloc(n * sizeof *ref), *near = malloc(n * sizeof *near),
               *claimed = malloc(n * sizeof *claimed);
        double curv_k =
            opt.earth_radius_m > 0 ? 0.5 * (1.0 - opt.refraction_k) / opt.earth_radius_m : 0.0;
        test_brute_horizon(&g, ss_direction_azimuth(&opt, 0), curv_k, (int)opt.lines, NULL, ref,
                           near, claimed);
        for (size_t c = 0; c < n; ++c)
            if (isfinite(g.z[c]))
                FUZZ_CHECK(fabs(angle[c] - ref[c]) <= 1e-3 * 180 / M_PI,
                           "cell %zu of %d x %d, az %.9g: horizon %.9g, brute force %.9g", c, w,
                           h, ss_direction_azimuth(&opt, 0), (double)angle[c], ref[c]);
        free(ref);
        free(near);
        free(claimed);
    }

    free(svf);
    free(angle);
    free(open);
    ss_grid_free(&g);
    ss_ctx_free(ctx);
    return 0;
}
