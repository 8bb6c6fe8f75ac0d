/* GDAL adapter: the bands of any raster as products are held (float32,
 * SS_NODATA at nodata), with the grid they lie on, for quicklooks and
 * drapes. DEMs are read by dem_io.h, which takes single-band rasters only. */
#ifndef SS_BAND_READ_H
#define SS_BAND_READ_H

#include "skysweep.h"

typedef struct {
    int width, height;
    int file_bands;          /* bands in the file */
    int first_band, n_bands; /* values[k] holds band first_band + k (1-based) */
    /* GDAL's geotransform; {0, 1, 0, 0, 0, -1} when the file has none, as
     * dem_io.h gives a DEM without georeferencing, so grids compare alike. */
    double geotransform[6];
    int has_geotransform;
    float **values; /* n_bands arrays of width*height, row 0 at the top */
    char **names;   /* the band's description, else "band N" */
    char **units;   /* the band's unit, "" when it has none */
} ss_bands;

/* Reads bands first_band .. first_band + n_bands - 1 of path (n_bands 0:
 * through the last band). Values get the band's scale and offset; the
 * band's nodata value, NaN and Inf become SS_NODATA. */
ss_status ss_bands_read(ss_ctx *ctx, const char *path, int first_band, int n_bands, ss_bands *out);
void ss_bands_free(ss_bands *bands);

#endif
