/* GeographicLib adapter: where each cell of a DEM lies on the Earth, which
 * way true north is, how large its cells are on the ground, and where the sun
 * stands seen from a cell. The only file that includes GeographicLib
 * (src/adapt/geodesy.cpp); conventions and test vectors in doc/geodesy.md.
 *
 * Cell positions (col, row) are cell-centre indices: the centre of cell
 * (c, r) is col = c, row = r, so its GDAL pixel/line position is (c + 0.5,
 * r + 0.5); the grid's outer corners are at -0.5 and width - 0.5 / height -
 * 0.5. Longitudes and latitudes are geodetic degrees on the CRS's own datum,
 * longitudes reckoned from Greenwich and normalised to [-180, 180]. */
#ifndef SS_GEODESY_H
#define SS_GEODESY_H

#include "skysweep.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct ss_geo ss_geo;

/* Opens the georeferencing of a width x height grid. crs_wkt is the CRS as
 * WKT (as GDAL reports it); it must be geographic or projected (compound
 * CRSs use their horizontal part). geotransform is GDAL's, x being easting
 * or longitude (GDAL's traditional GIS axis order). The geo keeps ctx for
 * the messages of later calls, so ctx must outlive it. */
ss_status ss_geo_open(ss_ctx *ctx, const char *crs_wkt, const double geotransform[6], int width,
                      int height, ss_geo **out);
void ss_geo_close(ss_geo *geo);

/* Nonzero when the grid's CRS is geographic (a lat/lon grid). */
int ss_geo_is_geographic(const ss_geo *geo);

/* Semi-major axis and flattening of the ellipsoid every computation here
 * uses: the CRS's own, else WGS84. */
void ss_geo_ellipsoid(const ss_geo *geo, double *a_m, double *f);

/* Geodetic longitude and latitude of the (fractional) cell-centre position. */
ss_status ss_geo_lonlat(ss_geo *geo, double col, double row, double *lon_deg, double *lat_deg);

/* True azimuth (degrees clockwise from true north, in (-180, 180]) of the
 * grid's "up" direction (toward decreasing row) at that position: true
 * azimuth = grid azimuth + this. For a projected grid it is the meridian
 * convergence with PROJ's sign (> 0 east of the central meridian of a
 * northern transverse Mercator); 0 on a north-up lat/lon grid. At a pole
 * east and north are those of ss_geo_ecef_to_enu at the longitude
 * ss_geo_lonlat returns there. */
ss_status ss_geo_grid_north(ss_geo *geo, double col, double row, double *true_azimuth_deg);

/* Ground length of one column step (dx_m, east-west on a north-up grid) and
 * of one row step (dy_m, north-south) at that position: M dphi and
 * N cos(phi) dlambda on a lat/lon grid, pixel size / projection scale on a
 * projected one. */
ss_status ss_geo_cell_size(ss_geo *geo, double col, double row, double *dx_m, double *dy_m);

/* Gaussian mean radius sqrt(M N) of the ellipsoid at that latitude, metres:
 * the radius to use for earth curvature around a point. */
double ss_geo_earth_radius_m(const ss_geo *geo, double lat_deg);

/* Geodesic from point 1 to point 2 on the ellipsoid: length and azimuth at
 * point 1 (degrees clockwise from true north, in [-180, 180]). */
ss_status ss_geo_inverse(const ss_geo *geo, double lat1_deg, double lon1_deg, double lat2_deg,
                         double lon2_deg, double *dist_m, double *azi1_deg);

/* Rotates an Earth-fixed direction (x toward longitude 0 on the equator,
 * z toward the north pole) into east, north, up at a geodetic latitude and
 * longitude. No ellipsoid is needed: the local vertical is the ellipsoid
 * normal, fixed by the geodetic latitude alone. */
void ss_geo_ecef_to_enu(double lat_deg, double lon_deg, const double ecef_dir[3],
                        double enu_dir[3]);

/* Topocentric (parallax included, airless) azimuth, degrees clockwise from
 * true north in [0, 360), and elevation of the sun seen from a point
 * height_m above the ellipsoid, given the sun's geocentric Earth-fixed
 * direction (need not be unit length) and its distance in astronomical
 * units. */
ss_status ss_geo_sun_local(const ss_geo *geo, double lat_deg, double lon_deg, double height_m,
                           const double sun_ecef_dir[3], double sun_dist_au, double *azimuth_deg,
                           double *elevation_deg);

/* What a planner needs to know about a whole grid. */
typedef struct {
    /* Outer corners (not corner-cell centres), in the order north-west,
     * north-east, south-east, south-west of the grid as stored (row 0 is the
     * "north" edge), then the centre of the grid. */
    double corner_lon_deg[4], corner_lat_deg[4];
    double centre_lon_deg, centre_lat_deg;
    /* ss_geo_grid_north over a 9 x 9 lattice of cell centres plus 33 points
     * along each edge; min and max are unwrapped around the centre's value
     * (they may pass +-180 on a south-up grid). */
    double grid_north_min_deg, grid_north_max_deg, grid_north_centre_deg;
    /* ss_geo_cell_size over the same points. */
    double dx_min_m, dx_max_m, dy_min_m, dy_max_m;
    /* max(dx_max / dx_min, dy_max / dy_min) - 1: the relative error of
     * taking one cell size for the whole grid. */
    double cell_variation;
    /* The longer of the two geodesic diagonals between outer corners. */
    double diagonal_m;
    /* ss_geo_earth_radius_m at the centre. */
    double centre_earth_radius_m;
} ss_geo_summary;

ss_status ss_geo_extent_summary(ss_geo *geo, ss_geo_summary *out);

#ifdef __cplusplus
}
#endif

#endif
