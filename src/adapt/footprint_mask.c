/* Building footprints as a mask of cells (footprint_mask.h). */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gdal.h>
#include <gdal_alg.h>
#include <ogr_api.h>

#include "footprint_mask.h"
#include "gdal_errors.h"

/* Segments per quarter circle of a buffer's rounded corners: OGR's own
 * default. */
#define BUFFER_QUADRANT_SEGMENTS 30

ss_status ss_footprints_mask(ss_ctx *ctx, const ss_dem *dem, const ss_footprints *f,
                             double buffer_m, unsigned char *mask)
{
    int w = dem->grid.width, h = dem->grid.height;
    memset(mask, 0, (size_t)w * (size_t)h);
    if (f->n == 0)
        return SS_OK;
    GDALDriverH mem = GDALGetDriverByName("MEM");
    GDALDatasetH ds = mem ? GDALCreate(mem, "", w, h, 1, GDT_Byte, NULL) : NULL;
    OGRGeometryH *geoms = calloc(f->n, sizeof *geoms);
    if (!ds || !geoms) {
        if (ds)
            GDALClose(ds);
        free(geoms);
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory rasterizing footprints");
    }
    GDALSetGeoTransform(ds, (double *)dem->geotransform);
    /* The buffer in the CRS's unit: metres per unit from the cell's size
     * in both (dem_read.c); a geographic CRS has no such ratio. */
    double buffer = buffer_m * fabs(dem->geotransform[1]) / dem->grid.cell_x_m;
    ss_status st = buffer_m > 0 && !isfinite(buffer)
                       ? ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                                      "--building-buffer needs a projected DSM (metres, not "
                                      "degrees): reproject it, or give --building-buffer 0")
                       : SS_OK;
    for (size_t i = 0; st == SS_OK && i < f->n; ++i) {
        OGRGeometryH g = f->items[i].geometry;
        geoms[i] =
            buffer_m > 0 ? OGR_G_Buffer(g, buffer, BUFFER_QUADRANT_SEGMENTS) : OGR_G_Clone(g);
        if (!geoms[i])
            st = ss_ctx_error(ctx, SS_ERR_INTERNAL, "cannot buffer footprint %s by %g m: %s",
                              f->items[i].id, buffer_m, ss_gdal_message());
    }
    int band = 1;
    double *burn = malloc(sizeof(double) * f->n);
    if (st == SS_OK && !burn)
        st = ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory rasterizing footprints");
    for (size_t i = 0; burn && i < f->n; ++i)
        burn[i] = 1.0;
    /* Without ALL_TOUCHED: the cells whose centres lie inside, as roofs
     * rasterizes its footprints. */
    if (st == SS_OK && (GDALRasterizeGeometries(ds, 1, &band, (int)f->n, geoms, NULL, NULL, burn,
                                                NULL, NULL, NULL) != CE_None ||
                        GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, w, h, mask, w, h,
                                     GDT_Byte, 0, 0) != CE_None))
        st = ss_ctx_error(ctx, SS_ERR_INTERNAL, "cannot rasterize the footprints: %s",
                          ss_gdal_message());
    for (size_t i = 0; i < f->n; ++i)
        if (geoms[i])
            OGR_G_DestroyGeometry(geoms[i]);
    free(geoms);
    free(burn);
    GDALClose(ds);
    return st;
}
