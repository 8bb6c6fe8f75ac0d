/* Hillshade against gdaldem itself (GDALDEMProcessing, in the same
 * process) on the bundled sample DEM: every cell gdaldem computes agrees to
 * +-1 grey level, for Horn and Zevenbergen-Thorne, the multidirectional
 * light, and another light and z factor. And on small random grids with
 * holes, which gdaldem leaves out: every cell equals, bit for bit, the
 * kernels' cell-by-cell gradient and incidence (the library takes cells
 * off the grid's edge in a vectorised loop of its own). */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gdal.h>
#include <gdal_utils.h>

#include "dem_io.h"
#include "ss_sun.h"
#include "ss_terms.h"
#include "tap.h"

/* Cells of a w x h grid of random heights, a fifth of them holes, shaded by
 * the library and cell by cell; returns the cells that differ. */
static size_t edges_and_holes(int w, int h, int zt, unsigned *seed)
{
    ss_grid g = {.width = w, .height = h, .cell_x_m = 10.0, .cell_y_m = 12.5};
    size_t n = (size_t)w * h, differ = 0;
    float *z = malloc(n * sizeof(float)), *ours = malloc(n * sizeof(float));
    for (size_t i = 0; i < n; ++i)
        z[i] = rand_r(seed) % 5 == 0 ? NAN : (float)(rand_r(seed) % 20000) * 0.05f;
    g.z = z;
    ss_ctx *ctx = ss_ctx_new();
    double az = 315.0 * M_PI / 180.0, alt = 45.0 * M_PI / 180.0, zf = 1.5;
    float sun_e = (float)(cos(alt) * sin(az)), sun_n = (float)(cos(alt) * cos(az)),
          sun_u = (float)sin(alt);
    if (ss_hillshade(ctx, &g, 315.0, 45.0, zf, zt, 0, ours) != SS_OK)
        differ = n;
    for (int r = 0; r < h && !differ; ++r)
        for (int c = 0; c < w; ++c) {
            float de, dn, want = SS_NODATA;
            if (isfinite(z[(size_t)r * w + c])) {
                if (zt)
                    ss_gradient_zt(z, w, h, c, r, 10.0f, 12.5f, &de, &dn);
                else
                    ss_gradient_horn(z, w, h, c, r, 10.0f, 12.5f, &de, &dn);
                float cang = ss_cos_incidence_gradient(sun_e, sun_n, sun_u, de * (float)zf,
                                                       dn * (float)zf);
                want = cang <= 0.0f ? 1.0f : 1.0f + 254.0f * cang;
            }
            differ += memcmp(&want, &ours[(size_t)r * w + c], sizeof want) != 0;
        }
    ss_ctx_free(ctx);
    free(z);
    free(ours);
    return differ;
}

static void compare(const ss_dem *dem, GDALDatasetH src, char **gdaldem_args, double az,
                    double alt, double z, int zt, int multi, const char *label)
{
    ss_ctx *ctx = ss_ctx_new();
    size_t n = (size_t)dem->grid.width * dem->grid.height;
    float *ours = malloc(n * sizeof(float));
    unsigned char *theirs = malloc(n);
    ss_status st = ss_hillshade(ctx, &dem->grid, az, alt, z, zt, multi, ours);
    GDALDEMProcessingOptions *o = GDALDEMProcessingOptionsNew(gdaldem_args, NULL);
    GDALDatasetH out = GDALDEMProcessing("/vsimem/hs.tif", src, "hillshade", NULL, o, NULL);
    GDALDEMProcessingOptionsFree(o);
    int ok = st == SS_OK && out &&
             GDALRasterIO(GDALGetRasterBand(out, 1), GF_Read, 0, 0, dem->grid.width,
                          dem->grid.height, theirs, dem->grid.width, dem->grid.height, GDT_Byte,
                          0, 0) == CE_None;
    int worst = 0;
    size_t compared = 0, valid = 0;
    for (size_t c = 0; ok && c < n; ++c) {
        valid += isfinite(dem->grid.z[c]);
        if (theirs[c] == 0)
            continue; /* gdaldem's nodata: edges (without -compute_edges), next to holes */
        int mine = (int)fmin(255, fmax(1, nearbyint(ours[c])));
        worst = abs(mine - theirs[c]) > worst ? abs(mine - theirs[c]) : worst;
        compared++;
    }
    /* With -compute_edges gdaldem shades every cell with a height. */
    int edges = strstr(label, "edges") != NULL;
    tap_ok(ok && worst <= 1 && compared > n / 2 && (!edges || compared == valid),
           "hillshade %s == gdaldem on %zu of %zu cells with heights to +-1 grey level (worst "
           "%d) %s",
           label, compared, valid, worst, st == SS_OK ? "" : ss_ctx_message(ctx));
    if (out)
        GDALClose(out);
    VSIUnlink("/vsimem/hs.tif");
    free(ours);
    free(theirs);
    ss_ctx_free(ctx);
}

int main(void)
{
    GDALAllRegister();
    const char *path = TOP_SRCDIR "/samples/kilauea_summit_30m.tif";
    ss_ctx *ctx = ss_ctx_new();
    ss_dem dem;
    const char *paths[] = {path};
    /* gdaldem uses the projected cell size (30 m); so does the plain reader. */
    if (!tap_ok(ss_dem_read(ctx, paths, 1, NULL, &dem) == SS_OK, "read %s", path))
        return tap_done();
    GDALDatasetH src = GDALOpen(path, GA_ReadOnly);
    char *horn[] = {"-q", NULL};
    char *zt[] = {"-alg", "ZevenbergenThorne", NULL};
    char *multi[] = {"-multidirectional", NULL};
    char *other[] = {"-az", "90", "-alt", "20", "-z", "3", NULL};
    compare(&dem, src, horn, 315, 45, 1, 0, 0, "Horn, 315/45");
    compare(&dem, src, zt, 315, 45, 1, 1, 0, "Zevenbergen-Thorne");
    compare(&dem, src, multi, 315, 45, 1, 0, 1, "multidirectional");
    compare(&dem, src, other, 90, 20, 3, 0, 0, "az 90 alt 20 z 3");
    /* The grid's edge as gdaldem -compute_edges takes it (kernels/ss_terms.h,
     * ss_z_or): every cell, edges and corners included. */
    char *horn_edges[] = {"-compute_edges", NULL};
    char *zt_edges[] = {"-alg", "ZevenbergenThorne", "-compute_edges", NULL};
    compare(&dem, src, horn_edges, 315, 45, 1, 0, 0, "Horn, -compute_edges");
    compare(&dem, src, zt_edges, 315, 45, 1, 1, 0, "Zevenbergen-Thorne, -compute_edges");
    GDALClose(src);
    static const int sizes[][2] = {{1, 5}, {5, 1}, {2, 2}, {3, 3}, {4, 7}, {37, 23}, {130, 9}};
    unsigned seed = 7;
    for (int zt_alg = 0; zt_alg < 2; ++zt_alg) {
        size_t differ = 0, cells = 0;
        for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; ++k) {
            differ += edges_and_holes(sizes[k][0], sizes[k][1], zt_alg, &seed);
            cells += (size_t)sizes[k][0] * sizes[k][1];
        }
        tap_ok(differ == 0,
               "%s on 7 random grids of 1 x 5 to 130 x 9 cells with holes == the kernels' cell "
               "by cell, bit for bit (%zu of %zu cells differ)",
               zt_alg ? "Zevenbergen-Thorne" : "Horn", differ, cells);
    }
    ss_dem_free(&dem);
    ss_ctx_free(ctx);
    return tap_done();
}
