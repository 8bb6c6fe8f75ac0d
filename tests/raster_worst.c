/* raster_worst A B [BAND...]: compares two rasters of the same size, band by
 * band (all bands, or those named), and prints "WORST MISMATCHED": the
 * largest |a - b| over the cells where both hold data, and the number of
 * cells that are nodata (or NaN) in one raster only. Exit 0; 2 when a file
 * cannot be read or the sizes or band counts differ (with one line saying
 * which). The shell tests' comparisons of whole rasters: GDAL reads the
 * values as doubles, exactly, where a text dump rounds them and costs
 * seconds a band on the large test DEMs. */
#include <gdal.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* Whether v is nodata of a band whose nodata value is nd (has_nd). */
static int is_nodata(double v, int has_nd, double nd)
{
    return isnan(v) || (has_nd && v == nd);
}

/* Adds band `band` of a and b to *worst and *mismatched; 0 on success,
 * else prints why and returns 2. */
static int compare_band(GDALDatasetH a, GDALDatasetH b, int band, double *worst,
                        long long *mismatched)
{
    GDALRasterBandH ba = GDALGetRasterBand(a, band), bb = GDALGetRasterBand(b, band);
    int w = GDALGetRasterXSize(a), h = GDALGetRasterYSize(a), has_a = 0, has_b = 0;
    double nd_a = GDALGetRasterNoDataValue(ba, &has_a), nd_b = GDALGetRasterNoDataValue(bb, &has_b);
    double *ra = malloc(sizeof *ra * (size_t)w), *rb = malloc(sizeof *rb * (size_t)w);
    int ok = ra && rb;
    if (!ok)
        fprintf(stderr, "raster_worst: out of memory for a row of %d cells\n", w);
    for (int r = 0; ok && r < h; ++r) {
        ok = GDALRasterIO(ba, GF_Read, 0, r, w, 1, ra, w, 1, GDT_Float64, 0, 0) == CE_None &&
             GDALRasterIO(bb, GF_Read, 0, r, w, 1, rb, w, 1, GDT_Float64, 0, 0) == CE_None;
        for (int c = 0; ok && c < w; ++c) {
            int na = is_nodata(ra[c], has_a, nd_a), nb = is_nodata(rb[c], has_b, nd_b);
            if (na != nb)
                ++*mismatched;
            else if (!na && fabs(ra[c] - rb[c]) > *worst)
                *worst = fabs(ra[c] - rb[c]);
        }
    }
    if (ra && rb && !ok)
        fprintf(stderr, "raster_worst: reading band %d failed\n", band);
    free(ra);
    free(rb);
    return ok ? 0 : 2;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: raster_worst A B [BAND...]\n");
        return 2;
    }
    GDALAllRegister();
    GDALDatasetH a = GDALOpen(argv[1], GA_ReadOnly), b = GDALOpen(argv[2], GA_ReadOnly);
    int status = 0;
    if (!a || !b) {
        fprintf(stderr, "raster_worst: cannot read %s\n", a ? argv[2] : argv[1]);
        status = 2;
    } else if (GDALGetRasterXSize(a) != GDALGetRasterXSize(b) ||
               GDALGetRasterYSize(a) != GDALGetRasterYSize(b) ||
               GDALGetRasterCount(a) != GDALGetRasterCount(b)) {
        fprintf(stderr, "raster_worst: %s and %s differ in size or bands\n", argv[1], argv[2]);
        status = 2;
    } else {
        double worst = 0;
        long long mismatched = 0;
        int n_bands = argc > 3 ? argc - 3 : GDALGetRasterCount(a);
        for (int i = 0; status == 0 && i < n_bands; ++i) {
            char *end = NULL;
            long band = argc > 3 ? strtol(argv[3 + i], &end, 10) : i + 1;
            if ((end && *end) || band < 1 || band > GDALGetRasterCount(a)) {
                fprintf(stderr, "raster_worst: no band %s\n", argv[3 + i]);
                status = 2;
            } else
                status = compare_band(a, b, (int)band, &worst, &mismatched);
        }
        if (status == 0)
            printf("%.17g %lld\n", worst, mismatched);
    }
    if (a)
        GDALClose(a);
    if (b)
        GDALClose(b);
    return status;
}
