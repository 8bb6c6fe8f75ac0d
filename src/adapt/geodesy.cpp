/* Geodesy of a DEM's grid: GDAL/OGR takes cell positions from the DEM's CRS
 * to geodetic lon/lat on the CRS's own datum, GeographicLib does everything
 * on the ellipsoid (geodesics, curvature radii, Earth-centred positions).
 * Conventions and accuracy: doc/geodesy.md. No exception leaves this file:
 * every entry point catches and returns a status with a message. */
#include "config.h"

#include <cmath>
#include <cstdio>
#include <exception>
#include <new>

#include <cpl_error.h>
#include <ogr_srs_api.h>

#include <GeographicLib/Constants.hpp>
#include <GeographicLib/Ellipsoid.hpp>
#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/Math.hpp>

#include "skysweep.h"
#include "gdal_errors.h"
#include "geodesy.h"

using GeographicLib::Math;

/* IAU 2012 Resolution B2: the astronomical unit is exactly this many metres. */
static const double AU_M = 149597870700.0;

/* Half the ground step of the central differences on projected grids.
 * Truncation error is ~(step/R)^2 ~ 1e-10 relative, rounding of lon/lat
 * (~1e-14 deg) over the step ~1e-11: both far below what any product needs
 * (doc/geodesy.md, "Accuracy"). */
static const double FD_STEP_M = 100.0;

/* Latitudes this far beyond +-90 are rounding in a geotransform that ends on
 * a pole, and are clamped to it. */
static const double POLE_SLACK_DEG = 1e-9;

struct ss_geo {
    ss_ctx *ctx;
    OGRSpatialReferenceH srs;
    OGRSpatialReferenceH geog;            /* the CRS's own geographic CRS */
    OGRCoordinateTransformationH to_geog; /* NULL for a geographic grid */
    double gt[6];
    int width, height;
    double deg_per_unit; /* angular unit of geog, in degrees */
    double pm_deg;       /* prime meridian of geog, degrees east of Greenwich */
    double fd_step_cells;
    GeographicLib::Geodesic geodesic;
    GeographicLib::Ellipsoid ellipsoid;
    GeographicLib::Geocentric geocentric;

    ss_geo(ss_ctx *c, double a_m, double f)
        : ctx(c), srs(nullptr), geog(nullptr), to_geog(nullptr), gt(), width(0), height(0),
          deg_per_unit(1), pm_deg(0), fd_step_cells(1), geodesic(a_m, f), ellipsoid(a_m, f),
          geocentric(a_m, f)
    {
    }
    ~ss_geo()
    {
        if (to_geog)
            OCTDestroyCoordinateTransformation(to_geog);
        if (geog)
            OSRDestroySpatialReference(geog);
        if (srs)
            OSRDestroySpatialReference(srs);
    }
    ss_geo(const ss_geo &) = delete;
    ss_geo &operator=(const ss_geo &) = delete;
};

/* GDAL reports through the status and CPLGetLastErrorMsg, never on stderr. */
struct quiet_gdal {
    quiet_gdal()
    {
        CPLPushErrorHandler(CPLQuietErrorHandler);
        CPLErrorReset();
    }
    ~quiet_gdal()
    {
        CPLPopErrorHandler();
    }
    quiet_gdal(const quiet_gdal &) = delete;
    quiet_gdal &operator=(const quiet_gdal &) = delete;
};

/* Runs body, turning any exception into status `st` (memory: SS_ERR_MEMORY). */
template <class F>
static ss_status guarded(ss_ctx *ctx, ss_status st, const char *what, F body) noexcept
{
    try {
        return body();
    } catch (const GeographicLib::GeographicErr &e) {
        return ss_ctx_error(ctx, st, "%s: %s", what, e.what());
    } catch (const std::bad_alloc &) {
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "%s: out of memory", what);
    } catch (const std::exception &e) {
        return ss_ctx_error(ctx, st, "%s: %s", what, e.what());
    } catch (...) {
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "%s: unknown exception", what);
    }
}

static bool valid_lat(double lat_deg)
{
    return std::fabs(lat_deg) <= 90.0;
}

static void rotate_to_enu(double lat_deg, double lon_deg, const double v[3], double enu[3])
{
    double sphi, cphi, slam, clam;
    Math::sincosd(lat_deg, sphi, cphi);
    Math::sincosd(lon_deg, slam, clam);
    enu[0] = -slam * v[0] + clam * v[1];
    enu[1] = -sphi * clam * v[0] - sphi * slam * v[1] + cphi * v[2];
    enu[2] = cphi * clam * v[0] + cphi * slam * v[1] + sphi * v[2];
}

static ss_status to_lonlat(ss_geo *g, double col, double row, double *lon_deg, double *lat_deg)
{
    /* Cell-centre indices: GDAL's pixel/line position is index + 0.5. */
    double px = col + 0.5, ln = row + 0.5;
    double x = g->gt[0] + px * g->gt[1] + ln * g->gt[2];
    double y = g->gt[3] + px * g->gt[4] + ln * g->gt[5];
    if (!std::isfinite(x) || !std::isfinite(y))
        return ss_ctx_error(g->ctx, SS_ERR_ARGUMENT, "cell position (%g, %g) is not finite", col, row);
    if (g->to_geog) {
        quiet_gdal quiet;
        double z = 0;
        int ok = 0;
        double cx = x, cy = y;
        if (!OCTTransformEx(g->to_geog, 1, &cx, &cy, &z, &ok) || !ok || !std::isfinite(cx) ||
            !std::isfinite(cy))
            return ss_ctx_error(g->ctx, SS_ERR_ARGUMENT,
                           "cell position (%g, %g) at x %.3f, y %.3f cannot be taken to "
                           "longitude/latitude: %s",
                           col, row, x, y, ss_gdal_message());
        x = cx;
        y = cy;
    }
    double lat = y * g->deg_per_unit;
    /* The DEM's georeferencing put it there: an input the DEM cannot be. */
    if (!(std::fabs(lat) <= 90.0 + POLE_SLACK_DEG))
        return ss_ctx_error(g->ctx, SS_ERR_INPUT,
                       "cell position (%g, %g) lies beyond a pole (latitude %.9g)", col, row, lat);
    *lat_deg = std::fmax(-90.0, std::fmin(90.0, lat));
    *lon_deg = Math::AngNormalize(x * g->deg_per_unit + g->pm_deg);
    return SS_OK;
}

/* Ground vectors (east, north; metres) of one column step and one row step
 * at a position, and the lon/lat there. */
typedef struct {
    double lon_deg, lat_deg;
    double col_en[2], row_en[2];
} local_frame;

static ss_status frame_at(ss_geo *g, double col, double row, local_frame *f)
{
    ss_status st = to_lonlat(g, col, row, &f->lon_deg, &f->lat_deg);
    if (st != SS_OK)
        return st;
    if (!g->to_geog) {
        /* Lat/lon grid: the metric is exact, dE = N cos(phi) dlambda, dN = M dphi. */
        const double rad = Math::pi() / 180.0 * g->deg_per_unit;
        double n_m = g->ellipsoid.TransverseCurvatureRadius(f->lat_deg);
        double m_m = g->ellipsoid.MeridionalCurvatureRadius(f->lat_deg);
        double cphi = Math::cosd(f->lat_deg);
        f->col_en[0] = n_m * cphi * g->gt[1] * rad;
        f->col_en[1] = m_m * g->gt[4] * rad;
        f->row_en[0] = n_m * cphi * g->gt[2] * rad;
        f->row_en[1] = m_m * g->gt[5] * rad;
        return SS_OK;
    }
    /* Any projection: central differences of Earth-centred positions, turned
     * into east/north at the point. Chords avoid the longitude wrap at the
     * antimeridian and stay defined at a pole, where east/north follow the
     * frame of the longitude the transformation returns there. */
    const double h = g->fd_step_cells;
    const double offsets[2][2] = {{h, 0}, {0, h}};
    for (int k = 0; k < 2; ++k) {
        double p[2][3];
        for (int s = 0; s < 2; ++s) {
            double sign = s ? 1.0 : -1.0, lon, lat;
            st = to_lonlat(g, col + sign * offsets[k][0], row + sign * offsets[k][1], &lon, &lat);
            if (st != SS_OK)
                return st;
            g->geocentric.Forward(lat, lon, 0.0, p[s][0], p[s][1], p[s][2]);
        }
        double d[3], enu[3];
        for (int i = 0; i < 3; ++i)
            d[i] = (p[1][i] - p[0][i]) / (2.0 * h);
        rotate_to_enu(f->lat_deg, f->lon_deg, d, enu);
        double *out = k == 0 ? f->col_en : f->row_en;
        /* The chord dips below the horizontal by ~step/R; its length is the
         * ground length to ~(step/R)^2. */
        double scale = std::sqrt(enu[0] * enu[0] + enu[1] * enu[1] + enu[2] * enu[2]) /
                       std::hypot(enu[0], enu[1]);
        out[0] = enu[0] * scale;
        out[1] = enu[1] * scale;
    }
    return SS_OK;
}

static ss_status open_geo(ss_ctx *ctx, const char *crs_wkt, const double geotransform[6], int width,
                          int height, ss_geo **out)
{
    quiet_gdal quiet;
    OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
    if (!srs)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory opening the CRS");
    char *wkt = const_cast<char *>(crs_wkt); /* OSRImportFromWkt only advances it */
    if (OSRImportFromWkt(srs, &wkt) != OGRERR_NONE) {
        OSRDestroySpatialReference(srs);
        return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot read the DEM's CRS: %s", ss_gdal_message());
    }
    int geographic = OSRIsGeographic(srs);
    if (!geographic && !OSRIsProjected(srs)) {
        OSRDestroySpatialReference(srs);
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                       "the DEM's CRS is neither geographic nor projected: its cells cannot be "
                       "placed on the Earth");
    }
    OGRErr err_a = OGRERR_NONE, err_f = OGRERR_NONE;
    double a_m = OSRGetSemiMajor(srs, &err_a);
    double inv_f = OSRGetInvFlattening(srs, &err_f);
    if (err_a != OGRERR_NONE || err_f != OGRERR_NONE || !(a_m > 0) || !std::isfinite(inv_f)) {
        a_m = GeographicLib::Constants::WGS84_a();
        inv_f = 1.0 / GeographicLib::Constants::WGS84_f();
    }
    /* GDAL gives 1/f = 0 for a sphere. */
    double f = inv_f == 0.0 ? 0.0 : 1.0 / inv_f;
    ss_geo *g;
    try {
        g = new ss_geo(ctx, a_m, f);
    } catch (...) {
        OSRDestroySpatialReference(srs);
        throw;
    }
    g->srs = srs;
    g->width = width;
    g->height = height;
    for (int i = 0; i < 6; ++i)
        g->gt[i] = geotransform[i];
    OSRSetAxisMappingStrategy(srs, OAMS_TRADITIONAL_GIS_ORDER);
    g->geog = OSRCloneGeogCS(srs);
    if (!g->geog) {
        delete g;
        return ss_ctx_error(ctx, SS_ERR_INPUT, "the DEM's CRS has no geographic CRS: %s",
                       ss_gdal_message());
    }
    OSRSetAxisMappingStrategy(g->geog, OAMS_TRADITIONAL_GIS_ORDER);
    double rad_per_unit = OSRGetAngularUnits(g->geog, nullptr);
    g->deg_per_unit = rad_per_unit * (180.0 / Math::pi());
    /* Keep degrees exact: the WKT's 0.0174532925199433 is pi/180 rounded. */
    if (std::fabs(g->deg_per_unit - 1.0) < 1e-12)
        g->deg_per_unit = 1.0;
    g->pm_deg = OSRGetPrimeMeridian(g->geog, nullptr);
    if (!geographic) {
        g->to_geog = OCTNewCoordinateTransformation(srs, g->geog);
        if (!g->to_geog) {
            delete g;
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                           "cannot transform the DEM's CRS to longitude/latitude: %s",
                           ss_gdal_message());
        }
        double pixel_m = std::sqrt(std::fabs(g->gt[1] * g->gt[5] - g->gt[2] * g->gt[4])) *
                         OSRGetLinearUnits(srs, nullptr);
        g->fd_step_cells = pixel_m > 0 && std::isfinite(pixel_m) ? FD_STEP_M / pixel_m : 1.0;
    }
    /* Refuse now a grid whose centre the transformation cannot place. */
    double lon, lat;
    ss_status st = to_lonlat(g, 0.5 * (width - 1), 0.5 * (height - 1), &lon, &lat);
    if (st != SS_OK) {
        delete g;
        char why[2048];
        snprintf(why, sizeof why, "%s", ss_ctx_message(ctx));
        return ss_ctx_error(ctx, SS_ERR_INPUT, "the DEM's grid cannot be placed on the Earth: %s", why);
    }
    *out = g;
    return SS_OK;
}

extern "C" {

ss_status ss_geo_open(ss_ctx *ctx, const char *crs_wkt, const double geotransform[6], int width,
                      int height, ss_geo **out)
{
    *out = nullptr;
    if (!crs_wkt || !*crs_wkt)
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                       "the DEM has no CRS: its cells cannot be placed on "
                       "the Earth");
    if (width < 1 || height < 1)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "grid size %d x %d is empty", width, height);
    for (int i = 0; i < 6; ++i)
        if (!std::isfinite(geotransform[i]))
            return ss_ctx_error(ctx, SS_ERR_INPUT, "geotransform term %d is not finite", i);
    double det = geotransform[1] * geotransform[5] - geotransform[2] * geotransform[4];
    if (det == 0.0)
        return ss_ctx_error(ctx, SS_ERR_INPUT, "the geotransform is singular (zero cell area)");
    return guarded(ctx, SS_ERR_INPUT, "opening the DEM's georeferencing",
                   [&] { return open_geo(ctx, crs_wkt, geotransform, width, height, out); });
}

void ss_geo_close(ss_geo *geo)
{
    delete geo;
}

int ss_geo_is_geographic(const ss_geo *geo)
{
    return geo->to_geog == nullptr;
}

void ss_geo_ellipsoid(const ss_geo *geo, double *a_m, double *f)
{
    *a_m = geo->geodesic.EquatorialRadius();
    *f = geo->geodesic.Flattening();
}

ss_status ss_geo_lonlat(ss_geo *geo, double col, double row, double *lon_deg, double *lat_deg)
{
    return guarded(geo->ctx, SS_ERR_ARGUMENT, "longitude/latitude of a cell",
                   [&] { return to_lonlat(geo, col, row, lon_deg, lat_deg); });
}

ss_status ss_geo_grid_north(ss_geo *geo, double col, double row, double *true_azimuth_deg)
{
    return guarded(geo->ctx, SS_ERR_ARGUMENT, "grid north of a cell", [&] {
        local_frame f;
        ss_status st = frame_at(geo, col, row, &f);
        if (st != SS_OK)
            return st;
        if (!(std::hypot(f.row_en[0], f.row_en[1]) > 0))
            return ss_ctx_error(geo->ctx, SS_ERR_ARGUMENT,
                           "the grid's rows have no extent at cell position (%g, %g)", col, row);
        /* "Up" is toward decreasing row. */
        *true_azimuth_deg = Math::atan2d(-f.row_en[0], -f.row_en[1]);
        return SS_OK;
    });
}

ss_status ss_geo_cell_size(ss_geo *geo, double col, double row, double *dx_m, double *dy_m)
{
    return guarded(geo->ctx, SS_ERR_ARGUMENT, "cell size", [&] {
        local_frame f;
        ss_status st = frame_at(geo, col, row, &f);
        if (st != SS_OK)
            return st;
        *dx_m = std::hypot(f.col_en[0], f.col_en[1]);
        *dy_m = std::hypot(f.row_en[0], f.row_en[1]);
        return SS_OK;
    });
}

double ss_geo_earth_radius_m(const ss_geo *geo, double lat_deg)
{
    /* Both radii are plain formulas; out-of-range latitudes give NaN. */
    return std::sqrt(geo->ellipsoid.MeridionalCurvatureRadius(lat_deg) *
                     geo->ellipsoid.TransverseCurvatureRadius(lat_deg));
}

ss_status ss_geo_inverse(const ss_geo *geo, double lat1_deg, double lon1_deg, double lat2_deg,
                         double lon2_deg, double *dist_m, double *azi1_deg)
{
    return guarded(geo->ctx, SS_ERR_ARGUMENT, "geodesic", [&] {
        if (!valid_lat(lat1_deg) || !valid_lat(lat2_deg) || !std::isfinite(lon1_deg) ||
            !std::isfinite(lon2_deg))
            return ss_ctx_error(geo->ctx, SS_ERR_ARGUMENT,
                           "geodesic between (%g, %g) and (%g, %g): latitudes must lie in "
                           "[-90, 90] and longitudes be finite",
                           lat1_deg, lon1_deg, lat2_deg, lon2_deg);
        double azi2_deg;
        geo->geodesic.Inverse(lat1_deg, lon1_deg, lat2_deg, lon2_deg, *dist_m, *azi1_deg, azi2_deg);
        return SS_OK;
    });
}

void ss_geo_ecef_to_enu(double lat_deg, double lon_deg, const double ecef_dir[3], double enu_dir[3])
{
    rotate_to_enu(lat_deg, lon_deg, ecef_dir, enu_dir);
}

ss_status ss_geo_sun_local(const ss_geo *geo, double lat_deg, double lon_deg, double height_m,
                           const double sun_ecef_dir[3], double sun_dist_au, double *azimuth_deg,
                           double *elevation_deg)
{
    return guarded(geo->ctx, SS_ERR_ARGUMENT, "sun position", [&] {
        double norm =
            std::sqrt(sun_ecef_dir[0] * sun_ecef_dir[0] + sun_ecef_dir[1] * sun_ecef_dir[1] +
                      sun_ecef_dir[2] * sun_ecef_dir[2]);
        if (!valid_lat(lat_deg) || !std::isfinite(lon_deg) || !std::isfinite(height_m))
            return ss_ctx_error(geo->ctx, SS_ERR_ARGUMENT,
                           "sun position at (%g, %g, %g m): latitude must lie in [-90, 90]",
                           lat_deg, lon_deg, height_m);
        if (!(norm > 0) || !std::isfinite(norm) || !(sun_dist_au > 0) ||
            !std::isfinite(sun_dist_au))
            return ss_ctx_error(geo->ctx, SS_ERR_ARGUMENT,
                           "sun direction must be a finite non-zero vector and its distance "
                           "positive (got %g AU)",
                           sun_dist_au);
        double observer[3];
        geo->geocentric.Forward(lat_deg, lon_deg, height_m, observer[0], observer[1], observer[2]);
        double sun_m = sun_dist_au * AU_M / norm, v[3], enu[3];
        for (int i = 0; i < 3; ++i)
            v[i] = sun_ecef_dir[i] * sun_m - observer[i];
        rotate_to_enu(lat_deg, lon_deg, v, enu);
        double az = Math::atan2d(enu[0], enu[1]);
        *azimuth_deg = az < 0 ? az + 360.0 : az;
        *elevation_deg = Math::atan2d(enu[2], std::hypot(enu[0], enu[1]));
        return SS_OK;
    });
}

ss_status ss_geo_extent_summary(ss_geo *geo, ss_geo_summary *out)
{
    return guarded(geo->ctx, SS_ERR_ARGUMENT, "grid summary", [&] {
        ss_geo_summary s = {};
        const double w = geo->width, h = geo->height;
        const double corners[4][2] = {
            {-0.5, -0.5}, {w - 0.5, -0.5}, {w - 0.5, h - 0.5}, {-0.5, h - 0.5}};
        for (int i = 0; i < 4; ++i) {
            ss_status st = to_lonlat(geo, corners[i][0], corners[i][1], &s.corner_lon_deg[i],
                                     &s.corner_lat_deg[i]);
            if (st != SS_OK)
                return st;
        }
        const double c_col = 0.5 * (w - 1), c_row = 0.5 * (h - 1);
        ss_status st = to_lonlat(geo, c_col, c_row, &s.centre_lon_deg, &s.centre_lat_deg);
        if (st == SS_OK)
            st = ss_geo_grid_north(geo, c_col, c_row, &s.grid_north_centre_deg);
        if (st != SS_OK)
            return st;
        s.grid_north_min_deg = s.grid_north_max_deg = s.grid_north_centre_deg;
        s.dx_min_m = s.dy_min_m = INFINITY;
        s.dx_max_m = s.dy_max_m = 0;
        /* A 9 x 9 lattice of cell centres, then 33 points along each edge,
         * where a projection's distortion peaks. */
        const int lattice = 9, edge = 33, n_points = lattice * lattice + 4 * edge;
        for (int p = 0; p < n_points; ++p) {
            double col, row;
            if (p < lattice * lattice) {
                col = (p % lattice) * (w - 1) / (lattice - 1);
                row = (p / lattice) * (h - 1) / (lattice - 1);
            } else {
                int q = p - lattice * lattice, side = q / edge, k = q % edge;
                double t = (double)k / (edge - 1);
                col = side < 2 ? t * (w - 1) : (side == 2 ? 0 : w - 1);
                row = side < 2 ? (side == 0 ? 0 : h - 1) : t * (h - 1);
            }
            double gn, dx, dy;
            st = ss_geo_grid_north(geo, col, row, &gn);
            if (st == SS_OK)
                st = ss_geo_cell_size(geo, col, row, &dx, &dy);
            if (st != SS_OK)
                return st;
            gn = s.grid_north_centre_deg + Math::AngDiff(s.grid_north_centre_deg, gn);
            s.grid_north_min_deg = std::fmin(s.grid_north_min_deg, gn);
            s.grid_north_max_deg = std::fmax(s.grid_north_max_deg, gn);
            s.dx_min_m = std::fmin(s.dx_min_m, dx);
            s.dx_max_m = std::fmax(s.dx_max_m, dx);
            s.dy_min_m = std::fmin(s.dy_min_m, dy);
            s.dy_max_m = std::fmax(s.dy_max_m, dy);
        }
        if (!(s.dx_min_m > 0) || !(s.dy_min_m > 0))
            return ss_ctx_error(geo->ctx, SS_ERR_INPUT,
                           "the grid has cells of zero ground size (a row on a pole)");
        s.cell_variation = std::fmax(s.dx_max_m / s.dx_min_m, s.dy_max_m / s.dy_min_m) - 1.0;
        for (int i = 0; i < 2; ++i) {
            double d_m, azi_deg;
            st = ss_geo_inverse(geo, s.corner_lat_deg[i], s.corner_lon_deg[i],
                                s.corner_lat_deg[i + 2], s.corner_lon_deg[i + 2], &d_m, &azi_deg);
            if (st != SS_OK)
                return st;
            s.diagonal_m = std::fmax(s.diagonal_m, d_m);
        }
        s.centre_earth_radius_m = ss_geo_earth_radius_m(geo, s.centre_lat_deg);
        *out = s;
        return SS_OK;
    });
}

} /* extern "C" */
