/* Reads a DEM through GDAL: one file, or several tiles on one grid mosaicked
 * by an in-memory VRT. Heights become float32 relative to a local origin,
 * nodata (tagged value, NaN, Inf, absurd heights) becomes NAN. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_http.h>
#include <gdal.h>
#include <gdal_utils.h>
#include <ogr_srs_api.h>

#include "ctx_internal.h"
#include "dem_io.h"

/* Heights beyond this are fill values or corruption, not terrain. */
#define SS_Z_PLAUSIBLE_M 1e7

void ss_gdal_init(void)
{
    if (GDALGetDriverCount() == 0)
        GDALAllRegister();
}

static const char *gdal_message(void)
{
    const char *m = CPLGetLastErrorMsg();
    return m && *m ? m : "no details from GDAL";
}

typedef struct {
    GDALDatasetH ds;
    double gt[6];
    int width, height;
} tile;

/* Tiles must share a CRS and a grid (same cell size, origins on whole
 * cells) and form one connected area, so the mosaic is seamless. */
static ss_status check_tiles(ss_ctx *ctx, const char *const *paths, tile *tiles, int n)
{
    OGRSpatialReferenceH srs0 = GDALGetSpatialRef(tiles[0].ds);
    for (int i = 1; i < n; ++i) {
        OGRSpatialReferenceH srs = GDALGetSpatialRef(tiles[i].ds);
        if ((srs0 == NULL) != (srs == NULL) || (srs0 && !OSRIsSame(srs0, srs)))
            return ss_fail(ctx, SS_ERR_INPUT, "tiles '%s' and '%s' have different CRSs",
                           paths[0], paths[i]);
        for (int k = 1; k <= 5; k += 4)
            if (fabs(tiles[i].gt[k] - tiles[0].gt[k]) > 1e-9 * fabs(tiles[0].gt[k]))
                return ss_fail(ctx, SS_ERR_INPUT,
                               "tiles '%s' and '%s' have different cell sizes", paths[0],
                               paths[i]);
        double off_x = (tiles[i].gt[0] - tiles[0].gt[0]) / tiles[0].gt[1];
        double off_y = (tiles[i].gt[3] - tiles[0].gt[3]) / tiles[0].gt[5];
        if (fabs(off_x - nearbyint(off_x)) > 1e-3 || fabs(off_y - nearbyint(off_y)) > 1e-3)
            return ss_fail(ctx, SS_ERR_INPUT,
                           "tile '%s' is not aligned on the grid of '%s' (origins differ by a "
                           "fraction of a cell)",
                           paths[i], paths[0]);
    }
    /* Connectivity: grow a set from tile 0 through tiles whose cell
     * rectangles overlap or share an edge. */
    int *reached = calloc((size_t)n, sizeof *reached);
    if (!reached)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory checking tiles");
    reached[0] = 1;
    for (int changed = 1; changed;) {
        changed = 0;
        for (int i = 0; i < n; ++i) {
            if (reached[i])
                continue;
            for (int j = 0; j < n && !reached[i]; ++j) {
                if (!reached[j])
                    continue;
                double ax0 = (tiles[i].gt[0] - tiles[0].gt[0]) / tiles[0].gt[1];
                double ay0 = (tiles[i].gt[3] - tiles[0].gt[3]) / tiles[0].gt[5];
                double bx0 = (tiles[j].gt[0] - tiles[0].gt[0]) / tiles[0].gt[1];
                double by0 = (tiles[j].gt[3] - tiles[0].gt[3]) / tiles[0].gt[5];
                int touch_x = ax0 <= bx0 + tiles[j].width + 1e-3 &&
                              bx0 <= ax0 + tiles[i].width + 1e-3;
                int touch_y = ay0 <= by0 + tiles[j].height + 1e-3 &&
                              by0 <= ay0 + tiles[i].height + 1e-3;
                if (touch_x && touch_y)
                    reached[i] = changed = 1;
            }
        }
    }
    int lonely = -1;
    for (int i = 0; i < n && lonely < 0; ++i)
        if (!reached[i])
            lonely = i;
    free(reached);
    if (lonely >= 0)
        return ss_fail(ctx, SS_ERR_INPUT,
                       "tile '%s' does not touch the others: tiles must form one connected "
                       "area",
                       paths[lonely]);
    return SS_OK;
}

/* Cell sizes in metres from the geotransform and CRS. */
static ss_status cell_size_metres(ss_ctx *ctx, const char *path, GDALDatasetH ds,
                                  const double gt[6], const ss_dem_read_options *opt,
                                  int georeferenced, double *cx, double *cy, char **wkt)
{
    *wkt = NULL;
    OGRSpatialReferenceH srs = GDALGetSpatialRef(ds);
    if (!georeferenced || !srs) {
        if (opt && opt->heightmap_cell_m > 0) {
            *cx = *cy = opt->heightmap_cell_m;
            return SS_OK;
        }
        return ss_fail(ctx, SS_ERR_INPUT,
                       "'%s' has no %s: it is not a georeferenced DEM (for a plain heightmap, "
                       "give its cell size with --cell-size METRES)",
                       path, georeferenced ? "coordinate reference system" : "georeferencing");
    }
    if (OSRIsGeographic(srs)) {
        /* Degrees: the ground size comes from geodesy (src/adapt/frame.c). */
        *cx = *cy = NAN;
    } else if (OSRIsProjected(srs) || OSRIsLocal(srs)) {
        double unit = OSRGetLinearUnits(srs, NULL);
        if (!(unit > 0))
            return ss_fail(ctx, SS_ERR_INPUT, "'%s': the CRS has no usable linear unit", path);
        *cx = fabs(gt[1]) * unit;
        *cy = fabs(gt[5]) * unit;
    } else {
        return ss_fail(ctx, SS_ERR_INPUT,
                       "'%s': unsupported kind of CRS (neither projected nor geographic)", path);
    }
    char *w = NULL;
    if (OSRExportToWkt(srs, &w) == OGRERR_NONE)
        *wkt = strdup(w);
    CPLFree(w);
    return SS_OK;
}

static ss_status open_tiles(ss_ctx *ctx, const char *const *paths, int n, tile *tiles,
                            int *georeferenced)
{
    *georeferenced = 1;
    for (int i = 0; i < n; ++i) {
        if (access(paths[i], F_OK) != 0 && strncmp(paths[i], "/vsi", 4) != 0)
            return ss_fail(ctx, SS_ERR_INPUT, "cannot open '%s': no such file", paths[i]);
        CPLErrorReset();
        tiles[i].ds = GDALOpenEx(paths[i], GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL, NULL);
        if (!tiles[i].ds)
            return ss_fail(ctx, SS_ERR_INPUT, "cannot read '%s' as a raster: %s", paths[i],
                           gdal_message());
        tiles[i].width = GDALGetRasterXSize(tiles[i].ds);
        tiles[i].height = GDALGetRasterYSize(tiles[i].ds);
        int bands = GDALGetRasterCount(tiles[i].ds);
        if (bands != 1)
            return ss_fail(ctx, SS_ERR_INPUT,
                           "'%s' has %d bands: a DEM has exactly one (height)", paths[i], bands);
        if (GDALGetGeoTransform(tiles[i].ds, tiles[i].gt) != CE_None) {
            *georeferenced = 0;
            double identity[6] = {0, 1, 0, 0, 0, -1};
            memcpy(tiles[i].gt, identity, sizeof identity);
        }
        const double *gt = tiles[i].gt;
        if (gt[2] != 0.0 || gt[4] != 0.0)
            return ss_fail(ctx, SS_ERR_INPUT,
                           "'%s' has a rotated geotransform, which is not supported: warp it "
                           "north-up first (gdalwarp)",
                           paths[i]);
        if (!(gt[1] > 0.0) || !(gt[5] < 0.0) || !isfinite(gt[0]) || !isfinite(gt[3]))
            return ss_fail(ctx, SS_ERR_INPUT,
                           "'%s' is not a north-up grid (pixel size %g x %g): warp it north-up "
                           "first (gdalwarp)",
                           paths[i], gt[1], gt[5]);
    }
    return SS_OK;
}

/* Reads the band into grid->z: heights relative to the first plausible
 * height found, NAN where there is none. */
static ss_status read_heights(ss_ctx *ctx, const char *what, GDALRasterBandH band, ss_dem *dem)
{
    ss_grid *g = &dem->grid;
    int has_nodata = 0;
    double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
    int has_scale = 0, has_offset = 0;
    double scale = GDALGetRasterScale(band, &has_scale);
    double offset = GDALGetRasterOffset(band, &has_offset);
    if (!has_scale)
        scale = 1.0;
    if (!has_offset)
        offset = 0.0;
    const int rows_per_chunk = 256;
    double *buf = malloc(sizeof(double) * (size_t)g->width * rows_per_chunk);
    if (!buf)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory reading '%s'", what);
    int have_origin = 0;
    for (int r0 = 0; r0 < g->height; r0 += rows_per_chunk) {
        int rows = g->height - r0 < rows_per_chunk ? g->height - r0 : rows_per_chunk;
        CPLErrorReset();
        if (GDALRasterIO(band, GF_Read, 0, r0, g->width, rows, buf, g->width, rows, GDT_Float64,
                         0, 0) != CE_None) {
            free(buf);
            return ss_fail(ctx, SS_ERR_INPUT, "cannot read rows %d..%d of '%s': %s", r0,
                           r0 + rows - 1, what, gdal_message());
        }
        for (size_t i = 0; i < (size_t)g->width * rows; ++i) {
            double v = buf[i];
            float *dst = &g->z[(size_t)r0 * g->width + i];
            if (!isfinite(v) || (has_nodata && v == nodata)) {
                *dst = NAN;
                dem->nodata_cells++;
                continue;
            }
            v = v * scale + offset;
            if (!(fabs(v) <= SS_Z_PLAUSIBLE_M)) {
                *dst = NAN;
                dem->rejected_cells++;
                continue;
            }
            if (!have_origin) {
                g->z_origin_m = nearbyint(v);
                have_origin = 1;
            }
            *dst = (float)(v - g->z_origin_m);
        }
    }
    free(buf);
    return SS_OK;
}

/* Mosaic cells covered by no tile are nodata, whatever the VRT filled in. */
static void mark_uncovered(ss_dem *dem, const tile *tiles, int n)
{
    ss_grid *g = &dem->grid;
    unsigned char *covered = calloc((size_t)g->width * g->height, 1);
    if (!covered)
        return;
    for (int i = 0; i < n; ++i) {
        int c0 = (int)nearbyint((tiles[i].gt[0] - dem->geotransform[0]) / dem->geotransform[1]);
        int r0 = (int)nearbyint((tiles[i].gt[3] - dem->geotransform[3]) / dem->geotransform[5]);
        for (int r = r0; r < r0 + tiles[i].height; ++r)
            for (int c = c0; c < c0 + tiles[i].width; ++c)
                if (r >= 0 && c >= 0 && r < g->height && c < g->width)
                    covered[(size_t)r * g->width + c] = 1;
    }
    for (size_t k = 0; k < (size_t)g->width * g->height; ++k)
        if (!covered[k] && isfinite(g->z[k])) {
            g->z[k] = NAN;
            dem->nodata_cells++;
        }
    free(covered);
}

/* Network reads only where the user names them. A file given as input (a
 * VRT, say) may name /vsicurl/, /vsis3/ or http:// sources that GDAL would
 * fetch (and /vsis3/ probes the cloud metadata address): unless an input
 * path itself names a network source, the read runs with GDAL's curl file
 * systems accepting no file and its HTTP fetches refused. */
static int names_network(const char *const *paths, int n)
{
    static const char *const marks[] = {"/vsicurl", "/vsis3", "/vsigs", "/vsiaz", "/vsiadls",
                                        "/vsioss", "/vsiswift", "/vsihdfs", "/vsiwebhdfs",
                                        "://"};
    for (int i = 0; i < n; ++i)
        for (size_t k = 0; k < sizeof marks / sizeof marks[0]; ++k)
            if (strstr(paths[i], marks[k]))
                return 1;
    return 0;
}

static CPLHTTPResult *refuse_fetch(const char *url, CSLConstList options,
                                   GDALProgressFunc progress, void *progress_arg,
                                   CPLHTTPFetchWriteFunc write, void *write_arg, void *user)
{
    (void)options, (void)progress, (void)progress_arg, (void)write, (void)write_arg, (void)user;
    CPLHTTPResult *r = CPLCalloc(1, sizeof *r);
    r->nStatus = 1;
    r->pszErrBuf = CPLStrdup("skysweep reads the network only for inputs named on its "
                             "command line");
    CPLError(CE_Failure, CPLE_AppDefined, "'%s' was not fetched: %s", url, r->pszErrBuf);
    return r;
}

#define SS_CURL_FENCE "/vsicurl/skysweep-reads-only-network-inputs-named-on-its-command-line"

ss_status ss_dem_read(ss_ctx *ctx, const char *const *paths, int n_paths,
                      const ss_dem_read_options *opt, ss_dem *dem)
{
    memset(dem, 0, sizeof *dem);
    if (n_paths < 1)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "no input DEM given");
    ss_gdal_init();
    int fenced = !names_network(paths, n_paths);
    char *saved_allowed = NULL;
    if (fenced) {
        const char *a = CPLGetThreadLocalConfigOption("CPL_VSIL_CURL_ALLOWED_FILENAME", NULL);
        saved_allowed = a ? CPLStrdup(a) : NULL;
        CPLSetThreadLocalConfigOption("CPL_VSIL_CURL_ALLOWED_FILENAME", SS_CURL_FENCE);
        fenced = CPLHTTPPushFetchCallback(refuse_fetch, NULL) ? 2 : 1;
    }
    CPLPushErrorHandler(CPLQuietErrorHandler);
    tile *tiles = calloc((size_t)n_paths, sizeof *tiles);
    GDALDatasetH mosaic = NULL;
    int georeferenced = 1;
    ss_status st = tiles ? open_tiles(ctx, paths, n_paths, tiles, &georeferenced)
                         : ss_fail(ctx, SS_ERR_MEMORY, "out of memory");
    if (st == SS_OK && n_paths > 1)
        st = check_tiles(ctx, paths, tiles, n_paths);
    GDALDatasetH ds = tiles ? tiles[0].ds : NULL;
    if (st == SS_OK && n_paths > 1) {
        GDALDatasetH *handles = malloc(sizeof *handles * (size_t)n_paths);
        for (int i = 0; handles && i < n_paths; ++i)
            handles[i] = tiles[i].ds;
        int usage_error = 0;
        CPLErrorReset();
        mosaic = handles ? GDALBuildVRT("", n_paths, handles, NULL, NULL, &usage_error) : NULL;
        free(handles);
        if (!mosaic)
            st = ss_fail(ctx, SS_ERR_INPUT, "cannot mosaic the %d tiles: %s", n_paths,
                         gdal_message());
        ds = mosaic;
    }
    double cx = 0, cy = 0;
    if (st == SS_OK) {
        GDALGetGeoTransform(ds, dem->geotransform);
        if (!georeferenced) {
            double identity[6] = {0, 1, 0, 0, 0, -1};
            memcpy(dem->geotransform, identity, sizeof identity);
        }
        st = cell_size_metres(ctx, paths[0], ds, dem->geotransform, opt, georeferenced, &cx, &cy,
                              &dem->crs_wkt);
    }
    if (st == SS_OK) {
        int w = GDALGetRasterXSize(ds), h = GDALGetRasterYSize(ds);
        double bytes_needed = (double)w * (double)h * 16.0; /* grid, stack, two outputs */
        double phys = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
        if (phys > 0 && bytes_needed > 0.8 * phys)
            st = ss_fail(ctx, SS_ERR_MEMORY,
                         "'%s' has %d x %d cells: sweeping it needs about %.1f GB, more than "
                         "this machine's %.1f GB",
                         paths[0], w, h, bytes_needed / 1e9, phys / 1e9);
        else if ((st = ss_grid_alloc(ctx, &dem->grid, w, h, cx, cy)) == SS_ERR_ARGUMENT)
            st = SS_ERR_INPUT; /* a size no sweep handles is the input's fault (exit 3) */
    }
    if (st == SS_OK) {
        snprintf(dem->description, sizeof dem->description, "%s%s",
                 n_paths > 1 ? "mosaic from " : "", paths[0]);
        st = read_heights(ctx, paths[0], GDALGetRasterBand(ds, 1), dem);
    }
    if (st == SS_OK && n_paths > 1)
        mark_uncovered(dem, tiles, n_paths);
    if (mosaic)
        GDALClose(mosaic);
    for (int i = 0; tiles && i < n_paths; ++i)
        if (tiles[i].ds)
            GDALClose(tiles[i].ds);
    free(tiles);
    CPLPopErrorHandler();
    if (fenced) {
        if (fenced == 2)
            CPLHTTPPopFetchCallback();
        CPLSetThreadLocalConfigOption("CPL_VSIL_CURL_ALLOWED_FILENAME", saved_allowed);
        CPLFree(saved_allowed);
    }
    if (st != SS_OK)
        ss_dem_free(dem);
    return st;
}

void ss_dem_free(ss_dem *dem)
{
    ss_grid_free(&dem->grid);
    free(dem->crs_wkt);
    dem->crs_wkt = NULL;
}
