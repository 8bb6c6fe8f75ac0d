#include "config.h"

#include "tree_scenes.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
