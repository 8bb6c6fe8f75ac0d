/* The one driver in bands (src/core/engine.c) against the whole grid: the
 * same SVF (every definition) and openness on random terrain with nodata
 * holes crossing band edges, for bands from 1 row to more than the grid,
 * bands that do not divide the grid, directions on the axes and diagonals
 * and between them in all four quadrants, both line models, curvature on
 * and off, on the C twin. Every row must be written exactly once, failures
 * of the reader must stop the run with its status, and shares of the
 * directions (MPI) must add up through the reduce hook. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "testlib.h"

typedef struct {
    const ss_grid *g;
    float *out;
    int *writes; /* per row */
    int fail_at_row;
} band_io_state;

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    band_io_state *s = user;
    if (s->fail_at_row >= row0 && s->fail_at_row < row0 + n_rows)
        return SS_ERR_INPUT;
    memcpy(z, s->g->z + (size_t)row0 * s->g->width, sizeof(float) * (size_t)n_rows * s->g->width);
    return SS_OK;
}

static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)output, (void)index;
    band_io_state *s = user;
    memcpy(s->out + (size_t)row0 * s->g->width, values,
           sizeof(float) * (size_t)n_rows * s->g->width);
    for (int r = row0; r < row0 + n_rows; ++r)
        s->writes[r]++;
    return SS_OK;
}

typedef struct {
    int directions;
    double offset;
    int model;
    int curved;
} sweep_case;

static void options_for(const sweep_case *k, ss_sweep_options *opt)
{
    ss_sweep_options_default(opt);
    opt->directions = k->directions;
    opt->offset_deg = k->offset;
    opt->lines = (ss_line_model)k->model;
    /* A small planet makes curvature matter on a small grid. */
    opt->earth_radius_m = k->curved ? 2e4 : 0;
    opt->refraction_k = 0;
}

/* kind: 0..2 the SVF definitions, 3 positive and 4 negative openness. */
static ss_status whole(const ss_grid *g, const ss_sweep_options *opt, int kind, float *out)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    ss_status st = kind < 3 ? ss_svf(ctx, g, opt, (ss_svf_definition)kind, out)
                            : ss_openness(ctx, g, opt, kind == 4, 0, out);
    if (st != SS_OK)
        tap_diag("whole-grid run failed: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st;
}

static ss_status banded(const ss_grid *g, const ss_sweep_options *opt, int kind, int band_rows,
                        float *out, int *writes, ss_band_stats *stats)
{
    band_io_state s = {g, out, writes, -1};
    ss_source src = test_source(g, read_rows, &s, band_rows, stats);
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    ss_status st = ss_sky_rows(ctx, &src, opt, (ss_sky_term)kind, 0.0, NULL, write_rows, &s);
    if (st != SS_OK)
        tap_diag("banded run failed: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st;
}

static const char *kind_name[] = {"geometric SVF", "horizontal SVF", "radiative SVF",
                                  "positive openness", "negative openness"};

/* Compares for every band height; returns the worst difference seen. */
static void compare(const ss_grid *g, const char *terrain, const sweep_case *k, int kind,
                    const int *band_rows, int n_band_rows)
{
    size_t n = (size_t)g->width * g->height;
    ss_sweep_options opt;
    options_for(k, &opt);
    float *ref = malloc(sizeof(float) * n), *out = malloc(sizeof(float) * n);
    int *writes = malloc(sizeof(int) * g->height);
    int ok = whole(g, &opt, kind, ref) == SS_OK;
    double worst = 0;
    int worst_rows = 0, rows_ok = 1, nodata_ok = 1;
    for (int b = 0; ok && b < n_band_rows; ++b) {
        memset(writes, 0, sizeof(int) * g->height);
        for (size_t c = 0; c < n; ++c)
            out[c] = -12345.0f;
        ok = banded(g, &opt, kind, band_rows[b], out, writes, NULL) == SS_OK;
        for (int r = 0; ok && r < g->height; ++r)
            rows_ok &= writes[r] == 1;
        for (size_t c = 0; ok && c < n; ++c) {
            if (ref[c] == SS_NODATA || out[c] == SS_NODATA) {
                nodata_ok &= ref[c] == out[c];
                continue;
            }
            double e = fabs(ref[c] - out[c]);
            if (e > worst || !isfinite(e)) {
                worst = isfinite(e) ? e : INFINITY;
                worst_rows = band_rows[b];
            }
        }
    }
    double tol = kind < 3 ? 2e-6 : 2e-4; /* float sums in another order; degrees for openness */
    tap_ok(ok && rows_ok && nodata_ok && worst <= tol,
           "%s, %s, %d dirs from %.1f deg, %s lines, curvature %s: banded == whole grid for %d "
           "band heights (worst %.2g at %d rows; every row written once: %s)",
           terrain, kind_name[kind], k->directions, k->offset,
           ss_line_model_name(k->model), k->curved ? "on" : "off",
           n_band_rows, worst, worst_rows, rows_ok ? "yes" : "no");
    free(ref);
    free(out);
    free(writes);
}

static void random_terrain(void)
{
    static const int band_rows[] = {1, 2, 3, 5, 7, 16, 40, 200};
    static const sweep_case cases[] = {
        {8, 0.0, SS_LINES_INTERPOLATED, 0},  /* axes and diagonals */
        {13, 7.3, SS_LINES_INTERPOLATED, 0}, /* between them, all quadrants */
        {13, 7.3, SS_LINES_INTERPOLATED, 1}, {8, 0.0, SS_LINES_DIGITAL, 0},
        {13, 7.3, SS_LINES_DIGITAL, 1}, {13, 7.3, SS_LINES_BOX, 0},
        {8, 0.0, SS_LINES_BOX, 1},
    };
    struct {
        const char *name;
        terrain_kind kind;
        int w, h;
        double cx, cy, relief;
    } terrains[] = {{"smooth hills 37x53", TERRAIN_SMOOTH, 37, 53, 30, 30, 800},
                    {"noise 48x31, 20 x 12 m cells", TERRAIN_NOISE, 48, 31, 20, 12, 150},
                    {"plateaus 33x40", TERRAIN_PLATEAUS, 33, 40, 10, 10, 90},
                    {"spikes 40x33", TERRAIN_SPIKES, 40, 33, 10, 10, 300}};
    for (size_t t = 0; t < sizeof terrains / sizeof *terrains; ++t) {
        ss_grid g = test_grid(terrains[t].w, terrains[t].h, terrains[t].cx, terrains[t].cy);
        test_fill(&g, terrains[t].kind, (unsigned)(11 + t), terrains[t].relief);
        test_holes(&g, (unsigned)(5 + t), 5, 6);
        for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k)
            for (int kind = 0; kind < 5; ++kind) {
                /* The full matrix on the first terrain; one case per kind on the others. */
                if (t > 0 && k != (size_t)(kind % 5))
                    continue;
                compare(&g, terrains[t].name, &cases[k], kind, band_rows,
                        (int)(sizeof band_rows / sizeof *band_rows));
            }
        ss_grid_free(&g);
    }
}

/* Hulls are handed on across band edges (counted), and a reader that fails
 * stops the run with its status. */
static void handoffs_and_failures(void)
{
    ss_grid g = test_grid(30, 60, 10, 10);
    test_fill(&g, TERRAIN_SMOOTH, 3, 200);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 8;
    size_t n = (size_t)g.width * g.height;
    float *out = malloc(sizeof(float) * n);
    int writes[60] = {0};
    ss_band_stats stats = {0};
    ss_status st = banded(&g, &opt, 0, 7, out, writes, &stats);
    tap_ok(st == SS_OK && stats.handoffs > 0 && stats.max_hull_points > 0 &&
               stats.hull_points_handed_on >= stats.handoffs,
           "60 rows in bands of 7: %zu hulls handed on, %.1f points on average, largest %zu",
           stats.handoffs, stats.handoffs ? (double)stats.hull_points_handed_on / stats.handoffs : 0,
           stats.max_hull_points);
    band_io_state s = {&g, out, writes, 33};
    ss_source src = test_source(&g, read_rows, &s, 7, NULL);
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    st = ss_sky_rows(ctx, &src, &opt, SS_SKY_SVF_GEOMETRIC, 0.0, NULL, write_rows, &s);
    tap_ok(st == SS_ERR_INPUT && ss_ctx_message(ctx)[0],
           "a reader failing at row 33 stops the run: status %d, '%s'", (int)st,
           ss_ctx_message(ctx));
    src.band_rows = -1;
    st = ss_sky_rows(ctx, &src, &opt, SS_SKY_SVF_GEOMETRIC, 0.0, NULL, write_rows, &s);
    tap_ok(st == SS_ERR_ARGUMENT, "-1 rows per band is refused: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    free(out);
    ss_grid_free(&g);
}

/* What MPI's reduce does, for processes run one after the other: the
 * first keeps each band's sums in call order, the next adds its own, and
 * the last adds everyone's into its sums, which the library then finishes. */
typedef struct {
    float *kept;
    size_t at;
    int process, processes;
} serial_reduce;

static ss_status reduce_in_turn(void *user, float *sums, size_t n)
{
    serial_reduce *r = user;
    float *kept = r->kept + r->at;
    for (size_t c = 0; c < n; ++c) {
        if (r->process == 0)
            kept[c] = sums[c];
        else if (r->process < r->processes - 1)
            kept[c] += sums[c];
        else
            sums[c] += kept[c];
    }
    r->at += n;
    return SS_OK;
}

/* Processes sharing the directions (every 3rd from 0, 1, 2) add their
 * sums through the reduce hook: whole-grid and banded shares must give the
 * product of all directions. */
static void shares(void)
{
    ss_grid g = test_grid(41, 29, 15, 15);
    test_fill(&g, TERRAIN_SMOOTH, 9, 400);
    test_holes(&g, 2, 3, 4);
    size_t n = (size_t)g.width * g.height;
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 11;
    opt.offset_deg = 3;
    for (int term = SS_SKY_SVF_GEOMETRIC; term <= SS_SKY_OPENNESS_NEGATIVE; term += 2) {
        float *all = malloc(sizeof(float) * n), *shared = malloc(sizeof(float) * n);
        float *kept = malloc(sizeof(float) * n);
        int writes[29] = {0};
        ss_ctx *ctx = ss_ctx_new();
        ss_ctx_use_device(ctx, "reference");
        int ok = (term < 3 ? ss_svf(ctx, &g, &opt, (ss_svf_definition)term, all)
                           : ss_openness(ctx, &g, &opt, term == 4, 0, all)) == SS_OK;
        double worst[2] = {0, 0};
        for (int banded_run = 0; banded_run < 2; ++banded_run) {
            band_io_state s = {&g, shared, writes, -1};
            ss_source src = test_source(&g, read_rows, &s, banded_run ? 4 : 0, NULL);
            for (int first = 0; ok && first < 3; ++first) {
                serial_reduce r = {kept, 0, first, 3};
                ss_share share = {first, 3, reduce_in_turn, &r};
                ok &= ss_sky_rows(ctx, &src, &opt, (ss_sky_term)term, 0.0, &share, write_rows,
                                  &s) == SS_OK;
            }
            for (size_t c = 0; ok && c < n; ++c)
                if (all[c] != SS_NODATA)
                    worst[banded_run] = fmax(worst[banded_run], fabs(shared[c] - all[c]));
        }
        double tol = term < 3 ? 2e-6 : 2e-4;
        tap_ok(ok && worst[0] <= tol && worst[1] <= tol,
               "%s from 3 shares of 11 directions: whole-grid worst %.2g, in bands of 4 rows "
               "worst %.2g",
               kind_name[term], worst[0], worst[1]);
        band_io_state none = {&g, shared, writes, -1};
        ss_source src = test_source(&g, read_rows, &none, 0, NULL);
        ss_share bad = {3, 3, NULL, NULL};
        ss_status st = ss_sky_rows(ctx, &src, &opt, (ss_sky_term)term, 0.0, &bad, write_rows,
                                   &none);
        tap_ok(st == SS_ERR_ARGUMENT, "a share with first >= stride is refused: %s",
               ss_ctx_message(ctx));
        ss_ctx_free(ctx);
        free(all);
        free(shared);
        free(kept);
    }
    ss_grid_free(&g);
}

int main(void)
{
    random_terrain();
    shares();
    handoffs_and_failures();
    return tap_done();
}
