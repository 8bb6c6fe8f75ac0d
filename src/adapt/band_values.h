/* How GDAL means a band's stored values, for this adapter's readers
 * (dem_read.c, band_read.c): bands are read as doubles, which hold every
 * real data type GDAL has, and then compared with the band's nodata. Two
 * kinds need more: signed bytes that GDAL before 3.7 gives as Byte (marked
 * PIXELTYPE=SIGNEDBYTE; later versions give them as Int8, which reads as
 * signed by itself), and 64-bit nodata values. Complex bands are refused:
 * heights and products are real. Includes GDAL: adapter files only. */
#ifndef SS_BAND_VALUES_H
#define SS_BAND_VALUES_H

#include <math.h>

#include <gdal.h>

#include "skysweep.h"

typedef struct {
    int has_nodata;
    double nodata;    /* as a value read by ss_band_value compares with it */
    int signed_bytes; /* a Byte band whose bytes are signed */
} ss_band_values;

/* How band's values read; a complex band is refused (SS_ERR_INPUT, naming
 * path). */
ss_status ss_band_values_of(ss_ctx *ctx, const char *path, GDALRasterBandH band,
                            ss_band_values *values);

/* A value GDAL read as GDT_Float64, as the band means it; NAN where it is
 * the band's nodata or not finite. */
static inline double ss_band_value(const ss_band_values *values, double read)
{
    if (values->signed_bytes && read > 127.0)
        read -= 256.0;
    if (!isfinite(read) || (values->has_nodata && read == values->nodata))
        return NAN;
    return read;
}

#endif
