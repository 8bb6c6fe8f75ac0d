/* How GDAL means a band's stored values (see band_values.h). */
#include "config.h"

#include <string.h>

#include <cpl_string.h>
#include <gdal.h>

#include "band_values.h"

/* GDAL before 3.7 has no Int8: GeoTIFF's signed bytes come as Byte with
 * PIXELTYPE=SIGNEDBYTE, and RasterIO gives their raw bytes (-99 as 157). */
static int stores_signed_bytes(GDALRasterBandH band)
{
    const char *pixel_type = GDALGetMetadataItem(band, "PIXELTYPE", "IMAGE_STRUCTURE");
    return GDALGetRasterDataType(band) == GDT_Byte && pixel_type &&
           strcmp(pixel_type, "SIGNEDBYTE") == 0;
}

/* The nodata value as the doubles read compare with it: a 64-bit integer
 * one is taken exactly and rounded as RasterIO rounds the values. */
static double nodata_value(GDALRasterBandH band, int *has_nodata)
{
#if GDAL_VERSION_NUM >= GDAL_COMPUTE_VERSION(3, 5, 0)
    if (GDALGetRasterDataType(band) == GDT_Int64)
        return (double)GDALGetRasterNoDataValueAsInt64(band, has_nodata);
    if (GDALGetRasterDataType(band) == GDT_UInt64)
        return (double)GDALGetRasterNoDataValueAsUInt64(band, has_nodata);
#endif
    return GDALGetRasterNoDataValue(band, has_nodata);
}

ss_status ss_band_values_of(ss_ctx *ctx, const char *path, GDALRasterBandH band,
                            ss_band_values *values)
{
    GDALDataType type = GDALGetRasterDataType(band);
    if (GDALDataTypeIsComplex(type))
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                            "'%s' holds complex numbers (%s), not real values: convert it to a "
                            "real type first (gdal_translate -ot Float32 keeps the real part)",
                            path, GDALGetDataTypeName(type));
    values->has_nodata = 0;
    values->nodata = nodata_value(band, &values->has_nodata);
    values->signed_bytes = stores_signed_bytes(band);
    return SS_OK;
}
