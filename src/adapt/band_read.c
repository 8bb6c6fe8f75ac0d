/* Reads the bands of a raster through GDAL (see band_read.h). */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal.h>

#include "band_read.h"
#include "band_values.h"
#include "skysweep.h"
#include "dem_io.h"
#include "gdal_errors.h"

/* One band into dst, nodata as SS_NODATA; the band's name and unit. */
static ss_status read_band(ss_ctx *ctx, const char *path, GDALDatasetH ds, int number,
                           ss_bands *out, int k)
{
    GDALRasterBandH band = GDALGetRasterBand(ds, number);
    const char *desc = GDALGetDescription(band);
    const char *unit = GDALGetRasterUnitType(band);
    char fallback[32];
    snprintf(fallback, sizeof fallback, "band %d", number);
    out->names[k] = strdup(desc && *desc ? desc : fallback);
    out->units[k] = strdup(unit ? unit : "");
    size_t n = (size_t)out->width * (size_t)out->height;
    out->values[k] = malloc(n * sizeof(float));
    if (!out->names[k] || !out->units[k] || !out->values[k])
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory reading band %d of '%s'", number, path);
    ss_band_values values;
    ss_status st = ss_band_values_of(ctx, path, band, &values);
    if (st != SS_OK)
        return st;
    int has_scale = 0, has_offset = 0;
    double scale = GDALGetRasterScale(band, &has_scale);
    double offset = GDALGetRasterOffset(band, &has_offset);
    /* Doubles, so a nodata value that float cannot hold still compares. */
    const int rows_per_chunk = 256;
    double *buf = malloc(sizeof(double) * (size_t)out->width * rows_per_chunk);
    if (!buf)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory reading '%s'", path);
    for (int r0 = 0; r0 < out->height; r0 += rows_per_chunk) {
        int rows = out->height - r0 < rows_per_chunk ? out->height - r0 : rows_per_chunk;
        CPLErrorReset();
        if (GDALRasterIO(band, GF_Read, 0, r0, out->width, rows, buf, out->width, rows, GDT_Float64,
                         0, 0) != CE_None) {
            free(buf);
            return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot read band %d of '%s': %s", number, path,
                           ss_gdal_message());
        }
        float *dst = out->values[k] + (size_t)r0 * out->width;
        for (size_t i = 0; i < (size_t)out->width * rows; ++i) {
            double v = ss_band_value(&values, buf[i]);
            if (isnan(v))
                dst[i] = SS_NODATA;
            else
                dst[i] = (float)(v * (has_scale ? scale : 1.0) + (has_offset ? offset : 0.0));
        }
    }
    free(buf);
    return SS_OK;
}

ss_status ss_bands_read(ss_ctx *ctx, const char *path, int first_band, int n_bands, ss_bands *out)
{
    memset(out, 0, sizeof *out);
    if (access(path, F_OK) != 0 && strncmp(path, "/vsi", 4) != 0)
        return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot open '%s': no such file", path);
    ss_gdal_init();
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
    GDALDatasetH ds = GDALOpenEx(path, GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL, NULL);
    ss_status st = SS_OK;
    if (!ds)
        st = ss_ctx_error(ctx, SS_ERR_INPUT, "cannot read '%s' as a raster: %s", path, ss_gdal_message());
    if (st == SS_OK) {
        out->width = GDALGetRasterXSize(ds);
        out->height = GDALGetRasterYSize(ds);
        out->file_bands = GDALGetRasterCount(ds);
        out->has_geotransform = GDALGetGeoTransform(ds, out->geotransform) == CE_None;
        if (!out->has_geotransform) {
            double identity[6] = {0, 1, 0, 0, 0, -1};
            memcpy(out->geotransform, identity, sizeof identity);
        }
        int last = n_bands > 0 ? first_band + n_bands - 1 : out->file_bands;
        if (first_band < 1 || last > out->file_bands || last < first_band)
            st = ss_ctx_error(ctx, SS_ERR_ARGUMENT, "'%s' has %d band%s: there is no band %d", path,
                         out->file_bands, out->file_bands == 1 ? "" : "s",
                         first_band < 1 ? first_band : last);
        else {
            out->first_band = first_band;
            out->n_bands = last - first_band + 1;
        }
    }
    if (st == SS_OK) {
        out->values = calloc((size_t)out->n_bands, sizeof *out->values);
        out->names = calloc((size_t)out->n_bands, sizeof *out->names);
        out->units = calloc((size_t)out->n_bands, sizeof *out->units);
        if (!out->values || !out->names || !out->units)
            st = ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory reading '%s'", path);
    }
    for (int k = 0; st == SS_OK && k < out->n_bands; ++k)
        st = read_band(ctx, path, ds, first_band + k, out, k);
    if (ds)
        GDALClose(ds);
    CPLPopErrorHandler();
    if (st != SS_OK)
        ss_bands_free(out);
    return st;
}

void ss_bands_free(ss_bands *bands)
{
    for (int k = 0; k < bands->n_bands; ++k) {
        if (bands->values)
            free(bands->values[k]);
        if (bands->names)
            free(bands->names[k]);
        if (bands->units)
            free(bands->units[k]);
    }
    free(bands->values);
    free(bands->names);
    free(bands->units);
    memset(bands, 0, sizeof *bands);
}
