/* Rasters onto a DEM's grid (see grid_warp.h). */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>
#include <gdal_alg.h>
#include <gdalwarper.h>

#include "band_read.h"
#include "gdal_errors.h"
#include "grid_warp.h"

static int on_dem_grid(const ss_dem *dem, const ss_bands *b)
{
    int same = b->width == dem->grid.width && b->height == dem->grid.height;
    for (int i = 0; i < 6; ++i)
        same = same && fabs(dem->geotransform[i] - b->geotransform[i]) <= 1e-6 * fabs(dem->geotransform[1]);
    return same;
}

/* Whether the DEM's edges (corners and every cell edge along them) map
 * inside the source raster's cells, by the transformer from DEM pixels to
 * source pixels. */
static int covers_dem(void *transform, const ss_dem *dem, int src_w, int src_h)
{
    int w = dem->grid.width, h = dem->grid.height, n = 2 * (w + h) + 4, k = 0;
    double *x = malloc(3 * sizeof(double) * (size_t)n), *y = x + n, *z = y + n;
    int *ok = malloc(sizeof(int) * (size_t)n);
    if (!x || !ok) {
        free(x), free(ok);
        return 0;
    }
    for (int c = 0; c <= w; ++c, k += 2)
        x[k] = x[k + 1] = c, y[k] = 0, y[k + 1] = h;
    for (int r = 0; r <= h; ++r, k += 2)
        y[k] = y[k + 1] = r, x[k] = 0, x[k + 1] = w;
    for (int i = 0; i < k; ++i)
        z[i] = 0.0;
    int covered = GDALGenImgProjTransform(transform, TRUE, k, x, y, z, ok);
    const double slack = 1e-6;
    for (int i = 0; covered && i < k; ++i)
        covered = ok[i] && x[i] >= -slack && x[i] <= src_w + slack && y[i] >= -slack &&
                  y[i] <= src_h + slack;
    free(x), free(ok);
    return covered;
}

static ss_status warp_onto(ss_ctx *ctx, const char *path, const char *what, const ss_dem *dem,
                           float *values)
{
    GDALDatasetH src = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL, NULL);
    if (!src)
        return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot read the %s '%s': %s", what, path,
                            ss_gdal_message());
    double gt[6];
    const char *wkt = GDALGetProjectionRef(src);
    if (!dem->crs_wkt || GDALGetGeoTransform(src, gt) != CE_None || !wkt || !*wkt) {
        GDALClose(src);
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                            "the %s '%s' is not on the DEM's grid, and without a CRS on both it "
                            "cannot be warped onto it",
                            what, path);
    }
    int w = dem->grid.width, h = dem->grid.height;
    GDALDatasetH dst = GDALCreate(GDALGetDriverByName("MEM"), "", w, h, 1, GDT_Float32, NULL);
    ss_status st = SS_OK;
    void *transform = NULL;
    if (!dst) {
        st = ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory warping the %s", what);
    } else {
        GDALSetGeoTransform(dst, (double *)dem->geotransform);
        GDALSetProjection(dst, dem->crs_wkt);
        GDALSetRasterNoDataValue(GDALGetRasterBand(dst, 1), SS_NODATA);
        GDALFillRaster(GDALGetRasterBand(dst, 1), SS_NODATA, 0);
        transform = GDALCreateGenImgProjTransformer(src, NULL, dst, NULL, FALSE, 0.0, 1);
        if (!transform)
            st = ss_ctx_error(ctx, SS_ERR_INPUT, "cannot warp the %s '%s' onto the DEM: %s",
                              what, path, ss_gdal_message());
        else if (!covers_dem(transform, dem, GDALGetRasterXSize(src), GDALGetRasterYSize(src)))
            st = ss_ctx_error(ctx, SS_ERR_INPUT,
                              "the %s '%s' does not cover the DEM; give one over the whole DEM",
                              what, path);
    }
    if (st == SS_OK) {
        GDALWarpOptions *wo = GDALCreateWarpOptions();
        wo->hSrcDS = src;
        wo->hDstDS = dst;
        wo->nBandCount = 1;
        wo->panSrcBands = CPLMalloc(sizeof(int));
        wo->panDstBands = CPLMalloc(sizeof(int));
        wo->panSrcBands[0] = wo->panDstBands[0] = 1;
        wo->eResampleAlg = GRA_Max; /* a crown keeps its top where cells merge */
        wo->pfnTransformer = GDALGenImgProjTransform;
        wo->pTransformerArg = transform;
        int has_nodata = 0;
        double nd = GDALGetRasterNoDataValue(GDALGetRasterBand(src, 1), &has_nodata);
        if (has_nodata) {
            wo->padfSrcNoDataReal = CPLMalloc(sizeof(double));
            wo->padfSrcNoDataReal[0] = nd;
        }
        wo->padfDstNoDataReal = CPLMalloc(sizeof(double));
        wo->padfDstNoDataReal[0] = SS_NODATA;
        GDALWarpOperationH op = GDALCreateWarpOperation(wo);
        CPLErrorReset();
        if (!op || GDALChunkAndWarpImage(op, 0, 0, w, h) != CE_None ||
            GDALRasterIO(GDALGetRasterBand(dst, 1), GF_Read, 0, 0, w, h, values, w, h,
                         GDT_Float32, 0, 0) != CE_None)
            st = ss_ctx_error(ctx, SS_ERR_INPUT, "cannot warp the %s '%s' onto the DEM: %s",
                              what, path, ss_gdal_message());
        if (op)
            GDALDestroyWarpOperation(op);
        wo->pTransformerArg = NULL;
        GDALDestroyWarpOptions(wo);
    }
    if (transform)
        GDALDestroyGenImgProjTransformer(transform);
    if (dst)
        GDALClose(dst);
    GDALClose(src);
    for (size_t i = 0; st == SS_OK && i < (size_t)w * h; ++i)
        if (isnan(values[i]))
            values[i] = SS_NODATA;
    return st;
}

ss_status ss_raster_onto_dem(ss_ctx *ctx, const char *path, const char *what, const ss_dem *dem,
                             float *values, int *warped)
{
    ss_bands b;
    *warped = 0;
    ss_status st = ss_bands_read(ctx, path, 1, 1, &b);
    if (st != SS_OK)
        return st;
    int same = on_dem_grid(dem, &b);
    if (same)
        memcpy(values, b.values[0], sizeof(float) * (size_t)b.width * (size_t)b.height);
    ss_bands_free(&b);
    if (same)
        return SS_OK;
    *warped = 1;
    CPLPushErrorHandler(CPLQuietErrorHandler);
    st = warp_onto(ctx, path, what, dem, values);
    CPLPopErrorHandler();
    return st;
}
