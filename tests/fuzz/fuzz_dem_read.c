/* Fuzz target: the DEM reader (src/adapt/dem_read.c) on arbitrary bytes,
 * through GDAL's in-memory files. The input holds one to four tiles
 * separated by the line "\n--tile--\n"; the first byte of each tile picks
 * its file name's extension (none, .tif, .asc, .vrt, .xyz, .tif.aux.xml
 * side-car, ...), the rest is the file. The tiles are read as one DEM
 * (ss_dem_read, as the CLI does); what is read must be consistent (every
 * cell a finite height within the limits or NAN; counts add up; a refusal
 * is SS_ERR_INPUT / SS_ERR_MEMORY / SS_ERR_ARGUMENT with a one-line
 * message), and a readable DEM of at most 64 x 64 cells then goes through a
 * 4-direction SVF on the C reference, so that reader and sweep are fuzzed
 * together.
 *
 * Kept out: inputs naming paths outside /vsimem (a VRT may name any file:
 * /dev/zero would hang the run and network drivers must stay silent), and
 * rasters above 4 million cells (the reader's refusal is measured against
 * physical memory, far more than a fuzzer's 2 GB; tests/test_faults.sh
 * checks that refusal on a 10^6 x 10^6 VRT). */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal.h>

#include "dem_io.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

#define MAX_TILES 4
#define MAX_CELLS 4000000.0
static const char separator[] = "\n--tile--\n";
static const char *const extensions[] = {"", ".tif", ".asc", ".vrt", ".xyz", ".tif", ".grd",
                                         ".bt", ".tif.aux.xml", ".dem", ".hgt", ".flt"};
#define N_EXT (sizeof extensions / sizeof extensions[0])

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    ss_gdal_init();
    CPLSetConfigOption("GDAL_DISABLE_READDIR_ON_OPEN", "EMPTY_DIR");
    CPLSetConfigOption("GDAL_HTTP_TIMEOUT", "1");
    CPLSetConfigOption("GDAL_HTTP_CONNECTTIMEOUT", "1");
    CPLSetConfigOption("CPL_VSIL_CURL_ALLOWED_EXTENSIONS", "none");
    CPLSetConfigOption("GDAL_CACHEMAX", "64");
    return 0;
}

/* Paths a file may name that lie outside /vsimem. */
static int names_outside(const uint8_t *data, size_t size)
{
    static const char *const bad[] = {"/dev", "/proc", "/sys", "/vsicurl", "/vsis3", "/vsigs",
                                      "/vsiaz", "/vsiadls", "/vsioss", "/vsiswift", "/vsihdfs",
                                      "/vsiwebhdfs", "/vsistdin", "/vsistdout", "/vsisubfile",
                                      "/vsicrypt", "http:", "https:", "ftp:", "PG:"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        size_t n = strlen(bad[i]);
        for (size_t k = 0; k + n <= size; ++k)
            if (memcmp(data + k, bad[i], n) == 0)
                return 1;
    }
    /* A VRT source must be relative (to /vsimem/fuzz) or in /vsimem. */
    const char *tag = "SourceFilename";
    size_t tn = strlen(tag);
    for (size_t k = 0; k + tn < size; ++k)
        if (memcmp(data + k, tag, tn) == 0) {
            const uint8_t *end = memchr(data + k + tn, '>', size - k - tn);
            if (!end)
                continue;
            size_t after = (size_t)(end - data) + 1;
            if (after < size && data[after] == '/' &&
                (size - after < 8 || memcmp(data + after, "/vsimem/", 8) != 0))
                return 1;
        }
    return 0;
}

/* Cells of the mosaic of the tiles as GDAL sees them; HUGE_VAL if unknown. */
static double mosaic_cells(char **paths, int n)
{
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY, biggest = 0;
    for (int i = 0; i < n; ++i) {
        GDALDatasetH ds = GDALOpenEx(paths[i], GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL,
                                     NULL);
        if (!ds)
            continue;
        double w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds), gt[6];
        if (w * h > biggest)
            biggest = w * h;
        if (GDALGetGeoTransform(ds, gt) == CE_None && gt[1] != 0 && gt[5] != 0) {
            double cx = gt[0] / gt[1], cy = gt[3] / gt[5];
            x0 = fmin(x0, cx);
            x1 = fmax(x1, cx + w);
            y0 = fmin(y0, cy);
            y1 = fmax(y1, cy + h);
        }
        GDALClose(ds);
    }
    double span = n > 1 && isfinite(x0) ? (x1 - x0) * (y1 - y0) : 0;
    return isfinite(span) ? fmax(biggest, span) : HUGE_VAL;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 200000 || names_outside(data, size))
        return 0;
    char *paths[MAX_TILES];
    int n = 0;
    size_t start = 0, sep = strlen(separator);
    while (n < MAX_TILES && start <= size) {
        size_t end = start;
        while (end + sep <= size && memcmp(data + end, separator, sep) != 0)
            ++end;
        if (end + sep > size)
            end = size;
        size_t len = end - start;
        int ext = len ? data[start] % N_EXT : 0;
        char path[64];
        snprintf(path, sizeof path, "/vsimem/fuzz/t%d%s", n, extensions[ext]);
        /* GDAL takes ownership of a copy it frees on unlink. */
        GByte *copy = CPLMalloc(len > 0 ? len : 1);
        if (len > 1)
            memcpy(copy, data + start + 1, len - 1);
        VSILFILE *fp = VSIFileFromMemBuffer(path, copy, len > 0 ? len - 1 : 0, TRUE);
        if (fp)
            VSIFCloseL(fp);
        paths[n++] = CPLStrdup(path);
        start = end + sep;
    }

    if (mosaic_cells(paths, n) <= MAX_CELLS) {
        ss_ctx *ctx = ss_ctx_new();
        ss_dem dem;
        ss_status st = ss_dem_read(ctx, (const char *const *)paths, n, NULL, &dem);
        if (st != SS_OK) {
            const char *m = ss_ctx_message(ctx);
            FUZZ_CHECK(st == SS_ERR_INPUT || st == SS_ERR_MEMORY || st == SS_ERR_ARGUMENT,
                       "status %d: %s", (int)st, m);
            FUZZ_CHECK(m[0] && !strchr(m, '\n'), "message '%s'", m);
            FUZZ_CHECK(dem.grid.z == NULL && dem.crs_wkt == NULL, "refused DEM kept memory");
        } else {
            const ss_grid *g = &dem.grid;
            size_t cells = (size_t)g->width * g->height, finite = 0;
            FUZZ_CHECK(g->width >= 1 && g->height >= 1 && g->z, "grid %d x %d", g->width,
                       g->height);
            for (size_t c = 0; c < cells; ++c) {
                if (isnan(g->z[c]))
                    continue;
                FUZZ_CHECK(isfinite(g->z[c]) && fabs(g->z[c] + g->z_origin_m) <= 1e7 + 4,
                           "cell %zu: %g + origin %g", c, (double)g->z[c], g->z_origin_m);
                finite++;
            }
            FUZZ_CHECK(finite + dem.nodata_cells + dem.rejected_cells == cells,
                       "%zu finite + %zu nodata + %zu rejected != %zu cells", finite,
                       dem.nodata_cells, dem.rejected_cells, cells);
            FUZZ_CHECK(dem.geotransform[1] > 0 && dem.geotransform[5] < 0,
                       "pixel size %g x %g", dem.geotransform[1], dem.geotransform[5]);
            if (cells <= 64 * 64) {
                ss_ctx_use_device(ctx, "reference");
                ss_sweep_options opt;
                ss_sweep_options_default(&opt);
                opt.directions = 4;
                float *svf = malloc(cells * sizeof *svf);
                st = ss_svf(ctx, g, &opt, SS_SVF_DEF_GEOMETRIC, svf);
                FUZZ_CHECK(st == SS_OK || st == SS_ERR_INPUT, "svf status %d: %s", (int)st,
                           ss_ctx_message(ctx));
                for (size_t c = 0; st == SS_OK && c < cells; ++c)
                    FUZZ_CHECK(svf[c] == SS_NODATA || (svf[c] >= 0 && svf[c] <= 1),
                               "svf %g at %zu", (double)svf[c], c);
                free(svf);
            }
            ss_dem_free(&dem);
        }
        ss_ctx_free(ctx);
    }
    for (int i = 0; i < n; ++i) {
        VSIUnlink(paths[i]);
        CPLFree(paths[i]);
    }
    /* Side-cars GDAL may have written (.aux.xml, .ovr) go too. */
    char **left = VSIReadDir("/vsimem/fuzz");
    for (int i = 0; left && left[i]; ++i) {
        char p[600];
        snprintf(p, sizeof p, "/vsimem/fuzz/%s", left[i]);
        VSIUnlink(p);
    }
    CSLDestroy(left);
    return 0;
}
