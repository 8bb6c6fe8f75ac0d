/* Per-cell sun positions (SPA once, rotated into each cell's frame on a
 * lattice) against a full SPA run at each cell's own latitude, longitude
 * and height: within 0.001 degrees (issue: "well under"), on a wide UTM grid
 * at Kilauea's latitude and one at Svalbard's, for suns high and low; and
 * each cell's refraction, interpolated between the lattice's nodes where
 * the sun is up, against the formula at the cell's own elevation: within
 * 1e-6 degrees and the floats' rounding, on 30 m cells with a sun at the
 * horizon, below it at some cells (refraction per cell) and above it at
 * others. */
#include "config.h"

#include <math.h>
#include <string.h>

#include <cpl_conv.h>
#include <gdal.h>
#include <ogr_srs_api.h>

#include "frame.h"
#include "skysweep_sun.h"
#include "sun_field.h"
#include "tap.h"

/* straddle: the sun must be below the horizontal at some cells and above
 * it at others, so that both of refraction's forms are taken. */
static void check(int epsg, double ulx, double uly, double cell, const char *when,
                  const char *label, int straddle)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_dem dem;
    memset(&dem, 0, sizeof dem);
    const int w = 301, h = 257; /* ~ 300 km wide at 1 km cells */
    ss_grid_alloc(ctx, &dem.grid, w, h, cell, cell);
    for (int k = 0; k < w * h; ++k)
        dem.grid.z[k] = (float)(500.0 + 400.0 * sin(k * 0.001));
    double gt[6] = {ulx, cell, 0, uly, 0, -cell};
    memcpy(dem.geotransform, gt, sizeof gt);
    OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
    OSRImportFromEPSG(srs, epsg);
    OSRExportToWkt(srs, &dem.crs_wkt);
    ss_dem_frame frame;
    ss_sun_field field;
    double t;
    ss_status st = ss_dem_frame_open(ctx, &dem, &frame);
    if (st == SS_OK)
        st = ss_parse_instant(ctx, when, &t);
    ss_spa_params p;
    ss_spa_params_default(&p);
    p.delta_t_s = 69.0;
    if (st == SS_OK)
        st = ss_sun_field_compute(ctx, &dem, &frame, t, &p, 1, &field);
    double worst_az = 0, worst_el = 0;
    for (int k = 0; st == SS_OK && k < 60; ++k) {
        int c = (k * 97) % w, r = (k * 61) % h;
        size_t cell_index = (size_t)r * w + c;
        double lon, lat, north;
        ss_geo_lonlat(frame.geo, c, r, &lon, &lat);
        ss_geo_grid_north(frame.geo, c, r, &north);
        ss_spa_params pc = p;
        pc.elevation_m = dem.grid.z[cell_index];
        ss_spa_result full;
        if ((st = ss_spa(ctx, t, lat, lon, &pc, &full)) != SS_OK)
            break;
        double az = field.grid_azimuth_deg[cell_index] + north;
        double daz = fmod(az - full.azimuth_deg + 540.0, 360.0) - 180.0;
        worst_az = fmax(worst_az, fabs(daz) * cos(full.elevation_deg * M_PI / 180));
        worst_el = fmax(worst_el, fabs(field.apparent_elevation_deg[cell_index] -
                                       full.apparent_elevation_deg));
    }
    /* Refraction at every cell: the apparent elevation less the true one,
     * against the formula, within 1e-6 deg and a float's rounding of each. */
    double worst_refraction = 0;
    int below = 0, above = 0; /* cells with the sun below and above the horizontal */
    for (size_t k = 0; st == SS_OK && k < (size_t)w * h; ++k) {
        float e0 = field.elevation_deg[k], app = field.apparent_elevation_deg[k];
        below += e0 < 0;
        above += e0 > 0;
        double want = ss_spa_refraction_deg(e0, p.pressure_hpa, p.temperature_c,
                                            p.atmos_refract_deg);
        double ulps = (nextafterf(fabsf(app), INFINITY) - fabsf(app)) +
                      (nextafterf(fabsf(e0), INFINITY) - fabsf(e0));
        worst_refraction = fmax(worst_refraction, fabs((double)app - e0 - want) - ulps);
    }
    tap_ok(st == SS_OK && worst_refraction <= 1e-6 && (!straddle || (below > 0 && above > 0)),
           "%s: refraction per cell == the formula at its elevation within 1e-6 deg beyond the "
           "floats' rounding (worst %.2e deg; centre's sun at %.3f deg; %d cells below the "
           "horizontal, %d above)",
           label, worst_refraction, st == SS_OK ? field.centre.elevation_deg : 0.0, below,
           above);
    tap_ok(st == SS_OK && worst_az < 1e-3 && worst_el < 1e-3,
           "%s: per-cell sun == full SPA per cell: worst %.2e deg in azimuth (times cos e), "
           "%.2e deg in apparent elevation (spread over the grid %.3f deg) %s",
           label, worst_az, worst_el, st == SS_OK ? field.spread_deg : 0.0,
           st == SS_OK ? "" : ss_ctx_message(ctx));
    if (st == SS_OK)
        ss_sun_field_free(&field);
    ss_dem_frame_close(&frame);
    CPLFree(dem.crs_wkt);
    dem.crs_wkt = NULL;
    ss_grid_free(&dem.grid);
    OSRDestroySpatialReference(srs);
    ss_ctx_free(ctx);
}

int main(void)
{
    GDALAllRegister();
    check(32605, 100000, 2300000, 1000, "2026-06-21T22:00:00Z", "UTM 5N, 20 N, high sun", 0);
    check(32605, 100000, 2300000, 1000, "2026-06-21T16:30:00Z", "UTM 5N, 20 N, sun at 7 deg", 0);
    check(25833, 400000, 8750000, 1000, "2026-06-21T23:00:00+02:00", "UTM 33N, 78 N, polar day", 0);
    check(32605, 100000, 2300000, 30, "2026-06-21T15:53:00Z", "UTM 5N, 30 m cells, sun just up", 0);
    check(32605, 100000, 2300000, 30, "2026-06-21T15:51:18Z", "UTM 5N, 30 m cells, sunrise", 1);
    check(32605, 100000, 2300000, 30, "2026-06-21T16:10:00Z", "UTM 5N, 30 m cells, sun at 4 deg", 0);
    return tap_done();
}
