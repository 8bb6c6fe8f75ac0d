/* The digital lines of every direction cover the grid with every cell
 * exactly once, walk monotonically away from the azimuth, and are
 * 8-connected; the host's cursor over a digital line visits the same
 * cells, each once, at distances that rise as it walks away from the
 * azimuth; and both backends visit each cell exactly once. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "lines.h"
#include "tap.h"
#include "testlib.h"

/* Checks the line set of one azimuth cell by cell; returns a description of
 * the first violation, or NULL. Digital lines must visit every cell once;
 * interpolated lines must give every cell weights summing to exactly 1. */
static const char *check_geometry(int w, int h, double cx, double cy, double az_deg, int model)
{
    static char why[200];
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, w, h, cx, cy, az_deg, model);
    float *visits = calloc((size_t)w * h, sizeof *visits);
    double a = az_deg * M_PI / 180.0;
    why[0] = '\0';
    for (int line = 0; line < ls.n_lines && !why[0]; ++line) {
        int first, n = ss_line_extent(&ls, line, &first);
        /* Interpolated sets keep a spare line at each end; digital ones none. */
        if (n == 0 && model == SS_LINE_MODEL_DIGITAL)
            snprintf(why, sizeof why, "line %d is empty", line);
        double prev_ahead = INFINITY;
        int prev_minor = 0;
        for (int s = 0; s < n && !why[0]; ++s) {
            ss_line_sample p =
                ss_line_sample_at(&ls, ss_line_intercept16(&ls, line),
                                  ss_line_major_at(&ls, first, n, s));
            int major = p.major, minor = p.minor0;
            float wt[2] = {1.0f - p.w1, p.w1};
            for (int k = 0; k < 2; ++k) {
                int m = minor + k;
                if (wt[k] == 0.0f)
                    continue;
                int col = ls.major_is_row ? m : major, row = ls.major_is_row ? major : m;
                if (col < 0 || row < 0 || col >= w || row >= h) {
                    if (model == SS_LINE_MODEL_DIGITAL)
                        snprintf(why, sizeof why, "line %d leaves the grid at (%d,%d)", line,
                                 col, row);
                    continue;
                }
                visits[(size_t)row * w + col] += wt[k];
            }
            double exact_minor = minor + (double)p.w1;
            int col = ls.major_is_row ? (int)0 : major, row = ls.major_is_row ? major : 0;
            double fcol = ls.major_is_row ? exact_minor : col;
            double frow = ls.major_is_row ? row : exact_minor;
            /* Position toward the azimuth must fall strictly as we walk. */
            double ahead = fcol * cx * sin(a) - frow * cy * cos(a);
            if (!(ahead < prev_ahead))
                snprintf(why, sizeof why, "line %d does not walk away from the azimuth at step %d",
                         line, s);
            if (s > 0 && abs(minor - prev_minor) > 1)
                snprintf(why, sizeof why, "line %d jumps %d cells at step %d", line,
                         minor - prev_minor, s);
            prev_ahead = ahead;
            prev_minor = minor;
        }
    }
    for (size_t i = 0; i < (size_t)w * h && !why[0]; ++i)
        if (visits[i] != 1.0f)
            snprintf(why, sizeof why, "cell (%zu,%zu) gets weight %.9g", i % (size_t)w,
                     i / (size_t)w, visits[i]);
    free(visits);
    return why[0] ? why : NULL;
}

/* The cursor (lines.h) over every digital line: each cell once, and the
 * distance walked rising by the cell's projection on the walk direction
 * (the distance from the line's first cell, as digital lines measure it,
 * within float rounding of the per-step distances). */
static const char *check_cursor(int w, int h, double cx, double cy, double az_deg)
{
    static char why[200];
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, w, h, cx, cy, az_deg, SS_LINE_MODEL_DIGITAL);
    int *visits = calloc((size_t)w * h, sizeof *visits);
    double a = az_deg * M_PI / 180.0, walk_east = -sin(a), walk_south = cos(a);
    why[0] = '\0';
    for (int line = 0; line < ss_line_count(&ls) && !why[0]; ++line) {
        ss_line_cursor c = ss_line_cursor_start(&ls, line);
        double first = 0.0, first_w = 0.0, prev_w = -INFINITY;
        for (int k = 0; ss_line_cursor_next(&c) && !why[0]; ++k) {
            ++visits[c.cell];
            double col = (double)(c.cell % (size_t)w), row = (double)(c.cell / (size_t)w);
            double along = col * cx * walk_east + row * cy * walk_south;
            if (k == 0)
                first = along, first_w = c.walked_m;
            if (!(c.walked_m > prev_w))
                snprintf(why, sizeof why, "line %d: the distance does not rise at its cell %d",
                         line, k);
            double want = along - first, got = c.walked_m - first_w;
            if (fabs(got - want) > 1e-5 * (w + h) * (cx + cy))
                snprintf(why, sizeof why, "line %d: cell %d walked %.9g m, %.9g m by projection",
                         line, k, got, want);
            prev_w = c.walked_m;
        }
    }
    for (size_t i = 0; i < (size_t)w * h && !why[0]; ++i)
        if (visits[i] != 1)
            snprintf(why, sizeof why, "cell (%zu,%zu) visited %d times", i % (size_t)w,
                     i / (size_t)w, visits[i]);
    free(visits);
    return why[0] ? why : NULL;
}

/* Both backends' bare pass over z = 1 must leave exactly 1 in every cell. */
/* One context per device for all checks: opening a device (a GPU's context
 * and kernel build) costs far more than a pass over these small grids. */
static const char *check_visits(ss_ctx *ctx, int w, int h, double cx, double cy, double az_deg,
                                int model)
{
    static char why[600];
    ss_grid g = test_grid(w, h, cx, cy);
    for (size_t i = 0; i < (size_t)w * h; ++i)
        g.z[i] = 1.0f;
    float *out = calloc((size_t)w * h, sizeof *out);
    why[0] = '\0';
    if (ss_bare_pass(ctx, &g, az_deg, (ss_line_model)model, out) != SS_OK)
        snprintf(why, sizeof why, "%s", ss_ctx_message(ctx));
    for (size_t i = 0; i < (size_t)w * h && !why[0]; ++i)
        if (out[i] != 1.0f)
            snprintf(why, sizeof why, "cell (%zu,%zu) visited %g times", i % (size_t)w,
                     i / (size_t)w, out[i]);
    free(out);
    ss_grid_free(&g);
    return why[0] ? why : NULL;
}

int main(void)
{
    const struct {
        int w, h;
        double cx, cy;
    } grids[] = {{37, 37, 1, 1},  {53, 17, 1, 1}, {17, 53, 1, 1}, {1, 40, 1, 1},
                 {40, 1, 1, 1},   {2, 2, 1, 1},   {31, 23, 30, 10}, {4099, 3, 1, 1}};
    double angles[12 * 3 + 50];
    int n_angles = 0;
    const double axes[] = {0, 45, 90, 135, 180, 225, 270, 315, 360, -45, 30, 60};
    for (int i = 0; i < 12; ++i) {
        angles[n_angles++] = axes[i];
        angles[n_angles++] = axes[i] + 1e-9;
        angles[n_angles++] = axes[i] - 1e-9;
    }
    unsigned s = 12345;
    for (int i = 0; i < 50; ++i) {
        s = s * 1103515245u + 12345u;
        angles[n_angles++] = (s >> 8) % 3600000 / 10000.0;
    }
    const char *models[] = {"interpolated lines", "digital lines"};
    for (int model = 0; model < 2; ++model)
        for (size_t gi = 0; gi < sizeof grids / sizeof grids[0]; ++gi) {
            const char *bad = NULL;
            double bad_az = 0;
            for (int ai = 0; ai < n_angles && !bad; ++ai)
                if ((bad = check_geometry(grids[gi].w, grids[gi].h, grids[gi].cx, grids[gi].cy,
                                          angles[ai], model)))
                    bad_az = angles[ai];
            tap_ok(!bad,
                   "%s on %dx%d (cells %gx%g m), %d azimuths: each cell weight 1, monotone, "
                   "8-connected%s%s",
                   models[model], grids[gi].w, grids[gi].h, grids[gi].cx, grids[gi].cy,
                   n_angles, bad ? ": " : "", bad ? bad : "");
            if (bad)
                tap_diag("first failure at azimuth %.12g", bad_az);
        }
    for (size_t gi = 0; gi < sizeof grids / sizeof grids[0]; ++gi) {
        const char *bad = NULL;
        double bad_az = 0;
        for (int ai = 0; ai < n_angles && !bad; ++ai)
            if ((bad = check_cursor(grids[gi].w, grids[gi].h, grids[gi].cx, grids[gi].cy,
                                    angles[ai])))
                bad_az = angles[ai];
        tap_ok(!bad, "the cursor over digital lines on %dx%d (cells %gx%g m), %d azimuths: each "
               "cell once, distances walked rising by projection%s%s",
               grids[gi].w, grids[gi].h, grids[gi].cx, grids[gi].cy, n_angles, bad ? ": " : "",
               bad ? bad : "");
        if (bad)
            tap_diag("first failure at azimuth %.12g", bad_az);
    }
    const char *devices[] = {NULL, "reference"};
    for (int model = 0; model < 2; ++model)
        for (int d = 0; d < 2; ++d) {
            ss_ctx *ctx = ss_ctx_new();
            ss_ctx_use_device(ctx, devices[d]);
            for (size_t gi = 0; gi < sizeof grids / sizeof grids[0]; ++gi) {
                const char *bad = NULL;
                double bad_az = 0;
                for (int ai = 0; ai < n_angles && !bad; ai += (gi == 7 ? 7 : 1))
                    if ((bad = check_visits(ctx, grids[gi].w, grids[gi].h, grids[gi].cx,
                                            grids[gi].cy, angles[ai], model)))
                        bad_az = angles[ai];
                tap_ok(!bad, "%s, %s bare pass on %dx%d: every cell receives weight 1%s%s",
                       models[model], devices[d] ? devices[d] : "OpenCL", grids[gi].w,
                       grids[gi].h, bad ? ": " : "", bad ? bad : "");
                if (bad)
                    tap_diag("first failure at azimuth %.12g", bad_az);
            }
            ss_ctx_free(ctx);
        }
    return tap_done();
}
