/* The geodesy adapter against GeographicLib's own tools (GeoConvert,
 * TransverseMercatorProj, GeodSolve 2.1.2, outputs pasted below with the
 * commands that made them), the DMA TM 8358.2 UTM vectors, the WGS84 cell
 * sizes and the other checks of reference/physics.md section 5 and
 * reference/toolchain.md. */
#include "config.h"

#include <math.h>
#include <string.h>

#include <cpl_conv.h>
#include <ogr_srs_api.h>

#include "geodesy.h"
#include "tap.h"

static const double ARCSEC_DEG = 1.0 / 3600.0;

/* WKT of any CRS definition GDAL takes (EPSG:n, PROJ string), as a DEM
 * reader would hand it over. Free with CPLFree. */
static char *wkt_of(const char *definition)
{
    OGRSpatialReferenceH srs = OSRNewSpatialReference(NULL);
    char *wkt = NULL;
    if (OSRSetFromUserInput(srs, definition) != OGRERR_NONE || OSRExportToWkt(srs, &wkt) != 0) {
        fprintf(stderr, "cannot build the CRS '%s'\n", definition);
        exit(99);
    }
    OSRDestroySpatialReference(srs);
    return wkt;
}

/* Opens a grid whose cell (col, row) is centred on (x, y) of CRS
 * `definition`, with square pixels of `pixel` CRS units, north up. */
static ss_geo *open_at(ss_ctx *ctx, const char *definition, double x, double y, int col, int row,
                       double pixel, int width, int height)
{
    double gt[6] = {x - (col + 0.5) * pixel, pixel, 0, y + (row + 0.5) * pixel, 0, -pixel};
    char *wkt = wkt_of(definition);
    ss_geo *geo = NULL;
    if (ss_geo_open(ctx, wkt, gt, width, height, &geo) != SS_OK) {
        fprintf(stderr, "ss_geo_open(%s): %s\n", definition, ss_ctx_message(ctx));
        exit(99);
    }
    CPLFree(wkt);
    return geo;
}

typedef struct {
    double x, y; /* in the CRS */
    double lat_deg, lon_deg;
    double gamma_deg, k; /* meridian convergence and scale */
} tm_point;

/* Places each point at the centre of cell (40, 60) of a 10 m grid and checks
 * position, convergence and scale. Against GeographicLib's tools: 1e-9 deg
 * (0.1 mm) in position, 2e-9 deg in convergence (the finite differences'
 * rounding is ~6e-10 deg, doc/geodesy.md), 2e-9 in scale. */
static void check_tm(ss_ctx *ctx, const char *definition, const tm_point *p, int n,
                     double tol_pos_deg, double tol_gamma_deg, double tol_k)
{
    const double pixel = 10.0;
    for (int i = 0; i < n; ++i) {
        ss_geo *geo = open_at(ctx, definition, p[i].x, p[i].y, 40, 60, pixel, 100, 100);
        double lon, lat, gn, dx, dy;
        char what[200];
        ss_status st = ss_geo_lonlat(geo, 40, 60, &lon, &lat);
        if (st == SS_OK)
            st = ss_geo_grid_north(geo, 40, 60, &gn);
        if (st == SS_OK)
            st = ss_geo_cell_size(geo, 40, 60, &dx, &dy);
        if (!tap_ok(st == SS_OK, "%s (%.2f, %.2f): calls succeed %s", definition, p[i].x, p[i].y,
                    st == SS_OK ? "" : ss_ctx_message(ctx))) {
            ss_geo_close(geo);
            continue;
        }
        snprintf(what, sizeof what, "%s (%.2f, %.2f) latitude", definition, p[i].x, p[i].y);
        tap_close(lat, p[i].lat_deg, tol_pos_deg, what);
        snprintf(what, sizeof what, "%s (%.2f, %.2f) longitude", definition, p[i].x, p[i].y);
        tap_close(lon, p[i].lon_deg, tol_pos_deg, what);
        snprintf(what, sizeof what, "%s (%.2f, %.2f) grid north = convergence", definition, p[i].x,
                 p[i].y);
        tap_close(gn, p[i].gamma_deg, tol_gamma_deg, what);
        snprintf(what, sizeof what, "%s (%.2f, %.2f) scale = pixel / dx", definition, p[i].x,
                 p[i].y);
        tap_close(pixel / dx, p[i].k, tol_k, what);
        snprintf(what, sizeof what, "%s (%.2f, %.2f) scale = pixel / dy", definition, p[i].x,
                 p[i].y);
        tap_close(pixel / dy, p[i].k, tol_k, what);
        ss_geo_close(geo);
    }
}

static void test_utm(ss_ctx *ctx)
{
    /* reference/toolchain.md, and
     * printf '5n 503200 2197600\n5n 195000 2150000\n5n 800000 2200000\n' | GeoConvert -g -p 9
     * (the same with -c for "gamma k"): the second and third points lie
     * 2.9 deg west and east of the central meridian, near the zone's edges. */
    const tm_point utm5n[] = {
        {503200, 2197600, 19.87455543963834, -152.96943293699994, 0.0103916390118,
         0.999600126561280},
        {195000, 2150000, 19.42115254553930, -155.90427673924725, -0.9664486941493,
         1.000750041464635},
        {800000, 2200000, 19.87319376352622, -150.13528653168271, 0.9745607407920,
         1.000712562582512},
    };
    check_tm(ctx, "EPSG:32605", utm5n, 3, 1e-9, 2e-9, 2e-9);
    /* The same with a vertical CRS (NAVD88 height): its horizontal part counts. */
    check_tm(ctx, "EPSG:32605+5703", utm5n, 1, 1e-9, 2e-9, 2e-9);

    /* ETRS89 / UTM 33N on GRS80, Svalbard:
     * printf -- '-70000 8660000\n70000 8700000\n0 8750000\n' | TransverseMercatorProj -r \
     *     -l 15 -k 0.9996 -e 6378137 1/298.257222101 -p 9
     * (x = E - 500000). The first two lie 3.0 deg from the central meridian. */
    const tm_point svalbard[] = {
        {430000, 8660000, 77.99845297469149, 11.98314403514876, -2.951031447262086,
         0.999659881378036},
        {570000, 8700000, 78.35635790452200, 18.10831140635414, 3.044469657302686,
         0.999659879356192},
        {500000, 8750000, 78.82103350266061, 15.0, 0.0, 0.9996},
    };
    check_tm(ctx, "EPSG:25833", svalbard, 3, 1e-9, 2e-9, 2e-9);

    /* UPS North, whose EPSG axis order is northing first (the geotransform's
     * x is still easting):
     * printf 'n 2100000 1900000\n' | GeoConvert -g -p 9   (and -c) */
    const tm_point ups[] = {{2100000, 1900000, 88.72625736726900, 45.0, 45.0, 0.994122822956977}};
    check_tm(ctx, "EPSG:32661", ups, 1, 1e-9, 2e-9, 2e-9);

    /* A UPS cell centred on the pole: north is defined there by the frame of
     * the longitude returned (ss_geo_ecef_to_enu), in which UPS North's
     * convergence is the longitude itself (as GeoConvert -c shows above). */
    ss_geo *pole = open_at(ctx, "EPSG:32661", 2000000, 2000000, 40, 60, 10, 100, 100);
    double pole_lon, pole_lat, pole_gn, pole_dx, pole_dy;
    ss_status pst = ss_geo_lonlat(pole, 40, 60, &pole_lon, &pole_lat);
    if (pst == SS_OK)
        pst = ss_geo_grid_north(pole, 40, 60, &pole_gn);
    if (pst == SS_OK)
        pst = ss_geo_cell_size(pole, 40, 60, &pole_dx, &pole_dy);
    if (tap_ok(pst == SS_OK && pole_lat == 90, "UPS cell on the north pole (lon %.9g)", pole_lon)) {
        tap_close(pole_gn, pole_lon, 1e-9, "UPS grid north at the pole = the returned longitude");
        tap_close(10 / pole_dx, 0.994, 1e-9, "UPS scale at the pole = k0");
    }
    ss_geo_close(pole);

    /* DMA TM 8358.2 on the International 1924 ellipsoid (physics.md section 5;
     * E/N given to the cm, convergence to 0.01", scale to 1e-8). Latitudes
     * and longitudes 73N 45E, 30N 102E, 72 04'32.110"N 113 54'43.321"W. */
    const tm_point dma38[] = {{500000.00, 8100702.90, 73.0, 45.0, 0.0, 0.99960000}};
    const tm_point dma48[] = {
        {210577.93, 3322624.35, 30.0, 102.0, -(1 + 30.0 / 60 + 3.76 / 3600), 1.00063354}};
    const tm_point dma12[] = {{400000.00, 8000000.01, 72 + 4.0 / 60 + 32.110 / 3600,
                               -(113 + 54.0 / 60 + 43.321 / 3600), -(2 + 46.0 / 60 + 15.31 / 3600),
                               0.99972228}};
    const double cm_deg = 1.5e-7, dma_gamma_deg = 0.006 * ARCSEC_DEG;
    check_tm(ctx, "+proj=utm +zone=38 +ellps=intl +units=m +no_defs", dma38, 1, cm_deg,
             dma_gamma_deg, 6e-9);
    check_tm(ctx, "+proj=utm +zone=48 +ellps=intl +units=m +no_defs", dma48, 1, cm_deg,
             dma_gamma_deg, 6e-9);
    check_tm(ctx, "+proj=utm +zone=12 +ellps=intl +units=m +no_defs", dma12, 1, cm_deg,
             dma_gamma_deg, 6e-9);

    /* A geographic CRS in grads on the Paris meridian (NTF Lambert II
     * etendu): its false origin is on the Paris meridian.
     * echo "600000 2428000" | cs2cs -f %.10f EPSG:27572 EPSG:4275
     *   -> 48.8504159149 2.3372291667
     * GDAL's WKT1 gives the meridian as 2.33722917 deg (2.5969213 grad), PROJ's
     * pipeline as 2 20'14.025": 3e-9 deg (0.3 mm) apart. */
    ss_geo *ntf = open_at(ctx, "EPSG:27572", 600000, 2428000, 40, 60, 10, 100, 100);
    double lon, lat;
    tap_ok(ss_geo_lonlat(ntf, 40, 60, &lon, &lat) == SS_OK, "NTF Lambert II: lon/lat");
    tap_close(lon, 2.3372291667, 5e-9, "NTF Lambert II (grads, Paris meridian) longitude");
    tap_close(lat, 48.8504159149, 1e-9, "NTF Lambert II (grads, Paris meridian) latitude");
    ss_geo_close(ntf);
}

static void test_svalbard_summary(ss_ctx *ctx)
{
    /* EPSG:25833, E 430000..570000, N 8660000..8750000, 100 m cells. */
    double gt[6] = {430000, 100, 0, 8750000, 0, -100};
    char *wkt = wkt_of("EPSG:25833");
    ss_geo *geo = NULL;
    ss_geo_summary s;
    ss_status st = ss_geo_open(ctx, wkt, gt, 1400, 900, &geo);
    CPLFree(wkt);
    if (st == SS_OK)
        st = ss_geo_extent_summary(geo, &s);
    if (!tap_ok(st == SS_OK, "Svalbard grid summary %s", st == SS_OK ? "" : ss_ctx_message(ctx)))
        return;
    /* Outer corners, TransverseMercatorProj as above on
     * -70000 8750000, 70000 8750000, 70000 8660000, -70000 8660000. */
    const double corner_lat[4] = {78.80368116188379, 78.80368116188379, 77.99845297469149,
                                  77.99845297469149};
    const double corner_lon[4] = {11.76908934268026, 18.23091065731974, 18.01685596485125,
                                  11.98314403514876};
    for (int i = 0; i < 4; ++i) {
        tap_close(s.corner_lat_deg[i], corner_lat[i], 1e-9, "Svalbard outer corner latitude");
        tap_close(s.corner_lon_deg[i], corner_lon[i], 1e-9, "Svalbard outer corner longitude");
    }
    /* Corner cell centres (+-69950, 8749950 / 8660050), same command:
     * gamma -3.167156384023104 .. 3.167156384023104, k 0.999659791404278
     * .. 0.999659795860348 there; on the central meridian k = 0.9996. */
    tap_close(s.grid_north_min_deg, -3.167156384023104, 1e-9, "Svalbard min convergence");
    tap_close(s.grid_north_max_deg, 3.167156384023104, 1e-9, "Svalbard max convergence");
    tap_close(s.grid_north_centre_deg, 0.0, 1e-9, "Svalbard centre convergence");
    /* The lattice's columns straddle the central meridian, so the largest
     * cell (k smallest) is within (350 m)^2/(2 R^2 k) ~ 1e-9 of 100/0.9996. */
    tap_close(s.dx_max_m, 100.0 / 0.9996, 1e-6, "Svalbard largest cell");
    tap_close(s.dx_min_m, 100.0 / 0.999659795860348, 1e-6, "Svalbard smallest cell");
    tap_close(s.cell_variation, 0.999659795860348 / 0.9996 - 1, 1e-8,
              "Svalbard cell-size variation");
    /* printf '78.80368116188379 11.76908934268026 77.99845297469149 18.01685596485125\n' |
     *     GeodSolve -i -e 6378137 1/298.257222101 -p 9 */
    tap_close(s.diagonal_m, 166496.445183666, 1e-6, "Svalbard diagonal (GeodSolve)");
    ss_geo_close(geo);
}

static void test_geographic(ss_ctx *ctx)
{
    /* physics.md section 5 (WGS84): 1" and 3" cells, dy then dx. */
    const double lats[4] = {0, 45, 60, 75};
    const double table[4][4] = {{30.7151, 30.9221, 92.145, 92.766},
                                {30.8699, 21.9019, 92.610, 65.706},
                                {30.9479, 15.5000, 92.844, 46.500},
                                {31.0051, 8.0283, 93.015, 24.085}};
    /* GeodSolve -i -p 9 between (lat -+ 0.5", 0) (meridian) and between
     * (lat, 0) and (lat, 1") (parallel): the geodesic over one cell. */
    const double geod_dy[4] = {30.715076617, 30.869938171, 30.947857628, 31.005106683};
    const double geod_dx[4] = {30.922080776, 21.901898637, 15.500000437, 8.028334947};
    for (int i = 0; i < 4; ++i) {
        for (int arcsec = 1; arcsec <= 3; arcsec += 2) {
            ss_geo *geo = open_at(ctx, "EPSG:4326", 10.0, lats[i], 0, 0, arcsec * ARCSEC_DEG, 9, 9);
            double dx, dy, gn, lon, lat;
            ss_status st = ss_geo_cell_size(geo, 0, 0, &dx, &dy);
            if (st == SS_OK)
                st = ss_geo_grid_north(geo, 0, 0, &gn);
            if (st == SS_OK)
                st = ss_geo_lonlat(geo, 0, 0, &lon, &lat);
            if (!tap_ok(st == SS_OK, "4326 at %g: calls succeed", lats[i])) {
                ss_geo_close(geo);
                continue;
            }
            char what[120];
            int k = arcsec == 1 ? 0 : 2;
            double tol = arcsec == 1 ? 5e-5 : 5e-4; /* the table's last digit */
            snprintf(what, sizeof what, "%d\" dy at %g (physics table)", arcsec, lats[i]);
            tap_close(dy, table[i][k], tol, what);
            snprintf(what, sizeof what, "%d\" dx at %g (physics table)", arcsec, lats[i]);
            tap_close(dx, table[i][k + 1], tol, what);
            if (arcsec == 1) {
                snprintf(what, sizeof what, "1\" dy at %g vs meridian geodesic", lats[i]);
                tap_close(dy, geod_dy[i], 1e-7, what);
                snprintf(what, sizeof what, "1\" dx at %g vs parallel geodesic", lats[i]);
                tap_close(dx, geod_dx[i], 1e-7, what);
            }
            tap_ok(gn == 0.0, "grid north on a lat/lon grid at %g is exactly 0 (got %.17g)",
                   lats[i], gn);
            tap_ok(lon == 10.0 && fabs(lat - lats[i]) < 1e-12,
                   "cell (0,0) is centred on (10, %g): got (%.15g, %.15g)", lats[i], lon, lat);
            ss_geo_close(geo);
        }
    }

    /* Across the antimeridian: lon 179.5 .. 180.5, lat 45.5 .. 44.5. */
    double gt[6] = {179.5, 0.01, 0, 45.5, 0, -0.01};
    char *wkt = wkt_of("EPSG:4326");
    ss_geo *geo = NULL;
    ss_geo_summary s;
    ss_status st = ss_geo_open(ctx, wkt, gt, 100, 100, &geo);
    if (st == SS_OK)
        st = ss_geo_extent_summary(geo, &s);
    if (tap_ok(st == SS_OK, "antimeridian grid summary %s",
               st == SS_OK ? "" : ss_ctx_message(ctx))) {
        double lon, lat;
        tap_ok(ss_geo_lonlat(geo, 75, 50, &lon, &lat) == SS_OK, "antimeridian cell lon/lat");
        tap_close(lon, -179.745, 1e-12, "antimeridian cell longitude wraps to -179.745");
        tap_close(s.corner_lon_deg[0], 179.5, 1e-12, "antimeridian NW corner longitude");
        tap_close(s.corner_lon_deg[1], -179.5, 1e-12, "antimeridian NE corner longitude");
        /* printf '45.5 179.5 44.5 -179.5\n' | GeodSolve -i -p 9 */
        tap_close(s.diagonal_m, 136258.519697190, 1e-6, "antimeridian diagonal (GeodSolve)");
        tap_ok(s.grid_north_min_deg == 0 && s.grid_north_max_deg == 0,
               "antimeridian grid north is 0 everywhere");
        /* Cell centres run from lat 45.495 to 44.505; over 0.01 deg of
         * longitude the geodesic is 5e-7 m shorter than the parallel:
         * echo "44.505 0 44.505 0.01" | GeodSolve -i -p 9  -> 795.227646373
         * echo "45.495 0 45.495 0.01" | GeodSolve -i -p 9  -> 781.649811201 */
        tap_close(s.dx_max_m, 795.227646373, 1e-6, "antimeridian largest dx");
        tap_close(s.dx_min_m, 781.649811201, 1e-6, "antimeridian smallest dx");
        tap_close(s.cell_variation, 795.227646373 / 781.649811201 - 1, 1e-9,
                  "antimeridian cell-size variation");
    }
    ss_geo_close(geo);

    /* Up to the north pole: lat 90 .. 89.8, cells 0.01 deg. */
    double gt_pole[6] = {0, 0.01, 0, 90, 0, -0.01};
    st = ss_geo_open(ctx, wkt, gt_pole, 100, 20, &geo);
    CPLFree(wkt);
    double lon, lat, dx, dy, gn;
    if (st == SS_OK)
        st = ss_geo_lonlat(geo, 49.5, 9.5, &lon, &lat);
    if (st == SS_OK)
        st = ss_geo_cell_size(geo, 49.5, 9.5, &dx, &dy);
    if (st == SS_OK)
        st = ss_geo_grid_north(geo, 49.5, 9.5, &gn);
    if (st == SS_OK)
        st = ss_geo_extent_summary(geo, &s);
    if (tap_ok(st == SS_OK, "grid up to the pole %s", st == SS_OK ? "" : ss_ctx_message(ctx))) {
        tap_close(lat, 89.9, 1e-12, "pole grid latitude");
        /* N cos(89.9 deg) 0.01 deg with N = a^2/b there: 19.49 m. */
        tap_close(dx, 6399593.6258 * cos(89.9 * M_PI / 180) * 0.01 * M_PI / 180, 1e-3,
                  "pole grid dx at 89.9");
        tap_ok(gn == 0, "pole grid north is 0");
        tap_ok(isfinite(s.cell_variation) && isfinite(s.diagonal_m) &&
                   isfinite(s.grid_north_max_deg) && s.corner_lat_deg[0] == 90,
               "pole grid summary is finite (variation %g, diagonal %g m)", s.cell_variation,
               s.diagonal_m);
    }
    ss_geo_close(geo);
}

static void test_geodesic(ss_ctx *ctx)
{
    ss_geo *geo = open_at(ctx, "EPSG:4326", 0, 0, 0, 0, 1, 3, 3);
    double d, azi;
    /* reference/toolchain.md; echo "19.82 -155.47 21.31 -157.86" | GeodSolve -i -p 9
     * -> azi1 -56.08202888006994, s12 298843.483585662 */
    tap_ok(ss_geo_inverse(geo, 19.82, -155.47, 21.31, -157.86, &d, &azi) == SS_OK,
           "geodesic inverse");
    tap_close(d, 298843.483585662, 1e-6, "geodesic distance");
    tap_close(azi, -56.08202888006994, 1e-9, "geodesic azimuth");
    /* sqrt(M N) = b on the equator and a^2/b at the poles (WGS84). */
    tap_close(ss_geo_earth_radius_m(geo, 0), 6356752.314245, 1e-5, "earth radius at 0 = b");
    tap_close(ss_geo_earth_radius_m(geo, 90), 6378137.0 * 6378137.0 / 6356752.314245, 1e-5,
              "earth radius at the pole = a^2/b");
    double a, f;
    ss_geo_ellipsoid(geo, &a, &f);
    tap_ok(a == 6378137.0 && fabs(1 / f - 298.257223563) < 1e-9, "EPSG:4326 uses WGS84");
    ss_geo_close(geo);

    geo = open_at(ctx, "+proj=utm +zone=38 +ellps=intl +units=m +no_defs", 500000, 8100702.9, 0, 0,
                  1, 3, 3);
    ss_geo_ellipsoid(geo, &a, &f);
    tap_ok(a == 6378388.0 && fabs(1 / f - 297) < 1e-9,
           "International 1924 CRS uses its own ellipsoid (a %.3f, 1/f %.9f)", a, 1 / f);
    ss_geo_close(geo);
}

static int vec_close(const double *got, double x, double y, double z)
{
    return fabs(got[0] - x) < 1e-15 && fabs(got[1] - y) < 1e-15 && fabs(got[2] - z) < 1e-15;
}

static void test_sun(ss_ctx *ctx)
{
    double enu[3];
    const double x_axis[3] = {1, 0, 0}, y_axis[3] = {0, 1, 0}, z_axis[3] = {0, 0, 1};
    ss_geo_ecef_to_enu(0, 0, x_axis, enu);
    tap_ok(vec_close(enu, 0, 0, 1), "ECEF x from (0, 0) is the zenith");
    ss_geo_ecef_to_enu(0, 90, x_axis, enu);
    tap_ok(vec_close(enu, -1, 0, 0), "ECEF x from (0, 90E) lies on the western horizon");
    ss_geo_ecef_to_enu(0, 0, y_axis, enu);
    tap_ok(vec_close(enu, 1, 0, 0), "ECEF y from (0, 0) lies on the eastern horizon");
    ss_geo_ecef_to_enu(0, 0, z_axis, enu);
    tap_ok(vec_close(enu, 0, 1, 0), "ECEF z from (0, 0) lies on the northern horizon");
    ss_geo_ecef_to_enu(90, 0, z_axis, enu);
    tap_ok(vec_close(enu, 0, 0, 1), "ECEF z from the north pole is the zenith");
    const double lat = 37.5, lon = -122.25;
    const double up[3] = {cos(lat * M_PI / 180) * cos(lon * M_PI / 180),
                          cos(lat * M_PI / 180) * sin(lon * M_PI / 180), sin(lat * M_PI / 180)};
    ss_geo_ecef_to_enu(lat, lon, up, enu);
    tap_ok(fabs(enu[0]) < 1e-15 && fabs(enu[1]) < 1e-15 && fabs(enu[2] - 1) < 1e-15,
           "the ellipsoid normal at (37.5, -122.25) is the zenith");

    /* Parallax: a/1 AU = 8.794". Seen from the equator at lon 0, a sun in the
     * equatorial plane at geocentric elevation e appears lower by
     * asin(a cos(e_topo) / d) ~ 8.794" cos(e). */
    ss_geo *geo = open_at(ctx, "EPSG:4326", 0, 0, 0, 0, 1, 3, 3);
    const double hp_arcsec = asin(6378137.0 / 149597870700.0) * 180 / M_PI * 3600;
    const double elevations[4] = {90, 45, 10, 0};
    for (int i = 0; i < 4; ++i) {
        double e = elevations[i] * M_PI / 180;
        const double dir[3] = {sin(e), cos(e), 0}; /* from the zenith toward the east */
        double az, el;
        if (!tap_ok(ss_geo_sun_local(geo, 0, 0, 0, dir, 1.0, &az, &el) == SS_OK,
                    "sun at geocentric elevation %g", elevations[i]))
            continue;
        char what[120];
        snprintf(what, sizeof what, "parallax at elevation %g, arcsec", elevations[i]);
        tap_close((elevations[i] - el) * 3600, hp_arcsec * cos(e), 0.005, what);
        if (elevations[i] < 90)
            tap_close(az, 90, 1e-9, "sun in the equatorial plane stays due east");
    }
    /* At 60N the observer is rho = 0.9976 a from the centre and off the
     * line of the vertical by 0.19 deg: the lowering is 8.794" rho/a cos(e)
     * = 7.597" to within 0.02"; the azimuth moves by micro-degrees. */
    double dir_en[3], sun_dir[3], az, el;
    const double e_deg = 30, az0_deg = 200;
    dir_en[0] = cos(e_deg * M_PI / 180) * sin(az0_deg * M_PI / 180);
    dir_en[1] = cos(e_deg * M_PI / 180) * cos(az0_deg * M_PI / 180);
    dir_en[2] = sin(e_deg * M_PI / 180);
    /* ENU -> ECEF is the transpose of the rotation: build it column by column. */
    for (int i = 0; i < 3; ++i) {
        double unit[3] = {0, 0, 0}, col[3];
        unit[i] = 1;
        ss_geo_ecef_to_enu(60, 25, unit, col);
        sun_dir[i] = col[0] * dir_en[0] + col[1] * dir_en[1] + col[2] * dir_en[2];
    }
    tap_ok(ss_geo_sun_local(geo, 60, 25, 500, sun_dir, 1.0, &az, &el) == SS_OK, "sun at 60N");
    tap_close((e_deg - el) * 3600, hp_arcsec * 0.9976 * cos(e_deg * M_PI / 180), 0.02,
              "parallax at 60N, elevation 30, arcsec");
    tap_close(az, az0_deg, 1e-4, "azimuth at 60N barely moves");
    ss_geo_close(geo);
}

static void test_errors(ss_ctx *ctx)
{
    const double gt[6] = {500000, 10, 0, 2200000, 0, -10};
    ss_geo *geo = (ss_geo *)1;
    ss_status st = ss_geo_open(ctx, "PROJCS[nonsense", gt, 10, 10, &geo);
    tap_ok(st == SS_ERR_INPUT && geo == NULL && strstr(ss_ctx_message(ctx), "CRS"),
           "bad WKT is refused: %s", ss_ctx_message(ctx));
    st = ss_geo_open(ctx, "", gt, 10, 10, &geo);
    tap_ok(st == SS_ERR_INPUT, "no CRS is refused: %s", ss_ctx_message(ctx));
    char *wkt = wkt_of("EPSG:4978");
    st = ss_geo_open(ctx, wkt, gt, 10, 10, &geo);
    CPLFree(wkt);
    tap_ok(st == SS_ERR_INPUT, "a geocentric CRS is refused: %s", ss_ctx_message(ctx));
    st = ss_geo_open(ctx, "LOCAL_CS[\"site grid\",UNIT[\"metre\",1]]", gt, 10, 10, &geo);
    tap_ok(st == SS_ERR_INPUT, "an engineering CRS is refused: %s", ss_ctx_message(ctx));
    wkt = wkt_of("EPSG:32605");
    const double singular[6] = {500000, 10, 0, 2200000, 0, 0};
    st = ss_geo_open(ctx, wkt, singular, 10, 10, &geo);
    tap_ok(st == SS_ERR_INPUT, "a singular geotransform is refused: %s", ss_ctx_message(ctx));
    const double far[6] = {1e15, 10, 0, 1e15, 0, -10};
    st = ss_geo_open(ctx, wkt, far, 10, 10, &geo);
    tap_ok(st == SS_ERR_INPUT, "a grid off the projection is refused: %s", ss_ctx_message(ctx));
    CPLFree(wkt);

    /* An ellipsoid PROJ accepts but GeographicLib refuses (f = 2: negative
     * polar radius): GeographicErr becomes a status. */
    const char *bad_ellipsoid =
        "GEOGCS[\"bad\",DATUM[\"bad\",SPHEROID[\"bad\",6378137,0.5]],PRIMEM[\"Greenwich\",0],"
        "UNIT[\"degree\",0.0174532925199433]]";
    const double gt_geo[6] = {0, 1, 0, 10, 0, -1};
    st = ss_geo_open(ctx, bad_ellipsoid, gt_geo, 4, 4, &geo);
    tap_ok(st == SS_ERR_INPUT, "an impossible ellipsoid is refused: %s", ss_ctx_message(ctx));

    geo = open_at(ctx, "EPSG:4326", 0, 89.5, 0, 0, 1, 3, 3);
    double lon, lat, d, azi, az, el;
    st = ss_geo_lonlat(geo, 0, -2, &lon, &lat);
    tap_ok(st == SS_ERR_INPUT, "a position beyond the pole is refused as the DEM's fault: %s",
           ss_ctx_message(ctx));
    st = ss_geo_lonlat(geo, NAN, 0, &lon, &lat);
    tap_ok(st == SS_ERR_ARGUMENT, "a NaN position is refused: %s", ss_ctx_message(ctx));
    st = ss_geo_inverse(geo, 91, 0, 0, 0, &d, &azi);
    tap_ok(st == SS_ERR_ARGUMENT, "latitude 91 is refused: %s", ss_ctx_message(ctx));
    const double dir[3] = {1, 0, 0}, zero[3] = {0, 0, 0};
    st = ss_geo_sun_local(geo, 0, 0, 0, dir, 0, &az, &el);
    tap_ok(st == SS_ERR_ARGUMENT, "a sun at distance 0 is refused: %s", ss_ctx_message(ctx));
    st = ss_geo_sun_local(geo, 0, 0, 0, zero, 1, &az, &el);
    tap_ok(st == SS_ERR_ARGUMENT, "a zero sun direction is refused: %s", ss_ctx_message(ctx));
    st = ss_geo_sun_local(geo, -90.5, 0, 0, dir, 1, &az, &el);
    tap_ok(st == SS_ERR_ARGUMENT, "a sun seen from latitude -90.5 is refused: %s",
           ss_ctx_message(ctx));
    ss_geo_close(geo);

    /* UTM far outside its zone: PROJ's inverse fails and says so. */
    geo = open_at(ctx, "EPSG:32605", 500000, 2200000, 0, 0, 10, 3, 3);
    st = ss_geo_lonlat(geo, 1e9, 0, &lon, &lat);
    tap_ok(st == SS_ERR_ARGUMENT, "a UTM position 1e10 m east is refused: %s", ss_ctx_message(ctx));
    ss_geo_close(geo);
}

int main(void)
{
    ss_ctx *ctx = ss_ctx_new();
    test_utm(ctx);
    test_svalbard_summary(ctx);
    test_geographic(ctx);
    test_geodesic(ctx);
    test_sun(ctx);
    test_errors(ctx);
    ss_ctx_free(ctx);
    return tap_done();
}
