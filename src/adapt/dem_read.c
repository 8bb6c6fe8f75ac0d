/* Reads a DEM through GDAL: one file, or several tiles on one grid mosaicked
 * by an in-memory VRT. Heights become float32 relative to a local origin,
 * nodata (tagged value, NaN, Inf, absurd heights) becomes NAN. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

#include <cpl_conv.h>
#include <cpl_error.h>
#include <cpl_http.h>
#include <gdal.h>
#include <gdal_utils.h>
#include <ogr_srs_api.h>

#include "skysweep.h"
#include "dem_io.h"
#include "gdal_errors.h"

void ss_gdal_init(void)
{
    if (GDALGetDriverCount() == 0) {
        ss_gdal_errors_install();
        GDALAllRegister();
    }
}

const char *ss_gdal_version(void)
{
    return GDALVersionInfo("RELEASE_NAME");
}

int ss_gdal_term_progress(double complete)
{
    return GDALTermProgress(complete, NULL, NULL);
}

void ss_gdal_limit_cache(size_t bytes)
{
    GDALSetCacheMax64((GIntBig)bytes);
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
            return ss_ctx_error(ctx, SS_ERR_INPUT, "tiles '%s' and '%s' have different CRSs",
                           paths[0], paths[i]);
        for (int k = 1; k <= 5; k += 4)
            if (fabs(tiles[i].gt[k] - tiles[0].gt[k]) > 1e-9 * fabs(tiles[0].gt[k]))
                return ss_ctx_error(ctx, SS_ERR_INPUT,
                               "tiles '%s' and '%s' have different cell sizes", paths[0],
                               paths[i]);
        double off_x = (tiles[i].gt[0] - tiles[0].gt[0]) / tiles[0].gt[1];
        double off_y = (tiles[i].gt[3] - tiles[0].gt[3]) / tiles[0].gt[5];
        if (fabs(off_x - nearbyint(off_x)) > 1e-3 || fabs(off_y - nearbyint(off_y)) > 1e-3)
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                           "tile '%s' is not aligned on the grid of '%s' (origins differ by a "
                           "fraction of a cell)",
                           paths[i], paths[0]);
    }
    /* Connectivity: grow a set from tile 0 through tiles whose cell
     * rectangles overlap or share an edge. */
    int *reached = calloc((size_t)n, sizeof *reached);
    if (!reached)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory checking tiles");
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
        return ss_ctx_error(ctx, SS_ERR_INPUT,
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
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                       "'%s' has no %s: it is not a georeferenced DEM (for a plain heightmap, "
                       "give its cell size with --cell-size METRES)",
                       path, georeferenced ? "coordinate reference system" : "georeferencing");
    }
    if (opt && opt->heightmap_cell_m > 0)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                            "--cell-size is for inputs without georeferencing, and '%s' has its "
                            "own: leave it out",
                            path);
    if (OSRIsGeographic(srs)) {
        /* Degrees: the ground size comes from geodesy (src/adapt/frame.c). */
        *cx = *cy = NAN;
    } else if (OSRIsProjected(srs) || OSRIsLocal(srs)) {
        double unit = OSRGetLinearUnits(srs, NULL);
        if (!(unit > 0))
            return ss_ctx_error(ctx, SS_ERR_INPUT, "'%s': the CRS has no usable linear unit", path);
        *cx = fabs(gt[1]) * unit;
        *cy = fabs(gt[5]) * unit;
    } else {
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                       "'%s': unsupported kind of CRS (neither projected nor geographic)", path);
    }
    char *w = NULL;
    if (OSRExportToWkt(srs, &w) == OGRERR_NONE)
        *wkt = strdup(w);
    CPLFree(w);
    return SS_OK;
}

/* Metres per unit for a band unit type as GDAL drivers and users write
 * it; 0 for a name not known. "" is no unit given. */
static double metres_per_unit_named(const char *unit)
{
    static const struct {
        const char *name;
        double metres;
    } units[] = {{"m", 1.0},           {"metre", 1.0},          {"meter", 1.0},
                 {"metres", 1.0},      {"meters", 1.0},         {"ft", 0.3048},
                 {"foot", 0.3048},     {"feet", 0.3048},        {"international foot", 0.3048},
                 {"ftUS", 1200.0 / 3937.0}, {"us-ft", 1200.0 / 3937.0},
                 {"US survey foot", 1200.0 / 3937.0}, {"US_survey_foot", 1200.0 / 3937.0},
                 {"foot_us", 1200.0 / 3937.0}, {"us survey feet", 1200.0 / 3937.0},
                 {"cm", 0.01},         {"centimetre", 0.01},    {"centimeter", 0.01},
                 {"mm", 0.001},        {"millimetre", 0.001},   {"millimeter", 0.001}};
    for (size_t i = 0; i < sizeof units / sizeof units[0]; ++i)
        if (strcasecmp(unit, units[i].name) == 0)
            return units[i].metres;
    return 0.0;
}

/* The stored heights' unit: --z-units, else the band's unit type, else the
 * CRS's vertical axis, else metres (said so, and flagged where the CRS's
 * horizontal unit is feet, as in US county lidar). */
static ss_status vertical_unit(ss_ctx *ctx, const char *path, GDALDatasetH ds,
                               GDALRasterBandH band, const ss_dem_read_options *opt, ss_dem *dem)
{
    const char *unit = GDALGetRasterUnitType(band);
    OGRSpatialReferenceH srs = GDALGetSpatialRef(ds);
    if (opt && opt->z_unit_m > 0) {
        dem->z_unit_m = opt->z_unit_m;
        snprintf(dem->z_unit_source, sizeof dem->z_unit_source, "%.10g m (given by --z-units)",
                 opt->z_unit_m);
        return SS_OK;
    }
    if (unit && *unit) {
        /* The whole name, else its first word ("m a.s.l.", "m (EGM96)"). */
        char word[32];
        snprintf(word, sizeof word, "%.*s", (int)strcspn(unit, " (,"), unit);
        dem->z_unit_m = metres_per_unit_named(unit);
        if (!(dem->z_unit_m > 0))
            dem->z_unit_m = metres_per_unit_named(word);
        if (!(dem->z_unit_m > 0))
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                           "'%s': the band's unit '%s' is not a unit of height skysweep knows: "
                           "give it with --z-units m|ft|us-ft",
                           path, unit);
        snprintf(dem->z_unit_source, sizeof dem->z_unit_source,
                 "%.10g m (the band's unit type '%s')", dem->z_unit_m, unit);
        return SS_OK;
    }
    if (srs && (OSRIsCompound(srs) || OSRIsVertical(srs))) {
        char *name = NULL;
        double metres = OSRGetTargetLinearUnits(srs, "VERT_CS", &name);
        if (!(metres > 0))
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                           "'%s': the CRS's vertical axis has no usable unit: give it with "
                           "--z-units m|ft|us-ft",
                           path);
        dem->z_unit_m = metres;
        snprintf(dem->z_unit_source, sizeof dem->z_unit_source,
                 "%.10g m (the CRS's vertical unit '%s')", metres, name ? name : "?");
        return SS_OK;
    }
    dem->z_unit_m = 1.0;
    int feet = srs && OSRIsProjected(srs) && fabs(OSRGetLinearUnits(srs, NULL) - 0.3048) < 1e-3;
    snprintf(dem->z_unit_source, sizeof dem->z_unit_source, "%s",
             feet ? "1 m (assumed: neither the band nor the CRS names one, although the CRS's "
                    "horizontal unit is feet; give --z-units ft or us-ft if the heights are too)"
                  : "1 m (assumed: neither the band nor the CRS names one)");
    return SS_OK;
}

static ss_status open_tiles(ss_ctx *ctx, const char *const *paths, int n, tile *tiles,
                            int *georeferenced)
{
    *georeferenced = 1;
    for (int i = 0; i < n; ++i) {
        if (access(paths[i], F_OK) != 0 && strncmp(paths[i], "/vsi", 4) != 0)
            return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot open '%s': no such file", paths[i]);
        CPLErrorReset();
        tiles[i].ds = GDALOpenEx(paths[i], GDAL_OF_RASTER | GDAL_OF_READONLY, NULL, NULL, NULL);
        if (!tiles[i].ds)
            return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot read '%s' as a raster: %s", paths[i],
                           ss_gdal_message());
        tiles[i].width = GDALGetRasterXSize(tiles[i].ds);
        tiles[i].height = GDALGetRasterYSize(tiles[i].ds);
        int bands = GDALGetRasterCount(tiles[i].ds);
        if (bands != 1)
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                           "'%s' has %d bands: a DEM has exactly one (height)", paths[i], bands);
        if (GDALGetGeoTransform(tiles[i].ds, tiles[i].gt) != CE_None) {
            *georeferenced = 0;
            double identity[6] = {0, 1, 0, 0, 0, -1};
            memcpy(tiles[i].gt, identity, sizeof identity);
        }
        const double *gt = tiles[i].gt;
        if (gt[2] != 0.0 || gt[4] != 0.0)
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                           "'%s' has a rotated geotransform, which is not supported: warp it "
                           "north-up first (gdalwarp)",
                           paths[i]);
        if (!(gt[1] > 0.0) || !(gt[5] < 0.0) || !isfinite(gt[0]) || !isfinite(gt[3]))
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                           "'%s' is not a north-up grid (pixel size %g x %g): warp it north-up "
                           "first (gdalwarp)",
                           paths[i], gt[1], gt[5]);
    }
    return SS_OK;
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

/* An opened DEM whose heights are read on demand (dem_io.h). */
struct ss_dem_source {
    tile *tiles;
    int n_tiles;
    GDALDatasetH mosaic;       /* VRT of the tiles, or NULL for one file */
    GDALRasterBandH band;
    int has_nodata;
    double nodata, scale, offset;
    int have_origin;           /* z_origin_m is set (from the first plausible height) */
    int fenced;                /* 1: network fenced, 2: and the fetch callback pushed */
    char *saved_allowed;
    char what[512];            /* the first path, for messages */
};

/* Mosaic cells covered by no tile are nodata, whatever the VRT filled in. */
static void mark_uncovered(const ss_dem_source *src, const ss_dem *dem, int row0, int n_rows,
                           float *z, size_t *nodata_cells)
{
    int w = dem->grid.width;
    unsigned char *covered = calloc((size_t)w, 1);
    if (!covered)
        return;
    for (int r = row0; r < row0 + n_rows; ++r) {
        memset(covered, 0, (size_t)w);
        for (int i = 0; i < src->n_tiles; ++i) {
            const tile *t = &src->tiles[i];
            int c0 = (int)nearbyint((t->gt[0] - dem->geotransform[0]) / dem->geotransform[1]);
            int r0 = (int)nearbyint((t->gt[3] - dem->geotransform[3]) / dem->geotransform[5]);
            if (r < r0 || r >= r0 + t->height)
                continue;
            for (int c = c0 < 0 ? 0 : c0; c < c0 + t->width && c < w; ++c)
                covered[c] = 1;
        }
        float *row = z + (size_t)(r - row0) * w;
        for (int c = 0; c < w; ++c)
            if (!covered[c] && isfinite(row[c])) {
                row[c] = NAN;
                (*nodata_cells)++;
            }
    }
    free(covered);
}

/* Reads rows [row0, row0 + n_rows) as they are; the first plausible
 * height read sets the origin if none is set. */
static ss_status read_rows(ss_ctx *ctx, ss_dem_source *src, ss_dem *dem, int row0, int n_rows,
                           float *z)
{
    ss_grid *g = &dem->grid;
    const int rows_per_chunk = n_rows < 256 ? n_rows : 256;
    double *buf = malloc(sizeof(double) * (size_t)g->width * rows_per_chunk);
    if (!buf)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory reading '%s'", src->what);
    size_t nodata = 0, rejected = 0;
    for (int r0 = row0; r0 < row0 + n_rows; r0 += rows_per_chunk) {
        int rows = row0 + n_rows - r0 < rows_per_chunk ? row0 + n_rows - r0 : rows_per_chunk;
        CPLErrorReset();
        if (GDALRasterIO(src->band, GF_Read, 0, r0, g->width, rows, buf, g->width, rows,
                         GDT_Float64, 0, 0) != CE_None) {
            free(buf);
            return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot read rows %d..%d of '%s': %s", r0,
                           r0 + rows - 1, src->what, ss_gdal_message());
        }
        for (size_t i = 0; i < (size_t)g->width * rows; ++i) {
            double v = buf[i];
            float *dst = &z[(size_t)(r0 - row0) * g->width + i];
            if (!isfinite(v) || (src->has_nodata && v == src->nodata)) {
                *dst = NAN;
                nodata++;
                continue;
            }
            *dst = ss_grid_stored_height(g, &src->have_origin, v * src->scale + src->offset);
            rejected += isnan(*dst);
        }
    }
    free(buf);
    if (src->n_tiles > 1)
        mark_uncovered(src, dem, row0, n_rows, z, &nodata);
    dem->nodata_cells += nodata;
    dem->rejected_cells += rejected;
    return SS_OK;
}

/* Sets the origin from the first plausible height in rows before row0,
 * as a read of the whole grid from its first row would: the heights then
 * round the same whatever order bands read them in. One row at a time:
 * leading rows of nodata (an ocean) cost one read each. */
static ss_status find_origin(ss_ctx *ctx, ss_dem_source *src, ss_dem *dem, int row0)
{
    float *row = malloc(sizeof(float) * (size_t)dem->grid.width);
    if (!row)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory reading '%s'", src->what);
    size_t nodata = dem->nodata_cells, rejected = dem->rejected_cells;
    ss_status st = SS_OK;
    for (int r = 0; r < row0 && !src->have_origin && st == SS_OK; ++r)
        st = read_rows(ctx, src, dem, r, 1, row);
    dem->nodata_cells = nodata;
    dem->rejected_cells = rejected;
    free(row);
    return st;
}

ss_status ss_dem_source_read(ss_ctx *ctx, ss_dem_source *src, ss_dem *dem, int row0, int n_rows,
                             float *z)
{
    if (row0 < 0 || n_rows < 0 || row0 + n_rows > dem->grid.height)
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "rows %d..%d are outside '%s'", row0,
                       row0 + n_rows - 1, src->what);
    if (n_rows == 0)
        return SS_OK;
    if (!src->have_origin && row0 > 0) {
        ss_status st = find_origin(ctx, src, dem, row0);
        if (st != SS_OK)
            return st;
    }
    return read_rows(ctx, src, dem, row0, n_rows, z);
}

void ss_dem_source_close(ss_dem_source *src)
{
    if (!src)
        return;
    if (src->mosaic)
        GDALClose(src->mosaic);
    for (int i = 0; src->tiles && i < src->n_tiles; ++i)
        if (src->tiles[i].ds)
            GDALClose(src->tiles[i].ds);
    free(src->tiles);
    CPLPopErrorHandler();
    if (src->fenced) {
        if (src->fenced == 2)
            CPLHTTPPopFetchCallback();
        CPLSetThreadLocalConfigOption("CPL_VSIL_CURL_ALLOWED_FILENAME", src->saved_allowed);
        CPLFree(src->saved_allowed);
    }
    free(src);
}

ss_status ss_dem_open(ss_ctx *ctx, const char *const *paths, int n_paths,
                      const ss_dem_read_options *opt, ss_dem *dem, ss_dem_source **source)
{
    memset(dem, 0, sizeof *dem);
    *source = NULL;
    if (n_paths < 1)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "no input DEM given");
    ss_gdal_init();
    ss_dem_source *src = calloc(1, sizeof *src);
    if (!src)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
    snprintf(src->what, sizeof src->what, "%s", paths[0]);
    src->fenced = !names_network(paths, n_paths);
    if (src->fenced) {
        const char *a = CPLGetThreadLocalConfigOption("CPL_VSIL_CURL_ALLOWED_FILENAME", NULL);
        src->saved_allowed = a ? CPLStrdup(a) : NULL;
        CPLSetThreadLocalConfigOption("CPL_VSIL_CURL_ALLOWED_FILENAME", SS_CURL_FENCE);
        src->fenced = CPLHTTPPushFetchCallback(refuse_fetch, NULL) ? 2 : 1;
    }
    CPLPushErrorHandler(CPLQuietErrorHandler);
    src->tiles = calloc((size_t)n_paths, sizeof *src->tiles);
    src->n_tiles = n_paths;
    int georeferenced = 1;
    ss_status st = src->tiles ? open_tiles(ctx, paths, n_paths, src->tiles, &georeferenced)
                              : ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
    if (st == SS_OK && n_paths > 1)
        st = check_tiles(ctx, paths, src->tiles, n_paths);
    GDALDatasetH ds = src->tiles ? src->tiles[0].ds : NULL;
    if (st == SS_OK && n_paths > 1) {
        GDALDatasetH *handles = malloc(sizeof *handles * (size_t)n_paths);
        for (int i = 0; handles && i < n_paths; ++i)
            handles[i] = src->tiles[i].ds;
        int usage_error = 0;
        CPLErrorReset();
        src->mosaic = handles ? GDALBuildVRT("", n_paths, handles, NULL, NULL, &usage_error)
                              : NULL;
        free(handles);
        if (!src->mosaic)
            st = ss_ctx_error(ctx, SS_ERR_INPUT, "cannot mosaic the %d tiles: %s", n_paths,
                         ss_gdal_message());
        ds = src->mosaic;
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
        ss_grid *g = &dem->grid;
        g->width = GDALGetRasterXSize(ds);
        g->height = GDALGetRasterYSize(ds);
        g->cell_x_m = cx;
        g->cell_y_m = cy;
        src->band = GDALGetRasterBand(ds, 1);
        src->nodata = GDALGetRasterNoDataValue(src->band, &src->has_nodata);
        int has_scale = 0, has_offset = 0;
        src->scale = GDALGetRasterScale(src->band, &has_scale);
        src->offset = GDALGetRasterOffset(src->band, &has_offset);
        if (!has_scale)
            src->scale = 1.0;
        if (!has_offset)
            src->offset = 0.0;
        st = vertical_unit(ctx, paths[0], ds, src->band, opt, dem);
        src->scale *= dem->z_unit_m;
        src->offset *= dem->z_unit_m;
    }
    if (st == SS_OK) {
        snprintf(dem->description, sizeof dem->description, "%s%s",
                 n_paths > 1 ? "mosaic from " : "", paths[0]);
    }
    if (st != SS_OK) {
        ss_dem_source_close(src);
        ss_dem_free(dem);
        return st;
    }
    *source = src;
    return SS_OK;
}

ss_status ss_dem_read(ss_ctx *ctx, const char *const *paths, int n_paths,
                      const ss_dem_read_options *opt, ss_dem *dem)
{
    ss_dem_source *src;
    ss_status st = ss_dem_open(ctx, paths, n_paths, opt, dem, &src);
    if (st != SS_OK)
        return st;
    int w = dem->grid.width, h = dem->grid.height;
    double cx = dem->grid.cell_x_m, cy = dem->grid.cell_y_m;
    /* The most a whole-grid product holds: heights, hull stack, three
     * outputs and the weights of a horizon run with --distance and
     * --cast-height. */
    double bytes_needed = (double)w * (double)h * 24.0;
    double phys = (double)sysconf(_SC_PHYS_PAGES) * (double)sysconf(_SC_PAGESIZE);
    if (phys > 0 && bytes_needed > 0.8 * phys)
        st = ss_ctx_error(ctx, SS_ERR_MEMORY,
                     "'%s' has %d x %d cells: sweeping it whole needs about %.1f GB, more than "
                     "this machine's %.1f GB (svf, openness, horizon, shadow, insolation and "
                     "a plain hillshade take it in bands: --memory)",
                     paths[0], w, h, bytes_needed / 1e9, phys / 1e9);
    else if ((st = ss_grid_alloc(ctx, &dem->grid, w, h, cx, cy)) == SS_ERR_ARGUMENT)
        st = SS_ERR_INPUT; /* a size no sweep handles is the input's fault (exit 3) */
    if (st == SS_OK)
        st = ss_dem_source_read(ctx, src, dem, 0, h, dem->grid.z);
    ss_dem_source_close(src);
    if (st != SS_OK)
        ss_dem_free(dem);
    return st;
}

ss_status ss_dem_set_window(ss_ctx *ctx, ss_dem *dem, const double projwin[4])
{
    const double *gt = dem->geotransform;
    /* gdal_translate -projwin: offsets floored (with a 0.001-cell grace),
     * sizes rounded to the nearest cell. */
    double x = (projwin[0] - gt[0]) / gt[1], y = (projwin[1] - gt[3]) / gt[5];
    double cols = (projwin[2] - projwin[0]) / gt[1], rows = (projwin[3] - projwin[1]) / gt[5];
    double col0 = floor(x + 0.001), row0 = floor(y + 0.001);
    cols = floor(cols + 0.5);
    rows = floor(rows + 0.5);
    if (!(cols >= 1 && rows >= 1 && col0 >= 0 && row0 >= 0 &&
          col0 + cols <= dem->grid.width && row0 + rows <= dem->grid.height))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "-projwin %g %g %g %g is %s the DEM (columns %.0f..%.0f, rows %.0f..%.0f "
                       "of %d x %d)",
                       projwin[0], projwin[1], projwin[2], projwin[3],
                       cols >= 1 && rows >= 1 ? "not inside" : "empty or upside down for",
                       col0, col0 + cols - 1, row0, row0 + rows - 1, dem->grid.width,
                       dem->grid.height);
    dem->window_col0 = (int)col0;
    dem->window_row0 = (int)row0;
    dem->window_cols = (int)cols;
    dem->window_rows = (int)rows;
    return SS_OK;
}

void ss_dem_free(ss_dem *dem)
{
    ss_grid_free(&dem->grid);
    free(dem->crs_wkt);
    dem->crs_wkt = NULL;
}
