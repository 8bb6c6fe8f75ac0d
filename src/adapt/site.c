/* Sites by coordinates through OGR (see site.h). */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cpl_error.h>
#include <ogr_srs_api.h>

#include "skysweep.h"
#include "gdal_errors.h"
#include "site.h"

struct ss_site_frame {
    ss_ctx *ctx;
    const ss_dem *dem;
    OGRSpatialReferenceH dem_srs, site_srs, wgs84;
    OGRCoordinateTransformationH to_dem; /* NULL when sites are in the DEM's CRS */
    OGRCoordinateTransformationH to_wgs84;
    char site_crs_name[64];
};

static OGRSpatialReferenceH srs_from(const char *text)
{
    OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
    if (srs && OSRSetFromUserInput(srs, text) != OGRERR_NONE) {
        OSRDestroySpatialReference(srs);
        return NULL;
    }
    if (srs)
        OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
    return srs;
}

void ss_site_frame_close(ss_site_frame *sf)
{
    if (!sf)
        return;
    if (sf->to_dem)
        OCTDestroyCoordinateTransformation(sf->to_dem);
    if (sf->to_wgs84)
        OCTDestroyCoordinateTransformation(sf->to_wgs84);
    if (sf->site_srs && sf->site_srs != sf->dem_srs)
        OSRDestroySpatialReference(sf->site_srs);
    if (sf->dem_srs)
        OSRDestroySpatialReference(sf->dem_srs);
    if (sf->wgs84)
        OSRDestroySpatialReference(sf->wgs84);
    free(sf);
}

ss_status ss_site_frame_open(ss_ctx *ctx, const ss_dem *dem, const char *site_crs,
                             ss_site_frame **out)
{
    *out = NULL;
    if (!dem->crs_wkt)
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                       "'%s' has no coordinate reference system: sites cannot be placed on it",
                       dem->description);
    ss_site_frame *sf = calloc(1, sizeof *sf);
    if (!sf)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory placing sites");
    sf->ctx = ctx;
    sf->dem = dem;
    int in_dem_crs = site_crs && strcmp(site_crs, "dem") == 0;
    const char *site_text = site_crs && *site_crs && !in_dem_crs ? site_crs : "EPSG:4326";
    snprintf(sf->site_crs_name, sizeof sf->site_crs_name, "%s",
             in_dem_crs ? "the DEM's CRS" : site_text);
    ss_status st = SS_OK;
    /* GDAL's errors come back in the status message, not on stderr. */
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
    sf->dem_srs = srs_from(dem->crs_wkt);
    sf->wgs84 = srs_from("EPSG:4326");
    if (!sf->dem_srs || !sf->wgs84)
        st = ss_ctx_error(ctx, SS_ERR_INPUT, "cannot read the DEM's CRS or WGS84: %s", ss_gdal_message());
    if (st == SS_OK && !in_dem_crs) {
        sf->site_srs = srs_from(site_text);
        if (!sf->site_srs)
            st = ss_ctx_error(ctx, SS_ERR_ARGUMENT, "unknown CRS for sites '%s': %s", site_text,
                         ss_gdal_message());
    } else if (st == SS_OK) {
        sf->site_srs = sf->dem_srs;
    }
    if (st == SS_OK && !in_dem_crs) {
        sf->to_dem = OCTNewCoordinateTransformation(sf->site_srs, sf->dem_srs);
        if (!sf->to_dem)
            st = ss_ctx_error(ctx, SS_ERR_ARGUMENT, "no transformation from %s to the DEM's CRS: %s",
                         site_text, ss_gdal_message());
    }
    if (st == SS_OK) {
        sf->to_wgs84 = OCTNewCoordinateTransformation(sf->dem_srs, sf->wgs84);
        if (!sf->to_wgs84)
            st = ss_ctx_error(ctx, SS_ERR_INPUT, "no transformation from the DEM's CRS to WGS84: %s",
                         ss_gdal_message());
    }
    CPLPopErrorHandler();
    if (st != SS_OK) {
        ss_site_frame_close(sf);
        return st;
    }
    *out = sf;
    return SS_OK;
}

void ss_site_dem_xy(const ss_site_frame *sf, double col, double row, double *x, double *y)
{
    const double *gt = sf->dem->geotransform; /* north-up: the reader refuses rotations */
    *x = gt[0] + (col + 0.5) * gt[1];
    *y = gt[3] + (row + 0.5) * gt[5];
}

ss_status ss_site_locate(ss_site_frame *sf, double x, double y, double *col, double *row)
{
    double dx = x, dy = y;
    if (!isfinite(x) || !isfinite(y))
        return ss_ctx_error(sf->ctx, SS_ERR_ARGUMENT, "site %g,%g: coordinates must be finite", x, y);
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
    int moved = !sf->to_dem || OCTTransform(sf->to_dem, 1, &dx, &dy, NULL);
    CPLPopErrorHandler();
    if (!moved)
        return ss_ctx_error(sf->ctx, SS_ERR_ARGUMENT,
                       "site %.9g,%.9g (%s) cannot be placed in the "
                       "DEM's CRS: %s",
                       x, y, sf->site_crs_name, ss_gdal_message());
    const ss_grid *g = &sf->dem->grid;
    const double *gt = sf->dem->geotransform;
    *col = (dx - gt[0]) / gt[1] - 0.5;
    *row = (dy - gt[3]) / gt[5] - 0.5;
    if (!(*col >= -0.5 && *col <= g->width - 0.5 && *row >= -0.5 && *row <= g->height - 0.5)) {
        double x0 = gt[0], x1 = gt[0] + g->width * gt[1];
        double y1 = gt[3], y0 = gt[3] + g->height * gt[5];
        return ss_ctx_error(sf->ctx, SS_ERR_ARGUMENT,
                       "site %.9g,%.9g (%s) lies outside the DEM: it is at x %.3f, y %.3f in "
                       "the DEM's CRS, which covers x %.3f to %.3f, y %.3f to %.3f",
                       x, y, sf->site_crs_name, dx, dy, x0, x1, y0, y1);
    }
    int c = (int)floor(*col + 0.5), r = (int)floor(*row + 0.5);
    c = c < g->width ? c : g->width - 1;
    r = r < g->height ? r : g->height - 1;
    if (!isfinite(g->z[(size_t)r * g->width + c]))
        return ss_ctx_error(sf->ctx, SS_ERR_ARGUMENT,
                       "site %.9g,%.9g (%s) lies on a nodata cell of the DEM (column %d, row %d)",
                       x, y, sf->site_crs_name, c, r);
    return SS_OK;
}

ss_status ss_site_lonlat(ss_site_frame *sf, int n, const double *col, const double *row,
                         double *lon_deg, double *lat_deg)
{
    /* Positions first (NAN passes through), then only finite ones go to
     * OGR, in place and in one call: PROJ's cost is mostly per call. */
    int m = 0;
    for (int i = 0; i < n; ++i) {
        ss_site_dem_xy(sf, col[i], row[i], &lon_deg[i], &lat_deg[i]);
        if (isfinite(lon_deg[i]) && isfinite(lat_deg[i])) {
            lon_deg[m] = lon_deg[i];
            lat_deg[m] = lat_deg[i];
            m++;
        }
    }
    CPLPushErrorHandler(CPLQuietErrorHandler);
    CPLErrorReset();
    int moved = m == 0 || OCTTransform(sf->to_wgs84, m, lon_deg, lat_deg, NULL);
    CPLPopErrorHandler();
    if (!moved)
        return ss_ctx_error(sf->ctx, SS_ERR_INPUT,
                       "positions on the DEM have no WGS84 longitude, latitude: %s", ss_gdal_message());
    /* Spread the results back to their slots, from the end. */
    for (int i = n - 1; i >= 0; --i) {
        if (isfinite(col[i]) && isfinite(row[i])) {
            m--;
            lon_deg[i] = lon_deg[m];
            lat_deg[i] = lat_deg[m];
        } else {
            lon_deg[i] = lat_deg[i] = NAN;
        }
    }
    return SS_OK;
}
