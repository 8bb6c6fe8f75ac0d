/* Horizons in bands (ss_horizon_rows, src/core/engine.c) against the
 * whole-grid horizon: the same angles, distances and casting heights,
 * direction by direction, on random terrain with nodata holes crossing band
 * edges, for bands from 1 row to more than the grid, bands that do not
 * divide the grid, directions on the axes and diagonals and between them
 * in all four quadrants, both line models, curvature on and off, on the C
 * twin. Each direction's rows must arrive exactly once. The shadows' form
 * (the horizontal where nothing lies ahead) is checked through the shadow
 * product in bands against ss_cast_shadow, and a failing reader or writer
 * stops the run. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "tap.h"
#include "testlib.h"

enum { ANGLE, DIST, CAST, N_OUT };

/* Every direction's grids, as the whole-grid sink or the banded writer
 * fill them. */
typedef struct {
    const ss_grid *g;
    int n_dirs;
    float *out[N_OUT]; /* n_dirs grids each */
    int *writes;       /* per direction and row */
    int fail_read_at, fail_write_at;
} horizon_state;

static size_t cells(const ss_grid *g)
{
    return (size_t)g->width * (size_t)g->height;
}

static int state_init(horizon_state *s, const ss_grid *g, int n_dirs)
{
    memset(s, 0, sizeof *s);
    s->g = g;
    s->n_dirs = n_dirs;
    s->fail_read_at = s->fail_write_at = -1;
    int ok = 1;
    for (int k = 0; k < N_OUT; ++k) {
        s->out[k] = malloc(sizeof(float) * cells(g) * (size_t)n_dirs);
        ok &= s->out[k] != NULL;
        for (size_t c = 0; ok && c < cells(g) * (size_t)n_dirs; ++c)
            s->out[k][c] = -12345.0f; /* a value nothing writes */
    }
    s->writes = calloc((size_t)n_dirs * (size_t)g->height, sizeof(int));
    return ok && s->writes;
}

static void state_free(horizon_state *s)
{
    for (int k = 0; k < N_OUT; ++k)
        free(s->out[k]);
    free(s->writes);
}

static int whole_sink(int index, double azimuth_deg, const float *angle_deg, const float *dist_m,
                      const float *cast_height_m, void *user)
{
    (void)azimuth_deg;
    horizon_state *s = user;
    const float *in[N_OUT] = {angle_deg, dist_m, cast_height_m};
    for (int k = 0; k < N_OUT; ++k)
        if (in[k])
            memcpy(s->out[k] + (size_t)index * cells(s->g), in[k], sizeof(float) * cells(s->g));
    return 1;
}

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    horizon_state *s = user;
    if (s->fail_read_at >= row0 && s->fail_read_at < row0 + n_rows)
        return SS_ERR_INPUT;
    memcpy(z, s->g->z + (size_t)row0 * s->g->width, sizeof(float) * (size_t)n_rows * s->g->width);
    return SS_OK;
}

/* Rows of one output (SS_OUT_HORIZON_*, the same order as ANGLE, DIST,
 * CAST) of one direction; the angles' rows are counted. */
static ss_status write_rows(void *user, int output, int direction, int row0, int n_rows,
                            const float *values)
{
    horizon_state *s = user;
    if (direction < 0 || direction >= s->n_dirs || row0 < 0 || row0 + n_rows > s->g->height ||
        output < 0 || output >= N_OUT)
        return SS_ERR_INTERNAL;
    if (s->fail_write_at >= row0 && s->fail_write_at < row0 + n_rows)
        return SS_ERR_OUTPUT;
    size_t at = (size_t)direction * cells(s->g) + (size_t)row0 * s->g->width;
    memcpy(s->out[output] + at, values, sizeof(float) * (size_t)n_rows * s->g->width);
    for (int r = row0; output == ANGLE && r < row0 + n_rows; ++r)
        s->writes[(size_t)direction * s->g->height + r]++;
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

static ss_status banded(const ss_grid *g, const ss_sweep_options *opt, int want, int band_rows,
                        horizon_state *s, ss_band_stats *stats, char *why, size_t why_size)
{
    ss_source src = test_source(g, read_rows, s, band_rows, stats);
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    ss_status st = ss_horizon_rows(ctx, &src, opt, want, write_rows, s);
    snprintf(why, why_size, "%s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st;
}

/* Worst differences between two runs' grids; mismatched nodata counts. */
typedef struct {
    double angle, dist_rel, cast;
    size_t nodata_mismatch, unwritten;
} difference;

static void differ(const horizon_state *a, const horizon_state *b, int want, difference *d)
{
    size_t n = cells(a->g) * (size_t)a->n_dirs;
    for (size_t c = 0; c < n; ++c) {
        for (int k = 0; k < N_OUT; ++k) {
            if ((k == DIST && !(want & SS_HORIZON_DISTANCE)) ||
                (k == CAST && !(want & SS_HORIZON_CAST_HEIGHT)))
                continue;
            float x = a->out[k][c], y = b->out[k][c];
            if (y == -12345.0f) {
                d->unwritten++;
                continue;
            }
            if ((x == SS_NODATA) != (y == SS_NODATA)) {
                d->nodata_mismatch++;
                continue;
            }
            double e = fabs((double)x - y);
            if (!isfinite(e))
                e = INFINITY;
            if (k == ANGLE)
                d->angle = fmax(d->angle, e);
            else if (k == DIST)
                d->dist_rel = fmax(d->dist_rel, e / fmax(1.0, fabs(x)));
            else
                d->cast = fmax(d->cast, e);
        }
    }
}

static void compare(const ss_grid *g, const char *terrain, const sweep_case *k, int want,
                    const int *band_rows, int n_band_rows)
{
    ss_sweep_options opt;
    options_for(k, &opt);
    horizon_state ref, out;
    int ok = state_init(&ref, g, k->directions) && state_init(&out, g, k->directions);
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    if (ok && ss_horizon(ctx, g, &opt, want, whole_sink, &ref) != SS_OK) {
        tap_diag("whole-grid run failed: %s", ss_ctx_message(ctx));
        ok = 0;
    }
    ss_ctx_free(ctx);
    difference d = {0, 0, 0, 0, 0};
    int rows_ok = 1, worst_rows = 0;
    char why[300] = "";
    for (int b = 0; ok && b < n_band_rows; ++b) {
        memset(out.writes, 0, sizeof(int) * (size_t)k->directions * g->height);
        ok = banded(g, &opt, want, band_rows[b], &out, NULL, why, sizeof why) == SS_OK;
        for (int r = 0; ok && r < k->directions * g->height; ++r)
            rows_ok &= out.writes[r] == 1;
        double before = d.angle;
        differ(&ref, &out, want, &d);
        if (d.angle > before)
            worst_rows = band_rows[b];
    }
    /* Float sums of at most two samples, and hulls handed on as whole
     * points: 1e-4 degrees is 1.7e-6 rad, inside the 1e-5 rad promised. */
    tap_ok(ok && rows_ok && !d.nodata_mismatch && !d.unwritten && d.angle <= 1e-4 &&
               d.dist_rel <= 1e-5 && d.cast <= 1e-3,
           "%s, %d dirs from %.1f deg, %s lines, curvature %s%s%s: banded horizon == whole "
           "grid for %d band heights (worst %.2g deg at %d rows, distance %.2g relative, "
           "casting height %.2g m; each direction's rows written once: %s)%s%s",
           terrain, k->directions, k->offset,
           k->model == SS_LINES_DIGITAL ? "digital" : "interpolated", k->curved ? "on" : "off",
           want & SS_HORIZON_DISTANCE ? ", distances" : "",
           want & SS_HORIZON_CAST_HEIGHT ? ", casting heights" : "", n_band_rows, d.angle,
           worst_rows, d.dist_rel, d.cast, rows_ok ? "yes" : "no", why[0] ? ": " : "", why);
    if (d.nodata_mismatch || d.unwritten)
        tap_diag("%zu nodata mismatches, %zu cells never written", d.nodata_mismatch, d.unwritten);
    state_free(&ref);
    state_free(&out);
}

static void random_terrain(void)
{
    static const int band_rows[] = {1, 2, 3, 5, 7, 16, 40, 200};
    static const sweep_case cases[] = {
        {8, 0.0, SS_LINES_INTERPOLATED, 0},  /* axes and diagonals */
        {13, 7.3, SS_LINES_INTERPOLATED, 0}, /* between them, all quadrants */
        {13, 7.3, SS_LINES_INTERPOLATED, 1}, {8, 0.0, SS_LINES_DIGITAL, 0},
        {13, 7.3, SS_LINES_DIGITAL, 1},
    };
    const int all = SS_HORIZON_DISTANCE | SS_HORIZON_CAST_HEIGHT;
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
        g.z_origin_m = 1000.0; /* casting heights are on the DEM's datum */
        for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k)
            /* Every case on the first terrain; the others with all outputs. */
            if (t == 0 || k == t)
                compare(&g, terrains[t].name, &cases[k], k == 1 && t == 0 ? 0 : all, band_rows,
                        (int)(sizeof band_rows / sizeof *band_rows));
        ss_grid_free(&g);
    }
}

/* One sun for every cell, given in the options' frame. */
typedef struct {
    double azimuth_deg, grid_north_deg, elevation_deg;
} fixed_sun;

static ss_status sun_of(ss_ctx *ctx, int index, int row0, int n_rows, ss_sun_step *step,
                        void *user)
{
    (void)ctx, (void)index, (void)row0, (void)n_rows;
    const fixed_sun *f = user;
    memset(step, 0, sizeof *step);
    step->azimuth_deg = f->azimuth_deg;
    step->grid_azimuth_deg = f->azimuth_deg - f->grid_north_deg;
    step->elevation_deg = step->apparent_elevation_deg = f->elevation_deg;
    return SS_OK;
}

static ss_status sunlit_rows(void *user, int output, int index, int row0, int n_rows,
                             const float *values)
{
    (void)index;
    horizon_state *s = user;
    if (output == SS_OUT_SUNLIT)
        memcpy(s->out[ANGLE] + (size_t)row0 * s->g->width, values,
               sizeof(float) * (size_t)n_rows * s->g->width);
    return SS_OK;
}

/* The shadows' form (a sweep along the sun, the horizontal where nothing
 * lies ahead): ss_shadow_rows in bands gives ss_cast_shadow's sunlit cells. */
static void sun_azimuths(void)
{
    ss_grid g = test_grid(45, 38, 25, 25);
    test_fill(&g, TERRAIN_SMOOTH, 21, 600);
    test_holes(&g, 4, 4, 5);
    const double az[] = {0.0, 90.0, 135.0, 181.7, 233.3, 301.9, 359.99};
    const int n_az = (int)(sizeof az / sizeof *az);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.earth_radius_m = 5e4;
    opt.refraction_k = 0;
    opt.grid_north_deg = 1.5; /* azimuths are in the options' frame, as the shadow's */
    horizon_state out;
    int ok = state_init(&out, &g, 1);
    float *sunlit = malloc(sizeof(float) * cells(&g));
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    size_t differ = 0, shaded = 0;
    for (int i = 0; ok && i < n_az; ++i) {
        fixed_sun sun = {az[i], opt.grid_north_deg, 10.0};
        ss_source src = test_source(&g, read_rows, &out, 6, NULL);
        ok = ss_cast_shadow(ctx, &g, &opt, az[i], 10.0, NULL, sunlit, NULL) == SS_OK &&
             ss_shadow_rows(ctx, &src, &opt, sun_of, &sun, sunlit_rows, &out) == SS_OK;
        for (size_t c = 0; ok && c < cells(&g); ++c) {
            differ += sunlit[c] != out.out[ANGLE][c];
            shaded += sunlit[c] == 0.0f;
        }
    }
    tap_ok(ok && !differ && shaded > 0,
           "7 sun azimuths with grid north 1.5 deg off, curvature on, bands of 6 rows: the "
           "banded shadow product == ss_cast_shadow's (%zu cells differ; %zu in shadow)",
           differ, shaded);
    free(sunlit);
    ss_ctx_free(ctx);
    state_free(&out);
    ss_grid_free(&g);
}

/* Hulls are handed on (counted); a reader or writer that fails stops the
 * run with its status; bad arguments are refused. */
static void handoffs_and_failures(void)
{
    ss_grid g = test_grid(30, 60, 10, 10);
    test_fill(&g, TERRAIN_SMOOTH, 3, 200);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 8;
    horizon_state s;
    int ok = state_init(&s, &g, opt.directions);
    ss_band_stats stats = {0};
    char why[300];
    ss_status st = ok ? banded(&g, &opt, 0, 7, &s, &stats, why, sizeof why) : SS_ERR_MEMORY;
    tap_ok(st == SS_OK && stats.handoffs > 0 && stats.max_hull_points > 0 &&
               stats.hull_points_handed_on >= stats.handoffs,
           "60 rows in bands of 7: %zu hulls handed on, %.1f points on average, largest %zu",
           stats.handoffs,
           stats.handoffs ? (double)stats.hull_points_handed_on / stats.handoffs : 0,
           stats.max_hull_points);
    s.fail_read_at = 33;
    st = banded(&g, &opt, 0, 7, &s, NULL, why, sizeof why);
    tap_ok(st == SS_ERR_INPUT && why[0],
           "a reader failing at row 33 stops the run: status %d, "
           "'%s'",
           (int)st, why);
    s.fail_read_at = -1;
    s.fail_write_at = 41;
    st = banded(&g, &opt, SS_HORIZON_DISTANCE, 7, &s, NULL, why, sizeof why);
    tap_ok(st == SS_ERR_OUTPUT, "a writer failing at row 41 stops the run: status %d", (int)st);
    s.fail_write_at = -1;
    st = banded(&g, &opt, 0, -1, &s, NULL, why, sizeof why);
    tap_ok(st == SS_ERR_ARGUMENT, "-1 rows per band is refused: %s", why);
    fixed_sun nan_sun = {NAN, 0.0, 10.0};
    ss_source src = test_source(&g, read_rows, &s, 7, NULL);
    ss_ctx *ctx = ss_ctx_new();
    st = ss_shadow_rows(ctx, &src, &opt, sun_of, &nan_sun, sunlit_rows, &s);
    tap_ok(st == SS_ERR_ARGUMENT, "a NaN sun azimuth is refused: %s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    state_free(&s);
    ss_grid_free(&g);
}

int main(void)
{
    random_terrain();
    sun_azimuths();
    handoffs_and_failures();
    return tap_done();
}
