/* Reads a DEM through GDAL: one file, or several tiles on one grid mosaicked
 * as they are read, each tile with its own data type, nodata, scale and
 * unit. Heights become float32 relative to a local origin, nodata (tagged
 * value, NaN, Inf, absurd heights) becomes NAN. */
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
#include "band_values.h"
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
    const char *path;
    GDALDatasetH ds;
    double gt[6];
    int width, height;
    int col0, row0; /* its first cell on the mosaic's grid */
    GDALRasterBandH band;
    ss_band_values values;
    double scale, offset; /* metres = stored value * scale + offset */
    double step_m;        /* metres between the values an integer band holds; 0: floating */
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
                               GDALRasterBandH band, const ss_dem_read_options *opt,
                               double *metres_per_unit, char *source, size_t source_size)
{
    const char *unit = GDALGetRasterUnitType(band);
    OGRSpatialReferenceH srs = GDALGetSpatialRef(ds);
    if (opt && opt->z_unit_m > 0) {
        *metres_per_unit = opt->z_unit_m;
        snprintf(source, source_size, "%.10g m (given by --z-units)", opt->z_unit_m);
        return SS_OK;
    }
    if (unit && *unit) {
        /* The whole name, else its first word ("m a.s.l.", "m (EGM96)"). */
        char word[32];
        snprintf(word, sizeof word, "%.*s", (int)strcspn(unit, " (,"), unit);
        *metres_per_unit = metres_per_unit_named(unit);
        if (!(*metres_per_unit > 0))
            *metres_per_unit = metres_per_unit_named(word);
        if (!(*metres_per_unit > 0))
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                           "'%s': the band's unit '%s' is not a unit of height skysweep knows: "
                           "give it with --z-units m|ft|us-ft",
                           path, unit);
        snprintf(source, source_size, "%.10g m (the band's unit type '%s')", *metres_per_unit,
                 unit);
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
        *metres_per_unit = metres;
        snprintf(source, source_size, "%.10g m (the CRS's vertical unit '%s')", metres,
                 name ? name : "?");
        return SS_OK;
    }
    *metres_per_unit = 1.0;
    int feet = srs && OSRIsProjected(srs) && fabs(OSRGetLinearUnits(srs, NULL) - 0.3048) < 1e-3;
    snprintf(source, source_size, "%s",
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
        tiles[i].path = paths[i];
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
    ss_overlap_rule overlap;   /* which height a cell covered by several tiles takes */
    int have_origin;           /* z_origin_m is set (from the first plausible height) */
    int fenced;                /* 1: network fenced, 2: and the fetch callback pushed */
    char *saved_allowed;
    char what[512];            /* the first path, for messages */
};

/* Reads rows [row0, row0 + n_rows) and columns [col0, col0 + n_cols) of a
 * tile as metres into dst (lines line_cells apart), NAN for nodata. */
static ss_status read_tile_window(ss_ctx *ctx, const tile *t, int col0, int row0, int n_cols,
                                  int n_rows, double *dst, int line_cells)
{
    CPLErrorReset();
    if (GDALRasterIO(t->band, GF_Read, col0, row0, n_cols, n_rows, dst, n_cols, n_rows,
                     GDT_Float64, 0, (GSpacing)line_cells * (GSpacing)sizeof *dst) != CE_None)
        return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot read rows %d..%d of '%s': %s", row0,
                            row0 + n_rows - 1, t->path, ss_gdal_message());
    for (int r = 0; r < n_rows; ++r)
        for (int c = 0; c < n_cols; ++c) {
            double *v = &dst[(size_t)r * line_cells + c];
            *v = ss_band_value(&t->values, *v) * t->scale + t->offset;
        }
    return SS_OK;
}

/* Puts a tile's heights (NAN: none) into the mosaic's under the overlap
 * rule; counts[] counts the heights a cell got, for the mean. */
static void merge_heights(ss_overlap_rule rule, double *mosaic, int *counts, const double *heights,
                          int n)
{
    for (int i = 0; i < n; ++i) {
        double v = heights[i];
        if (isnan(v))
            continue;
        if (rule == SS_OVERLAP_LAST || isnan(mosaic[i]))
            mosaic[i] = v;
        else if (rule == SS_OVERLAP_MEAN)
            mosaic[i] += v;
        if (counts)
            counts[i]++;
    }
}

/* The mosaic's rows [row0, row0 + n_rows) in metres, NAN where no tile has
 * a height: tile after tile (in the order given) through scratch, cells no
 * tile covers left NAN; counts is NULL but for the mean. */
static ss_status mosaic_rows(ss_ctx *ctx, const ss_dem_source *src, int width, int row0,
                             int n_rows, double *mosaic, double *scratch, int *counts)
{
    size_t n = (size_t)width * (size_t)n_rows;
    for (size_t i = 0; i < n; ++i)
        mosaic[i] = NAN;
    if (counts)
        memset(counts, 0, n * sizeof *counts);
    for (int k = 0; k < src->n_tiles; ++k) {
        const tile *t = &src->tiles[k];
        int r0 = row0 > t->row0 ? row0 : t->row0;
        int r1 = row0 + n_rows < t->row0 + t->height ? row0 + n_rows : t->row0 + t->height;
        if (r0 >= r1)
            continue;
        size_t at = (size_t)(r0 - row0) * width + (size_t)t->col0;
        ss_status st = read_tile_window(ctx, t, 0, r0 - t->row0, t->width, r1 - r0,
                                        scratch + at, width);
        if (st != SS_OK)
            return st;
        for (int r = 0; r < r1 - r0; ++r) {
            size_t line = at + (size_t)r * width;
            merge_heights(src->overlap, mosaic + line, counts ? counts + line : NULL,
                          scratch + line, t->width);
        }
    }
    for (size_t i = 0; counts && i < n; ++i)
        if (counts[i] > 1)
            mosaic[i] /= counts[i];
    return SS_OK;
}

/* Reads rows [row0, row0 + n_rows) as they are; the first plausible
 * height read sets the origin if none is set. */
static ss_status read_rows(ss_ctx *ctx, ss_dem_source *src, ss_dem *dem, int row0, int n_rows,
                           float *z)
{
    ss_grid *g = &dem->grid;
    const int rows_per_chunk = n_rows < 256 ? n_rows : 256;
    size_t chunk = (size_t)g->width * rows_per_chunk;
    int one = src->n_tiles == 1;
    double *buf = malloc(sizeof(double) * chunk);
    double *scratch = one ? NULL : malloc(sizeof(double) * chunk);
    int *counts = src->overlap == SS_OVERLAP_MEAN && !one ? malloc(sizeof(int) * chunk) : NULL;
    ss_status st = SS_OK;
    if (!buf || (!one && !scratch) || (src->overlap == SS_OVERLAP_MEAN && !one && !counts))
        st = ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory reading '%s'", src->what);
    size_t nodata = 0, rejected = 0;
    for (int r0 = row0; st == SS_OK && r0 < row0 + n_rows; r0 += rows_per_chunk) {
        int rows = row0 + n_rows - r0 < rows_per_chunk ? row0 + n_rows - r0 : rows_per_chunk;
        /* One file is the mosaic: read straight into it. */
        st = one ? read_tile_window(ctx, &src->tiles[0], 0, r0, g->width, rows, buf, g->width)
                 : mosaic_rows(ctx, src, g->width, r0, rows, buf, scratch, counts);
        for (size_t i = 0; st == SS_OK && i < (size_t)g->width * rows; ++i) {
            float *dst = &z[(size_t)(r0 - row0) * g->width + i];
            if (isnan(buf[i])) {
                *dst = NAN;
                nodata++;
                continue;
            }
            *dst = ss_grid_stored_height(g, &src->have_origin, buf[i]);
            rejected += isnan(*dst);
        }
    }
    free(buf);
    free(scratch);
    free(counts);
    dem->nodata_cells += nodata;
    dem->rejected_cells += rejected;
    return st;
}

/* The mosaic's grid: the box around the tiles on the first tile's cells
 * (check_tiles has put them all on that grid), and each tile's place. */
static void place_tiles(tile *tiles, int n, ss_dem *dem)
{
    double left = tiles[0].gt[0], top = tiles[0].gt[3];
    for (int i = 1; i < n; ++i) {
        left = fmin(left, tiles[i].gt[0]);
        top = fmax(top, tiles[i].gt[3]);
    }
    double gt[6] = {left, tiles[0].gt[1], 0, top, 0, tiles[0].gt[5]};
    memcpy(dem->geotransform, gt, sizeof gt);
    dem->grid.width = dem->grid.height = 0;
    for (int i = 0; i < n; ++i) {
        tiles[i].col0 = (int)nearbyint((tiles[i].gt[0] - left) / gt[1]);
        tiles[i].row0 = (int)nearbyint((tiles[i].gt[3] - top) / gt[5]);
        if (tiles[i].col0 + tiles[i].width > dem->grid.width)
            dem->grid.width = tiles[i].col0 + tiles[i].width;
        if (tiles[i].row0 + tiles[i].height > dem->grid.height)
            dem->grid.height = tiles[i].row0 + tiles[i].height;
    }
}

/* How each tile's stored values become metres: its own data type, nodata,
 * scale, offset and unit. The DEM's unit is the first tile's, or NAN with
 * a note where tiles differ. */
static ss_status tiles_heights(ss_ctx *ctx, tile *tiles, int n, const ss_dem_read_options *opt,
                               ss_dem *dem)
{
    int mixed = 0;
    for (int i = 0; i < n; ++i) {
        tile *t = &tiles[i];
        t->band = GDALGetRasterBand(t->ds, 1);
        ss_status st = ss_band_values_of(ctx, t->path, t->band, &t->values);
        double unit_m = 0;
        char unit_source[sizeof dem->z_unit_source];
        if (st == SS_OK)
            st = vertical_unit(ctx, t->path, t->ds, t->band, opt, &unit_m, unit_source,
                               sizeof unit_source);
        if (st != SS_OK)
            return st;
        int has_scale = 0, has_offset = 0;
        double scale = GDALGetRasterScale(t->band, &has_scale);
        double offset = GDALGetRasterOffset(t->band, &has_offset);
        t->scale = (has_scale ? scale : 1.0) * unit_m;
        t->offset = (has_offset ? offset : 0.0) * unit_m;
        t->step_m = GDALDataTypeIsFloating(GDALGetRasterDataType(t->band)) ? 0.0 : fabs(t->scale);
        if (i == 0) {
            dem->z_unit_m = unit_m;
            memcpy(dem->z_unit_source, unit_source, sizeof unit_source);
        }
        mixed |= unit_m != dem->z_unit_m;
    }
    if (mixed) {
        char first[sizeof dem->z_unit_source];
        memcpy(first, dem->z_unit_source, sizeof first);
        dem->z_unit_m = NAN;
        snprintf(dem->z_unit_source, sizeof dem->z_unit_source,
                 "each tile's own (the tiles differ; the first's: %.150s)", first);
    }
    return SS_OK;
}

/* Where two tiles' heights may differ and still agree: a centimetre, or
 * half a step of the coarser integer band (an Int16 copy of a Float32
 * tile rounds each height by up to half a metre). */
static double agreement_m(const tile *a, const tile *b)
{
    return fmax(0.01, 0.5 * fmax(a->step_m, b->step_m));
}

/* Counts the cells where both tiles have heights (shared) and where those
 * differ by more than agreement_m (differ, by up to worst metres). */
static ss_status compare_overlap(ss_ctx *ctx, const tile *a, const tile *b, size_t *shared,
                                 size_t *differ, double *worst)
{
    int c0 = a->col0 > b->col0 ? a->col0 : b->col0;
    int r0 = a->row0 > b->row0 ? a->row0 : b->row0;
    int c1 = a->col0 + a->width < b->col0 + b->width ? a->col0 + a->width : b->col0 + b->width;
    int r1 = a->row0 + a->height < b->row0 + b->height ? a->row0 + a->height
                                                       : b->row0 + b->height;
    if (c0 >= c1 || r0 >= r1)
        return SS_OK;
    int cols = c1 - c0;
    int chunk = (1 << 20) / cols > 1 ? (1 << 20) / cols : 1;
    double *va = malloc(sizeof(double) * (size_t)cols * (size_t)chunk);
    double *vb = malloc(sizeof(double) * (size_t)cols * (size_t)chunk);
    ss_status st = va && vb ? SS_OK
                            : ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory comparing tiles");
    double agree = agreement_m(a, b);
    for (int r = r0; st == SS_OK && r < r1; r += chunk) {
        int rows = r1 - r < chunk ? r1 - r : chunk;
        st = read_tile_window(ctx, a, c0 - a->col0, r - a->row0, cols, rows, va, cols);
        if (st == SS_OK)
            st = read_tile_window(ctx, b, c0 - b->col0, r - b->row0, cols, rows, vb, cols);
        for (size_t i = 0; st == SS_OK && i < (size_t)cols * (size_t)rows; ++i) {
            if (isnan(va[i]) || isnan(vb[i]))
                continue;
            double d = fabs(va[i] - vb[i]);
            (*shared)++;
            *differ += d > agree;
            *worst = fmax(*worst, d);
        }
    }
    free(va);
    free(vb);
    return st;
}

/* Overlapping tiles must agree, unless the overlap rule decides between
 * them: then the cells they disagree on are counted (once per pair). */
static ss_status check_overlaps(ss_ctx *ctx, const ss_dem_source *src, ss_dem *dem)
{
    for (int i = 0; i < src->n_tiles; ++i)
        for (int j = i + 1; j < src->n_tiles; ++j) {
            size_t shared = 0, differ = 0;
            double worst = 0;
            ss_status st = compare_overlap(ctx, &src->tiles[i], &src->tiles[j], &shared, &differ,
                                           &worst);
            if (st != SS_OK)
                return st;
            if (differ && src->overlap == SS_OVERLAP_REFUSE)
                return ss_ctx_error(ctx, SS_ERR_INPUT,
                                    "tiles '%s' and '%s' overlap and disagree on %zu of the %zu "
                                    "cells where both have heights (by up to %.3g m): give "
                                    "--overlap first|last|mean to decide",
                                    src->tiles[i].path, src->tiles[j].path, differ, shared,
                                    worst);
            dem->overlap_cells += differ;
            dem->overlap_rule = src->overlap;
        }
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
    if (st == SS_OK)
        place_tiles(src->tiles, n_paths, dem);
    double cx = 0, cy = 0;
    if (st == SS_OK) {
        if (!georeferenced) {
            double identity[6] = {0, 1, 0, 0, 0, -1};
            memcpy(dem->geotransform, identity, sizeof identity);
        }
        st = cell_size_metres(ctx, paths[0], src->tiles[0].ds, dem->geotransform, opt,
                              georeferenced, &cx, &cy, &dem->crs_wkt);
    }
    if (st == SS_OK) {
        dem->grid.cell_x_m = cx;
        dem->grid.cell_y_m = cy;
        src->overlap = opt ? opt->overlap : SS_OVERLAP_REFUSE;
        st = tiles_heights(ctx, src->tiles, n_paths, opt, dem);
    }
    if (st == SS_OK && n_paths > 1)
        st = check_overlaps(ctx, src, dem);
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
