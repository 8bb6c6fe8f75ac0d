/* Sites given by coordinates (GDAL/OGR adapter): from WGS84 longitude and
 * latitude, or any CRS GDAL reads, or the DEM's own CRS, to the DEM's
 * cell-centre position (geodesy.h's convention: the centre of cell (c, r)
 * is col = c, row = r), and from a cell-centre position back to WGS84
 * longitude and latitude for reporting. Axis order is always x = easting
 * or longitude, y = northing or latitude (GDAL's traditional GIS order). */
#ifndef SS_SITE_H
#define SS_SITE_H

#include "dem_io.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ss_site_frame ss_site_frame;

/* site_crs: NULL or "" for WGS84 longitude, latitude; "dem" for the DEM's
 * own CRS (its geotransform's x, y); else anything OSRSetFromUserInput
 * reads ("EPSG:32605", WKT, a PROJ string). The DEM must be georeferenced
 * and must outlive the frame. */
ss_status ss_site_frame_open(ss_ctx *ctx, const ss_dem *dem, const char *site_crs,
                             ss_site_frame **out);
void ss_site_frame_close(ss_site_frame *sf);

/* Cell-centre position of the site (x, y) in the site CRS. Refuses, with
 * the coordinates in the message, a site outside the DEM's outer edges and
 * one whose cell (the one whose square holds it) is nodata. */
ss_status ss_site_locate(ss_site_frame *sf, double x, double y, double *col, double *row);

/* WGS84 longitude and latitude (degrees) of n cell-centre positions, in
 * one transformation; a NAN position gives NAN. */
ss_status ss_site_lonlat(ss_site_frame *sf, int n, const double *col, const double *row,
                         double *lon_deg, double *lat_deg);

/* The position in the DEM's CRS (its geotransform's x, y). */
void ss_site_dem_xy(const ss_site_frame *sf, double col, double row, double *x, double *y);

#ifdef __cplusplus
}
#endif
#endif
