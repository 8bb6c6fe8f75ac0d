#include "config.h"

#include "tree_scenes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lines.h"
#include "tap.h"
#include "testlib.h"

double tree_trunk_at(const ss_canopy *cn, size_t i)
{
    return cn->trunk_m ? cn->trunk_m[i] : cn->trunk_ratio * cn->height_m[i];
}

void tree_plant(const ss_grid *g, float *height, unsigned seed, int n_trees)
{
    memset(height, 0, sizeof(float) * (size_t)g->width * g->height);
    srand(seed);
    for (int k = 0; k < n_trees; ++k) {
        int cr = rand() % g->height, cc = rand() % g->width;
        double R = 2 + rand() % 5, H = 4 + rand() % 17;
        for (int r = (int)(cr - R); r <= cr + R; ++r)
            for (int c = (int)(cc - R); c <= cc + R; ++c)
                if (r >= 0 && c >= 0 && r < g->height && c < g->width && hypot(r - cr, c - cc) <= R)
                    height[(size_t)r * g->width + c] = (float)H;
    }
}

int tree_gothenburg(ss_dem *dsm, float **height)
{
    const char *dsm_path = test_shared_data("goteborg_kronenhuset_dsm_1m.tif");
    const char *cdsm_found = test_shared_data("goteborg_kronenhuset_cdsm_1m.tif");
    if (!dsm_path || !cdsm_found)
        return 0;
    char cdsm_path[1024]; /* test_shared_data's buffer is reused */
    snprintf(cdsm_path, sizeof cdsm_path, "%s", cdsm_found);
    ss_ctx *ctx = ss_ctx_new();
    ss_dem cdsm;
    const char *p1[] = {dsm_path}, *p2[] = {cdsm_path};
    if (ss_dem_read(ctx, p1, 1, NULL, dsm) != SS_OK) {
        tap_ok(0, "cannot read the Gothenburg DSM: %s", ss_ctx_message(ctx));
        ss_ctx_free(ctx);
        return -1;
    }
    if (ss_dem_read(ctx, p2, 1, NULL, &cdsm) != SS_OK) {
        tap_ok(0, "cannot read the Gothenburg CDSM: %s", ss_ctx_message(ctx));
        ss_dem_free(dsm);
        ss_ctx_free(ctx);
        return -1;
    }
    size_t cells = (size_t)dsm->grid.width * dsm->grid.height;
    *height = malloc(cells * sizeof(float));
    for (size_t i = 0; *height && i < cells; ++i) {
        double h = cdsm.grid.z[i] + cdsm.grid.z_origin_m;
        (*height)[i] = isfinite(h) && h > 0 ? (float)h : 0.0f;
    }
    ss_dem_free(&cdsm);
    ss_ctx_free(ctx);
    if (!*height) {
        tap_ok(0, "out of memory for the Gothenburg canopy");
        ss_dem_free(dsm);
        return -1;
    }
    return 1;
}

void tree_cylinder(ss_grid *g, float *height, double cx, double cy, double R, double top)
{
    test_plane(g, 0.0, 0.0);
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c)
            height[(size_t)r * g->width + c] =
                hypot(c + 0.5 - cx, r + 0.5 - cy) <= R ? (float)top : 0.0f;
}

void tree_hedge(ss_grid *g, float *height, int col, double top)
{
    test_plane(g, 0.0, 0.0);
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c)
            height[(size_t)r * g->width + c] = c == col ? (float)top : 0.0f;
}

void tree_brute_paths(const ss_grid *g, const ss_canopy *cn, double az, double el, double *path)
{
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, g->width, g->height, g->cell_x_m, g->cell_y_m, az,
                            SS_LINE_MODEL_DIGITAL);
    double a = az * M_PI / 180.0, e = el * M_PI / 180.0;
    double t = tan(e), away_major = (double)ls.along_per_step_m * ls.step;
    double run_m =
        ls.major_is_row ? g->cell_y_m / fabs(cos(a)) : g->cell_x_m / fabs(sin(a));
    double slant_m = run_m / cos(e);
    size_t *cell = malloc(sizeof(size_t) * ls.major_len);
    double *level = malloc(sizeof(double) * ls.major_len);
    for (size_t i = 0; i < (size_t)g->width * g->height; ++i)
        path[i] = 0.0;
    for (int line = 0; line < ls.n_lines; ++line) {
        ss_i64 b16 = ss_line_intercept16(&ls, line);
        int m = 0;
        for (int k = 0; k < ls.major_len; ++k) { /* the sunny end first */
            int major = ls.step > 0 ? k : ls.major_len - 1 - k;
            int minor = ss_line_minor(&ls, b16, major);
            if (minor < 0 || minor >= ls.minor_len)
                continue;
            size_t i = (size_t)major * ls.stride_major + (size_t)minor * ls.stride_minor;
            if (!isfinite(g->z[i]))
                continue;
            cell[m] = i;
            /* Heights relative to the ray: + distance walked x tan e. */
            level[m++] = (major * away_major + minor * (double)ls.along_per_minor_m) * t;
        }
        for (int p = 0; p < m; ++p) {
            int hits = 0;
            double ray = g->z[cell[p]] + level[p];
            for (int q = 0; q < p; ++q) {
                size_t j = cell[q];
                double bottom = tree_trunk_at(cn, j);
                hits += cn->height_m[j] > bottom && ray > g->z[j] + bottom + level[q] &&
                        ray < g->z[j] + cn->height_m[j] + level[q];
            }
            path[cell[p]] = hits * slant_m;
        }
    }
    free(cell), free(level);
}
