/* skysweep horizon --point / --points: horizon profiles of sites (solar PV,
 * doc/pv-horizons.md) as CSV, JSON or a PVGIS user horizon, instead of
 * horizon rasters. */
#ifndef SS_CLI_HORIZON_POINTS_H
#define SS_CLI_HORIZON_POINTS_H

#include "skysweep_sites.h"
#include "run.h"
#include "site.h"
#include "trees.h"

/* csv and json hold every site in one file (or standard output); the others
 * are PV software's horizon files (horizon_formats.h), one per site. */
#define HORIZON_POINT_FORMATS "csv|json|pvgis|pvsyst|pvsol|helioscope|sam"
enum { POINT_FORMAT_CSV, POINT_FORMAT_JSON };
#define HORIZON_OF_CHOICES "solid|canopy"
enum { HORIZON_OF_SOLID, HORIZON_OF_CANOPY };

typedef struct {
    const char *point;     /* "X,Y": one site, WGS84 longitude,latitude unless --point-crs */
    const char *points;    /* CSV file of sites: id, lon (or x), lat (or y), optional height */
    const char *point_crs; /* CRS of site coordinates; "dem": the DEM's own */
    double step_deg;       /* azimuth step; 360 / step must be a whole number */
    double height_m;       /* observer above the ground, where a site gives none */
    int format;            /* index into HORIZON_POINT_FORMATS */
    const char *far;       /* terrain DEM for the far horizon, merged by the maximum */
    const tree_settings *trees; /* --canopy given: the crowns' profiles too; else NULL */
    int horizon_of;        /* index into "solid|canopy": the profile PV files hold */
} horizon_point_settings;

#define ID_MAX 200

typedef struct {
    char id[ID_MAX + 1];
    double x, y;     /* as given, in the sites' CRS */
    double height_m; /* observer above the ground */
    double lon_deg, lat_deg, ground_m;
} site_rec;

/* Reads a sites CSV (--points): a header naming id, lon (or x), lat (or y)
 * and optionally height, in any order; '#' lines and blank lines are
 * skipped. A regular file of at most 256 MiB (text_input.h). ids_as_files:
 * ids must name per-site files. *out (to be freed) holds *n_out >= 1 sites;
 * else the error is in ctx (SS_ERR_INPUT, SS_ERR_MEMORY). */
ss_status horizon_sites_read(ss_ctx *ctx, const char *path, double default_height_m,
                             int ids_as_files, site_rec **out, int *n_out);

/* Point mode of skysweep horizon. pos holds the DEM tiles and, when there
 * are two or more, OUTPUT last ("-": standard output; one DEM alone: the
 * profiles go to standard output). Returns the exit code. */
int horizon_points_run(const common_settings *common, const horizon_point_settings *pts,
                       const char **pos, int n_pos);

/* The terrain horizon of one site at any azimuth, computed exactly there
 * (skysweep sun --horizon-from). */
typedef struct {
    ss_ctx *ctx;
    ss_dem dem;
    ss_dem_frame frame;
    int have_dem;
    ss_site_frame *sf;
    ss_point_grid *pg;
    ss_point_site site;
    ss_sweep_options opt;
    double ground_m;
} site_horizon;

typedef struct {
    double height_m;     /* observer above the ground */
    int lines;           /* 0 interpolated, 1 digital */
    int curvature;       /* 0 off, 1 on (earth radius of the DEM's centre) */
    double refraction_k; /* with curvature */
} site_horizon_settings;

/* Reads the DEM and places the site (WGS84 degrees) on it; failures leave
 * their message in ctx, which must outlive sh. Close sh in any case. */
ss_status site_horizon_open(site_horizon *sh, ss_ctx *ctx, const char *dem_path, double lon_deg,
                            double lat_deg, const site_horizon_settings *set);
/* Horizon elevation (degrees) toward a true azimuth. */
ss_status site_horizon_at(site_horizon *sh, double azimuth_deg, double *elevation_deg);
/* What was used: "interpolated lines, earth curvature off, observer 0 m". */
void site_horizon_describe(const site_horizon *sh, char *buf, size_t size);
void site_horizon_close(site_horizon *sh);

#endif
