/* GDAL adapter round trips: what the writer stores (CRS, geotransform,
 * nodata, band descriptions and units, metadata, values) is what GDAL reads
 * back; the reader takes every integer and float type with its nodata,
 * scale and offset; four tiles read together equal the merged DEM; and the
 * writer never leaves a file behind when it is aborted or given NaN. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <cpl_conv.h>
#include <gdal.h>
#include <gdal_utils.h>
#include <ogr_srs_api.h>

#include "dem_io.h"
#include "tap.h"
#include "testlib.h"

static char work[256];

static void make_dem(const char *path, GDALDataType type, int w, int h, const double gt[6],
                     int has_nodata, double nodata, double scale, double offset)
{
    GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), path, w, h, 1, type, NULL);
    GDALSetGeoTransform(ds, (double *)gt);
    OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
    OSRImportFromEPSG(srs, 32605);
    GDALSetSpatialRef(ds, srs);
    OSRDestroySpatialReference(srs);
    GDALRasterBandH b = GDALGetRasterBand(ds, 1);
    if (has_nodata)
        GDALSetRasterNoDataValue(b, nodata);
    if (scale != 1.0 || offset != 0.0) {
        GDALSetRasterScale(b, scale);
        GDALSetRasterOffset(b, offset);
    }
    double *v = malloc(sizeof(double) * (size_t)w * h);
    for (int i = 0; i < w * h; ++i)
        v[i] = (i * 37) % (type == GDT_Byte ? 250 : 1000);
    if (has_nodata)
        v[3] = nodata;
    if (GDALRasterIO(b, GF_Write, 0, 0, w, h, v, w, h, GDT_Float64, 0, 0) != CE_None)
        tap_diag("write failed");
    free(v);
    GDALClose(ds);
}

static void reader_types(void)
{
    const struct {
        GDALDataType type;
        double nodata, scale, offset;
    } cases[] = {{GDT_Int16, -32768, 1, 0},  {GDT_UInt16, 65535, 0.1, -50},
                 {GDT_Int32, -99999, 1, 0},  {GDT_Float32, -3.4028234663852886e38, 1, 0},
                 {GDT_Float64, -9999, 1, 0}, {GDT_Byte, 255, 2, 100}};
    const double gt[6] = {254325, 30, 0, 2153655, 0, -30};
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        char path[300];
        snprintf(path, sizeof path, "%s/type%zu.tif", work, i);
        make_dem(path, cases[i].type, 13, 7, gt, 1, cases[i].nodata, cases[i].scale,
                 cases[i].offset);
        ss_ctx *ctx = ss_ctx_new();
        ss_dem dem;
        const char *paths[] = {path};
        ss_status st = ss_dem_read(ctx, paths, 1, NULL, &dem);
        int good = st == SS_OK && dem.nodata_cells == 1 && isnan(dem.grid.z[3]);
        double worst = 0;
        for (int k = 0; good && k < 13 * 7; ++k) {
            if (k == 3)
                continue;
            double raw = (k * 37) % (cases[i].type == GDT_Byte ? 250 : 1000);
            double want = raw * cases[i].scale + cases[i].offset;
            worst = fmax(worst, fabs(dem.grid.z[k] + dem.grid.z_origin_m - want));
        }
        tap_ok(good && worst < 1e-3 && dem.grid.cell_x_m == 30 && dem.grid.cell_y_m == 30,
               "reader: %s with nodata %g, scale %g, offset %g: heights within %.1e m, 1 "
               "nodata cell %s",
               GDALGetDataTypeName(cases[i].type), cases[i].nodata, cases[i].scale,
               cases[i].offset, worst, st == SS_OK ? "" : ss_ctx_message(ctx));
        if (st == SS_OK)
            ss_dem_free(&dem);
        ss_ctx_free(ctx);
    }
}

static void mosaic(void)
{
    const int w = 40, h = 30;
    const double gt[6] = {254325, 30, 0, 2153655, 0, -30};
    char whole[300];
    snprintf(whole, sizeof whole, "%s/whole.tif", work);
    make_dem(whole, GDT_Float32, w, h, gt, 0, 0, 1, 0);
    /* Four tiles of unequal size, and a fifth apart from the first. */
    const int cuts[5][4] = {
        {0, 0, 17, 12}, {17, 0, 23, 12}, {0, 12, 17, 18}, {17, 12, 23, 18}, {30, 20, 10, 10}};
    char tiles[5][300];
    const char *tile_paths[5];
    GDALDatasetH src = GDALOpen(whole, GA_ReadOnly);
    for (int t = 0; t < 5; ++t) {
        snprintf(tiles[t], sizeof tiles[t], "%s/tile%d.tif", work, t);
        char a[4][16];
        for (int k = 0; k < 4; ++k)
            snprintf(a[k], sizeof a[k], "%d", cuts[t][k]);
        char *argv[] = {"-srcwin", a[0], a[1], a[2], a[3], NULL};
        GDALTranslateOptions *o = GDALTranslateOptionsNew(argv, NULL);
        GDALClose(GDALTranslate(tiles[t], src, o, NULL));
        GDALTranslateOptionsFree(o);
        tile_paths[t] = tiles[t];
    }
    GDALClose(src);
    ss_ctx *ctx = ss_ctx_new();
    ss_dem one, four;
    const char *one_path[] = {whole};
    int ok = ss_dem_read(ctx, one_path, 1, NULL, &one) == SS_OK &&
             ss_dem_read(ctx, tile_paths, 4, NULL, &four) == SS_OK;
    size_t differ = 0;
    if (ok) {
        ok = one.grid.width == four.grid.width && one.grid.height == four.grid.height &&
             memcmp(one.geotransform, four.geotransform, sizeof one.geotransform) == 0;
        for (int k = 0; ok && k < w * h; ++k)
            differ += one.grid.z[k] + one.grid.z_origin_m != four.grid.z[k] + four.grid.z_origin_m;
    }
    tap_ok(ok && differ == 0, "four tiles read together equal the merged DEM (%zu cells differ) %s",
           differ, ss_ctx_message(ctx));
    /* Tiles that do not touch are refused. */
    const char *apart[] = {tiles[0], tiles[4]};
    ss_dem bad;
    ss_status st = ss_dem_read(ctx, apart, 2, NULL, &bad);
    tap_ok(st == SS_ERR_INPUT && strstr(ss_ctx_message(ctx), "does not touch"),
           "tiles that do not touch are refused (%s)", ss_ctx_message(ctx));
    if (st == SS_OK)
        ss_dem_free(&bad);
    ss_dem_free(&one);
    ss_dem_free(&four);
    ss_ctx_free(ctx);
}

static void writer_round_trip(void)
{
    const double gt[6] = {254325, 30, 0, 2153655, 0, -30};
    char in[300], out[300];
    snprintf(in, sizeof in, "%s/in.tif", work);
    snprintf(out, sizeof out, "%s/out.tif", work);
    make_dem(in, GDT_Int16, 9, 5, gt, 1, -32768, 1, 0);
    ss_ctx *ctx = ss_ctx_new();
    ss_dem dem;
    const char *paths[] = {in};
    if (!tap_ok(ss_dem_read(ctx, paths, 1, NULL, &dem) == SS_OK, "read the input"))
        return;
    ss_raster_writer *w;
    float band1[45], band2[45];
    for (int k = 0; k < 45; ++k) {
        band1[k] = k * 0.5f;
        band2[k] = k == 7 ? SS_NODATA : -k * 1.25f;
    }
    ss_status st = ss_writer_open(ctx, out, &dem, 2, NULL, NULL, &w);
    if (st == SS_OK)
        st = ss_writer_band(w, 1, band1, "azimuth 0", "deg");
    if (st == SS_OK)
        st = ss_writer_band(w, 2, band2, "azimuth 180", "deg");
    if (st == SS_OK) {
        ss_writer_metadata(w, "DIRECTIONS", "2");
        st = ss_writer_commit(w, NULL, NULL);
    }
    tap_ok(st == SS_OK, "write a 2-band output %s", ss_ctx_message(ctx));
    GDALDatasetH ds = GDALOpen(out, GA_ReadOnly);
    double got_gt[6] = {0};
    int ok = ds && GDALGetGeoTransform(ds, got_gt) == CE_None &&
             memcmp(got_gt, gt, sizeof got_gt) == 0;
    tap_ok(ok, "geotransform survives");
    OGRSpatialReferenceH want = OSRNewSpatialReference(NULL);
    OSRImportFromEPSG(want, 32605);
    tap_ok(ds && GDALGetSpatialRef(ds) && OSRIsSame(GDALGetSpatialRef(ds), want),
           "CRS survives (EPSG:32605)");
    OSRDestroySpatialReference(want);
    int has = 0;
    double nd = ds ? GDALGetRasterNoDataValue(GDALGetRasterBand(ds, 2), &has) : 0;
    tap_ok(has && nd == SS_NODATA, "nodata value -9999 survives");
    tap_ok(ds && strcmp(GDALGetDescription(GDALGetRasterBand(ds, 2)), "azimuth 180") == 0 &&
               strcmp(GDALGetRasterUnitType(GDALGetRasterBand(ds, 1)), "deg") == 0,
           "band descriptions and units survive");
    const char *md = ds ? GDALGetMetadataItem(ds, "DIRECTIONS", NULL) : NULL;
    tap_ok(md && strcmp(md, "2") == 0, "metadata survives");
    float back[45];
    ok = ds && GDALRasterIO(GDALGetRasterBand(ds, 2), GF_Read, 0, 0, 9, 5, back, 9, 5,
                            GDT_Float32, 0, 0) == CE_None &&
         memcmp(back, band2, sizeof back) == 0;
    tap_ok(ok, "values survive bit for bit");
    if (ds)
        GDALClose(ds);

    /* Byte bands (hillshade's): values rounded half to even and held in
     * 1..255 as gdaldem's nearbyint would, nodata 0; ties, the range's
     * ends and far beyond (the writer refuses what is not finite). */
    char out_byte[300];
    snprintf(out_byte, sizeof out_byte, "%s/byte.tif", work);
    static const float edges[] = {0.5f,   1.5f,   2.5f,   3.5f,    254.5f, 253.5f, 255.49f,
                                  255.5f, -3.0f,  0.0f,   1e30f,   -1e30f, 3.4e38f, -3.4e38f,
                                  0.999f, 1.001f, 127.5f, 128.5f,  99.49999f};
    float shades[45];
    int n_edges = (int)(sizeof edges / sizeof edges[0]);
    for (int k = 0; k < 45; ++k)
        shades[k] = k == 44 ? SS_NODATA : k < n_edges ? edges[k] : 1.0f + k * 5.7f;
    st = ss_writer_open_byte(ctx, out_byte, &dem, 1, NULL, NULL, &w);
    if (st == SS_OK)
        st = ss_writer_rows(w, 1, 0, 5, shades);
    if (st == SS_OK)
        st = ss_writer_commit(w, NULL, NULL);
    unsigned char bytes[45];
    ds = st == SS_OK ? GDALOpen(out_byte, GA_ReadOnly) : NULL;
    int wrong = ds ? 0 : 45;
    if (ds && GDALRasterIO(GDALGetRasterBand(ds, 1), GF_Read, 0, 0, 9, 5, bytes, 9, 5, GDT_Byte,
                           0, 0) != CE_None)
        wrong = 45;
    for (int k = 0; ds && k < 45; ++k) {
        int expected =
            shades[k] == SS_NODATA ? 0 : (int)fmin(255.0, fmax(1.0, nearbyint(shades[k])));
        wrong += bytes[k] != expected;
    }
    tap_ok(st == SS_OK && wrong == 0,
           "byte bands: ties to even, held in 1..255, nodata 0, as nearbyint, fmax and fmin "
           "give them (%d of 45 wrong) %s",
           wrong, st == SS_OK ? "" : ss_ctx_message(ctx));
    if (ds)
        GDALClose(ds);

    /* NaN is refused and abort leaves nothing. */
    char out2[300];
    snprintf(out2, sizeof out2, "%s/nan.tif", work);
    band1[4] = NAN;
    st = ss_writer_open(ctx, out2, &dem, 1, NULL, NULL, &w);
    ss_status st2 = st == SS_OK ? ss_writer_band(w, 1, band1, NULL, NULL) : st;
    if (st == SS_OK)
        ss_writer_abort(w);
    tap_ok(st == SS_OK && st2 == SS_ERR_INTERNAL && access(out2, F_OK) != 0,
           "a NaN value is refused and the aborted output leaves no file");
    ss_dem_free(&dem);
    ss_ctx_free(ctx);
}

int main(void)
{
    GDALAllRegister();
    snprintf(work, sizeof work, "%s/ss-geotiff-XXXXXX", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
    if (!mkdtemp(work)) {
        printf("Bail out! cannot make a temporary folder\n");
        return 99;
    }
    reader_types();
    mosaic();
    writer_round_trip();
    /* Remove what the tests made. */
    const char *names[] = {"type0.tif", "type1.tif", "type2.tif", "type3.tif", "type4.tif",
                           "type5.tif", "whole.tif", "tile0.tif", "tile1.tif", "tile2.tif",
                           "tile3.tif", "tile4.tif", "in.tif", "out.tif", "byte.tif"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
        char p[400];
        snprintf(p, sizeof p, "%s/%s", work, names[i]);
        unlink(p);
    }
    rmdir(work);
    return tap_done();
}
