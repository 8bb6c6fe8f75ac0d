/* Hillshade against gdaldem itself (GDALDEMProcessing, in the same
 * process) on the bundled sample DEM: every cell gdaldem computes agrees to
 * +-1 grey level, for Horn and Zevenbergen-Thorne, the multidirectional
 * light, and another light and z factor. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gdal.h>
#include <gdal_utils.h>

#include "dem_io.h"
#include "tap.h"

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
    size_t compared = 0;
    for (size_t c = 0; ok && c < n; ++c) {
        if (theirs[c] == 0)
            continue; /* gdaldem's nodata: edges, next to holes */
        int mine = (int)fmin(255, fmax(1, nearbyint(ours[c])));
        worst = abs(mine - theirs[c]) > worst ? abs(mine - theirs[c]) : worst;
        compared++;
    }
    tap_ok(ok && worst <= 1 && compared > n / 2,
           "hillshade %s == gdaldem on %zu cells to +-1 grey level (worst %d) %s", label, compared,
           worst, st == SS_OK ? "" : ss_ctx_message(ctx));
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
    GDALClose(src);
    ss_dem_free(&dem);
    ss_ctx_free(ctx);
    return tap_done();
}
