/* skysweep roofs: a solar cadastre per roof plane and per building from a
 * DSM, building footprints and a weather file (doc/roofs.md). The
 * footprints (any OGR source, reprojected, repaired or skipped one by one)
 * are rasterized onto the DSM's grid, each building's roof cells split into
 * planes (roof_planes.h), the per-cell yield is the insolation command's
 * run with --weather and --pv on the same DSM (the same code path, every
 * insolation option passed on), and the planes' unshaded irradiation
 * comes from the same sky model on the plane with no horizon. Results go
 * to a GeoPackage (layers buildings and roof_planes), and a CSV of the
 * planes on request. */
#include "config.h"

#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "commands.h"
#include "insolation_trees.h"
#include "mpi_share.h"
#include "roof_horizons.h"
#include "roof_panels.h"
#include "roof_planes.h"
#include "roof_shade.h"
#include "roofs_io.h"
#include "run.h"
#include "skysweep_sun.h"
#include "temporaries.h"
#include "temporary_name.h"
#include "weather.h"

typedef struct {
    common_settings common; /* first: common_options()' offsets are relative to it */
    ss_insolation_params ins;
    const char *weather, *weather_zone;
    int weather_far_ok;
    const char *buildings, *buildings_layer, *dtm, *csv, *id_field, *shade_masks, *cell_raster;
    double min_area_m2, max_angle_deg, tolerance_m, obstacle_m;
    double setback_m, min_irradiation, max_tilt_deg, max_off_equator_deg;
    const char *module_size;
    const char *horizon_dir;
    int horizon_format;
    int orientation, panels_layer, shade_table;
    double module_power_w, module_spacing_m, row_spacing_m, min_panel_area_m2;
    double flat_tilt_deg, rack_tilt_deg, rack_sun_elevation_deg;
    panel_options panel; /* from the above (settle_panel_options) */
    insolation_tree_settings trees; /* passed on to insolation */
} roofs_settings;

#define SET(field) offsetof(roofs_settings, field)
/* roofs' own options; the others go on to the insolation run. */
static const opt_spec own_options[] = {
    {"buildings", OPT_INPUT, SET(buildings), "FILE", NULL, 0, 0, NULL,
     "building footprints: any vector source OGR reads (Shapefile, GeoPackage, GeoJSON, "
     "OpenStreetMap .osm/.pbf, ...); reprojected to the DSM's CRS (required)"},
    {"buildings-layer", OPT_STRING, SET(buildings_layer), "NAME", NULL, 0, 0, NULL,
     "the layer of --buildings that holds the footprints (default: an OpenStreetMap file's "
     "areas tagged building, else the first layer of polygons)"},
    {"id-field", OPT_STRING, SET(id_field), "NAME", NULL, 0, 0, NULL,
     "the footprints' field that names each building (default: building_id or id where the "
     "layer has one, else the feature id)"},
    {"dtm", OPT_INPUT, SET(dtm), "FILE", NULL, 0, 0, NULL,
     "terrain heights on the DSM's grid: each building's height_m is its highest roof plane "
     "cell above the median ground under its footprint"},
    {"csv", OPT_OUTPUT, SET(csv), "FILE", NULL, 0, 0, NULL,
     "also write the roof planes' rows as CSV"},
    {"min-area", OPT_DOUBLE, SET(min_area_m2), "M2", "5", 0.01, 1e6, NULL,
     "smallest roof plane (true 3D area, m2); smaller regions are not planes"},
    {"plane-angle", OPT_DOUBLE, SET(max_angle_deg), "DEG", "8", 0.5, 45, NULL,
     "a cell joins a plane where its local normal (3 x 3 fit) lies within this angle"},
    {"plane-tolerance", OPT_DOUBLE, SET(tolerance_m), "M", "0.15", 0.001, 10, NULL,
     "a cell joins a plane where its height lies within this of the plane"},
    {"obstacle-height", OPT_DOUBLE, SET(obstacle_m), "M", "0.3", 0.01, 100, NULL,
     "cells of no plane higher than the nearest plane by more are obstacles (chimneys, dormers)"},
    {"setback", OPT_DOUBLE, SET(setback_m), "M", "0.5", 0, 100, NULL,
     "usable cells lie at least this far (horizontally) from their plane's edges and obstacles"},
    {"min-irradiation", OPT_DOUBLE, SET(min_irradiation), "KWH_M2", "700", 0, 5000, NULL,
     "usable cells receive at least this much in the weather file's year (kWh/m2)"},
    {"max-tilt", OPT_DOUBLE, SET(max_tilt_deg), "DEG", "60", 0, 90, NULL,
     "usable planes are tilted at most this much"},
    {"max-off-equator", OPT_DOUBLE, SET(max_off_equator_deg), "DEG", "180", 0, 180, NULL,
     "usable planes face at most this far (azimuth) from the equator: 90 keeps east through "
     "west by the equator's side; planes tilted under 1 degree face it (default 180: any "
     "orientation, left to --min-irradiation)"},
    {"module-size", OPT_STRING, SET(module_size), "LxW", "1.7x1.0", 0, 0, NULL,
     "the modules' long and short sides (m) of the panel layout"},
    {"module-power", OPT_DOUBLE, SET(module_power_w), "W", "400", 1, 5000, NULL,
     "a module's nameplate power (W, STC): kwp = panels x this"},
    {"orientation", OPT_CHOICE, SET(orientation), NULL, "best", 0, 0, "portrait|landscape|best",
     "modules' long side up the slope (portrait), along the rows (landscape), or whichever "
     "fits more modules on each plane (best)"},
    {"module-spacing", OPT_DOUBLE, SET(module_spacing_m), "M", "0.02", 0, 10, NULL,
     "gap between modules of a row (m)"},
    {"row-spacing", OPT_DOUBLE, SET(row_spacing_m), "M", "0.02", 0, 50, NULL,
     "gap between rows on the plane (m; on racked flat roofs the least gap)"},
    {"min-panel-area", OPT_DOUBLE, SET(min_panel_area_m2), "M2", "10", 0, 1e6, NULL,
     "a plane whose modules would cover less than this (m2 of modules) gets none"},
    {"flat-tilt", OPT_DOUBLE, SET(flat_tilt_deg), "DEG", "10", 0, 45, NULL,
     "planes tilted less are flat roofs: modules racked at --rack-tilt facing the equator"},
    {"rack-tilt", OPT_DOUBLE, SET(rack_tilt_deg), "DEG", "10", 0, 60, NULL,
     "tilt of the racks on flat roofs"},
    {"rack-sun-elevation", OPT_DOUBLE, SET(rack_sun_elevation_deg), "DEG", NULL, 1, 90, NULL,
     "racked rows are spaced so that none shades the next with the sun this high toward the "
     "equator (default: the noon sun at the winter solstice at the DSM's centre, 90 - |lat| - "
     "23.44, at least 5)"},
    {"panels", OPT_FLAG, SET(panels_layer), NULL, NULL, 0, 0, NULL,
     "also write the layer panels: each module's footprint on the ground"},
    {"shade-table", OPT_FLAG, SET(shade_table), NULL, NULL, 0, 0, NULL,
     "also write the table plane_shade: each plane's share in direct sun by month and hour "
     "(a shadow sweep per record with the sun up)"},
    {"shade-masks", OPT_OUTPUT, SET(shade_masks), "FILE", NULL, 0, 0, NULL,
     "also write every cell's hourly shade masks (Google's hourlyShade): a GeoTIFF of 288 "
     "UInt32 bands, month x hour, bit d - 1 set where the cell is sunlit at that hour of day d"},
    {"cell-raster", OPT_OUTPUT, SET(cell_raster), "FILE", NULL, 0, 0, NULL,
     "also keep the per-cell results the planes are summed from: the insolation run's GeoTIFF "
     "on the DSM's grid, every band with its name and unit (global kWh/m2 of the period and of "
     "each month, DC and AC PV yield per kWp, ...; doc/insolation.md)"},
    {"horizon-files", OPT_STRING, SET(horizon_dir), "DIR", NULL, 0, 0, NULL,
     "also write a horizon file for PV software per roof plane, seen from its centre, into "
     "this existing folder as BUILDING_PLANE.ext (doc/pv-horizons.md)"},
    {"horizon-format", OPT_CHOICE, SET(horizon_format), NULL, "pvgis", 0, 0,
     ROOF_HORIZON_FORMATS, "format of --horizon-files (as horizon --format)"},
    OPT_END};
static const opt_spec passed_on[] = {
    {"weather", OPT_INPUT, SET(weather), "FILE", NULL, 0, 0, NULL,
     "the weather records (EPW, TMY3, PVGIS, NSRDB PSM or CSV); --time selects records as for "
     "insolation (default: a clear sky, hourly over --time or the year 2025)"},
    {"weather-far-ok", OPT_FLAG, SET(weather_far_ok), NULL, NULL, 0, 0, NULL,
     "use a weather file whose site lies farther than 100 km from the DSM's centre (as for "
     "insolation)"},
    {"weather-zone", OPT_STRING, SET(weather_zone), "+HH:MM", NULL, 0, 0, NULL,
     "the zone the weather file's local stamps are in (as for insolation; needed for a "
     "UMEP/SUEWS met file)"},
    OPT_END};

/* ---- the insolation run ------------------------------------------------- */

/* Whether spec is one of roofs' own options. */
static int is_own(const opt_spec *spec)
{
    return spec >= own_options && spec < own_options + sizeof own_options / sizeof *own_options;
}

/* The option a command-line word names: its full name, or a prefix of
 * one alone (getopt_long_only's rule); NULL: none. */
static const opt_spec *named_option(const opt_spec *const *tables, const char *name)
{
    const opt_spec *exact = opt_find(tables, name), *only = NULL;
    int matches = 0;
    for (int t = 0; !exact && tables[t]; ++t)
        for (const opt_spec *o = tables[t]; o->name; ++o)
            if (strncmp(o->name, name, strlen(name)) == 0)
                matches++, only = o;
    return exact ? exact : matches == 1 ? only : NULL;
}

/* The insolation command line: every option given that is not roofs' own
 * (so the run is exactly `skysweep insolation --weather F --pv` with the
 * same options), then --pv, -q, GeoTIFF, the DSM tiles and the
 * intermediate raster; --weather CLEAR_SKY where roofs wrote the records
 * of a clear sky (NULL: the user's --weather is among the options).
 * Returns the count, or -1 where it does not fit. */
static int insolation_args(const opt_spec *const *tables, int argc, char **argv,
                           const char *clear_sky, const char *const *dsm, int n_dsm,
                           const char *raster, char **out, int max)
{
    int n = 0;
    out[n++] = "insolation";
    for (int i = 1; i < argc; ++i) {
        const char *t = argv[i];
        if (strcmp(t, "--") == 0)
            break; /* positionals only from here */
        if (t[0] != '-' || !t[1])
            continue; /* a positional: the DSM tiles and OUTPUT are added below */
        char name[64];
        const char *start = t + (t[1] == '-' ? 2 : 1);
        size_t len = strcspn(start, "=");
        snprintf(name, sizeof name, "%.*s", (int)(len < 63 ? len : 63), start);
        const opt_spec *spec = named_option(tables, name);
        int takes_value = spec && spec->type != OPT_FLAG && !start[len];
        if (!spec || !is_own(spec)) {
            if (n + 2 >= max)
                return -1;
            out[n++] = argv[i];
            if (takes_value && i + 1 < argc)
                out[n++] = argv[i + 1];
        }
        i += takes_value;
    }
    const char *tail[] = {"--pv", "-q", "-of", "GTiff"};
    if (n + 6 + n_dsm + 2 > max)
        return -1;
    if (clear_sky) { /* the clear sky's records roofs wrote (write_clear_sky) */
        out[n++] = "--weather";
        out[n++] = (char *)clear_sky;
    }
    for (int k = 0; k < 4; ++k)
        out[n++] = (char *)tail[k];
    for (int k = 0; k < n_dsm; ++k)
        out[n++] = (char *)dsm[k];
    out[n++] = (char *)raster;
    out[n] = NULL;
    return n;
}

/* Bands of the insolation raster roofs reads (cmd_insolation.c's order). */
#define BAND_GLOBAL 1
#define BAND_MONTHS 6
#define BAND_PV_DC 18
#define BAND_PV_AC 19

/* A window of the grid's rows [row0, row0 + rows) that holds whole
 * footprints (doc/roofs.md, "Scale"): the DSM's heights, the ground's
 * (--dtm) and the insolation run's results per cell. The grid's cell c is
 * element c - base. */
typedef struct {
    int row0, rows;
    size_t base, n; /* row0 x width; rows x width */
    const float *z; /* the DSM's heights (relative to z_origin_m) */
    float *z_read;  /* where a banded job reads them, else NULL (the job's whole grid) */
    float *dtm;     /* absolute ground heights (--dtm), else NULL */
    float *global;  /* kWh/m2 for the records */
    float *monthly; /* 12 planes of kWh/m2 */
    float *pv_dc;   /* kWh/kWp DC (after the system losses) */
    float *pv_ac;   /* kWh/kWp AC */
} roof_window;

/* Bytes a window holds per cell (roof_window; the DTM's counted always). */
#define WINDOW_CELL_BYTES (sizeof(float) * 17)

/* Runs insolation into a hidden neighbour raster (its path) of OUTPUT, or
 * of `kept` (--cell-raster), which write_outputs renames it to: the
 * windows read it back and close_run removes what is left. With --plan,
 * insolation prints its plan and nothing is kept. Returns the exit code
 * (0: done). */
static int run_insolation(sweep_job *job, const opt_spec *const *tables, int argc, char **argv,
                          const char *clear_sky, const char *kept, char *raster, size_t size)
{
    char dir[PATH_MAX], prefix[PATH_MAX];
    const char *beside = kept ? kept : job->output;
    if (!ss_temporary_prefix(beside, dir, prefix) ||
        (size_t)snprintf(raster, size, "%s/%sinsolation.tif", dir, prefix) >= size)
        return run_fail(&job->run, ss_ctx_error(job->run.ctx, SS_ERR_ARGUMENT,
                                                "output name '%s' is too long", beside));
    if (kept) /* its temporaries go if the run is stopped (temporaries.h) */
        ss_temporaries_track(kept);
    char *args[2 * 128 + COMMAND_MAX_INPUTS + 16];
    int n = insolation_args(tables, argc, argv, clear_sky, job->inputs, job->n_inputs, raster, args,
                            (int)(sizeof args / sizeof *args) - 1);
    if (n < 0)
        return run_fail(&job->run, ss_ctx_error(job->run.ctx, SS_ERR_ARGUMENT,
                                                "too many options to pass on to insolation"));
    int rc = cmd_insolation(n, args);
    if (rc != 0 || job->run.plan_only) /* --plan: insolation printed its plan */
        remove(raster);
    return rc;
}

/* ---- the planes with no horizon ------------------------------------------ */

/* The weather's records as insolation steps at the DSM's centre, in a
 * frame whose grid north is true north (the steps of the unshaded runs). */
typedef struct {
    ss_sun_step *steps;
    int n;
} sky_steps;

static ss_status step_at(ss_ctx *ctx, int index, ss_sun_step *step, void *user)
{
    (void)ctx;
    *step = ((const sky_steps *)user)->steps[index];
    return SS_OK;
}

static ss_status make_sky_steps(sweep_job *job, const roofs_settings *set, const ss_weather *w,
                                sky_steps *out)
{
    ss_ctx *ctx = job->run.ctx;
    ss_time_range range = {0};
    ss_status st = set->common.sun.time ? ss_parse_time_range(ctx, set->common.sun.time, &range)
                                        : SS_OK;
    out->steps = calloc(w->n ? w->n : 1, sizeof *out->steps);
    out->n = 0;
    if (st == SS_OK && !out->steps)
        st = command_out_of_memory(&job->run);
    ss_spa_params p;
    ss_sun_params_spa(&set->common.sun, &p);
    p.elevation_m = job->dem.grid.z_origin_m;
    for (size_t i = 0; st == SS_OK && i < w->n; ++i) {
        const ss_weather_record *rec = &w->records[i];
        if (set->common.sun.time &&
            !(rec->sun_unix_s >= range.start_unix_s && rec->sun_unix_s < range.end_unix_s))
            continue;
        ss_spa_result sun;
        st = ss_spa(ctx, rec->sun_unix_s, job->frame.centre_lat_deg, job->frame.centre_lon_deg,
                    &p, &sun);
        if (st != SS_OK)
            break;
        ss_sun_step *s = &out->steps[out->n++];
        ss_sun_step_clear_sky(&sun, sun.azimuth_deg, 0.0, rec->duration_h, 3.0,
                              set->ins.solar_constant, s);
        ss_civil_time local;
        ss_civil_from_unix(rec->sun_unix_s + w->utc_offset_h * 3600.0, &local);
        s->real_sky = 1;
        s->ghi_w_m2 = rec->ghi, s->dni_w_m2 = rec->dni, s->dhi_w_m2 = rec->dhi;
        s->albedo = rec->albedo;
        s->temp_air_c = rec->temp_air_c, s->wind_speed_m_s = rec->wind_speed_m_s;
        s->month = local.month;
    }
    return st;
}

/* ---- a clear sky, without --weather --------------------------------------- */

/* The clear sky's span where --time gives none: a calendar year (UTC). */
#define CLEAR_SKY_YEAR "2025-01-01T00:00Z/2026-01-01T00:00Z"
/* The most hours of clear sky (as insolation's most clear-sky steps). */
#define CLEAR_SKY_MAX_HOURS 100000.0

/* Without --weather, the records of a clear sky: one an hour of --time's
 * whole UTC hours (or CLEAR_SKY_YEAR's), each at the middle of its hour,
 * ESRA's irradiance for the sun at the DSM's centre (ss_clear_sky_record,
 * --linke's turbidity of the record's month, the DSM's height), as a plain
 * CSV beside OUTPUT at path, which the insolation run and the open planes
 * then read as any weather file: one code path for both skies. The records
 * give no air temperature or wind: the modules take --temp-air and
 * --wind-speed. note says which sky it was. */
static ss_status write_clear_sky(sweep_job *job, const roofs_settings *set, char *path,
                                 size_t size, char *note, size_t note_size)
{
    ss_ctx *ctx = job->run.ctx;
    char dir[PATH_MAX], prefix[PATH_MAX];
    if (!ss_temporary_prefix(job->output, dir, prefix) ||
        (size_t)snprintf(path, size, "%s/%sclear_sky.csv", dir, prefix) >= size)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "output name '%s' is too long", job->output);
    ss_time_range range = {0};
    double linke[12];
    ss_status st = ss_parse_time_range(ctx, set->common.sun.time ? set->common.sun.time
                                                                 : CLEAR_SKY_YEAR,
                                       &range);
    if (st == SS_OK)
        st = ss_insolation_params_linke(ctx, &set->ins, linke);
    double first = ceil(range.start_unix_s / 3600.0), end = floor(range.end_unix_s / 3600.0);
    if (st == SS_OK && !(end > first))
        st = ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                          "without --weather, --time must hold a whole hour (UTC): the clear "
                          "sky's records are hourly");
    if (st == SS_OK && end - first > CLEAR_SKY_MAX_HOURS)
        st = ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                          "without --weather, --time spans %.0f hours, more than %.0f of clear "
                          "sky",
                          end - first, CLEAR_SKY_MAX_HOURS);
    FILE *f = st == SS_OK ? fopen(path, "w") : NULL;
    if (st == SS_OK && !f)
        st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s'", path);
    if (f)
        fprintf(f, "time,ghi,dni,dhi\n");
    ss_spa_params p;
    ss_sun_params_spa(&set->common.sun, &p);
    p.elevation_m = job->dem.grid.z_origin_m;
    char stamp[40], until[40];
    for (double hour = first; f && st == SS_OK && hour < end; ++hour) {
        double t = hour * 3600.0 + 1800.0, ghi, dni, dhi;
        ss_spa_result sun;
        st = ss_spa(ctx, t, job->frame.centre_lat_deg, job->frame.centre_lon_deg, &p, &sun);
        if (st != SS_OK)
            break;
        ss_civil_time civil;
        ss_civil_from_unix(t, &civil);
        ss_sun_step step;
        ss_sun_step_clear_sky(&sun, sun.azimuth_deg, 0.0, 1.0, linke[civil.month - 1],
                              set->ins.solar_constant, &step);
        ss_clear_sky_record(&step, job->dem.grid.z_origin_m, &ghi, &dni, &dhi);
        ss_format_instant(t, stamp, sizeof stamp);
        fprintf(f, "%s,%.9g,%.9g,%.9g\n", stamp, ghi, dni, dhi);
    }
    int written = f && !ferror(f);
    if (f && fclose(f) != 0)
        written = 0;
    if (f && !written && st == SS_OK)
        st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s'", path);
    ss_format_instant(first * 3600.0, stamp, sizeof stamp);
    ss_format_instant(end * 3600.0, until, sizeof until);
    snprintf(note, note_size,
             "a clear sky (ESRA, Linke turbidity %s; no --weather), hourly from %s to %s, the "
             "modules in %g C air and %g m/s wind",
             set->ins.linke, stamp, until, set->ins.temp_air_c, set->ins.wind_speed_m_s);
    return st;
}

/* ---- per plane and per building ------------------------------------------- */

static const char *const month_abbr[12] = {"jan", "feb", "mar", "apr", "may", "jun",
                                           "jul", "aug", "sep", "oct", "nov", "dec"};

/* Suitability after sonnendach.ch's classes of annual irradiation. */
static int suitability_class(double kwh_m2)
{
    return !isfinite(kwh_m2) ? 0 : kwh_m2 < 800 ? 1 : kwh_m2 < 1000 ? 2 : kwh_m2 < 1200 ? 3
                                                   : kwh_m2 < 1400 ? 4
                                                                   : 5;
}
static const char *const class_names[6] = {"none", "low", "medium", "good", "very good",
                                           "excellent"};

typedef struct {
    size_t building;
    int number; /* 1.. within the building */
    roof_plane fit;
    double tilt_deg, azimuth_deg; /* true azimuth of the downslope direction */
    double centre_col, centre_row; /* the plane's cell nearest its mean (--horizon-files) */
    double area_m2, usable_area_m2, inner_area_m2;
    double kwh_m2_year, unshaded_kwh_m2_year, shading_loss_pct;
    double kwp, kwh_ac_year, kwh_dc_year, kwh_per_kwp, kwh_ac_month[12];
    int n_panels, racked, landscape;
    int shade_on_usable; /* the shade table counts its usable cells (else all its cells) */
    double panel_tilt_deg, panel_azimuth_deg; /* the modules' (racks': toward the equator) */
    void *geometry;
} plane_row;

/* A module of the layer panels. */
typedef struct {
    size_t plane; /* index of its plane_row */
    int number;   /* 1.. within the plane */
    double kwh_ac_year;
    void *geometry;
} panel_row;

typedef struct {
    double roof_area_m2, usable_area_m2, obstacle_area_m2, footprint_area_m2;
    double kwp, kwh_ac_year, kwh_dc_year, kwh_ac_month[12];
    int n_panels;
    double inner_area_m2, inner_kwh, inner_unshaded_kwh; /* for the mean and the loss */
    double height_m;
    int n_planes;
} building_sums;

/* What a plane's panel layout reads. */
typedef struct {
    const sweep_job *job;
    const roofs_settings *set;
    const ss_footprint *fp;
    const roof_window *win;
} roofs_run_view;

/* Whether window cell (c, r) of plane p lies at least setback from every
 * cell that is not p's (outside the building's window included). */
static int clear_of_edges(const int *plane_at, int cols, int rows, int c, int r, int p,
                          double setback_m, double cx, double cy)
{
    int reach_c = (int)ceil(setback_m / cx + 0.5), reach_r = (int)ceil(setback_m / cy + 0.5);
    for (int dr = -reach_r; dr <= reach_r; ++dr)
        for (int dc = -reach_c; dc <= reach_c; ++dc) {
            int cc = c + dc, rr = r + dr;
            int other = cc < 0 || rr < 0 || cc >= cols || rr >= rows || plane_at[rr * cols + cc] != p;
            double d = hypot(fmax(0.0, fabs((double)dc) - 0.5) * cx,
                             fmax(0.0, fabs((double)dr) - 0.5) * cy);
            if (other && d < setback_m)
                return 0;
        }
    return 1;
}

/* How far azimuth (clockwise from true north) turns from the equator's
 * direction at latitude lat: 0 facing it, 180 facing the pole. */
static double off_equator_deg(double azimuth_deg, double lat_deg)
{
    return fabs(fmod(azimuth_deg - (lat_deg >= 0 ? 180.0 : 0.0) + 540.0, 360.0) - 180.0);
}

/* Plane p's sums over its cells (label p, p + 1 in plane_at): the inner
 * ones (clear of the edges) give its irradiation; the usable ones (inner,
 * bright enough, not too steep, not facing too far from the equator) its
 * usable area, and are marked 1 in
 * usable (the building's window, zeroed by the caller). */
static void plane_irradiation(const sweep_job *job, const roofs_settings *set,
                              const roof_window *y, const ss_footprint *fp, const int *label,
                              const int *plane_at, int p, plane_row *row, unsigned char *usable)
{
    double cx = job->dem.grid.cell_x_m, cy = job->dem.grid.cell_y_m;
    double cell_m2 = cx * cy / cos(row->tilt_deg * M_PI / 180.0);
    double inner_kwh = 0;
    size_t n_inner = 0, n_usable = 0, n_all = 0;
    double all_kwh = 0;
    for (size_t i = 0; i < fp->n_cells; ++i) {
        if (label[i] != p)
            continue;
        int cell = fp->cells[i], width = job->dem.grid.width;
        double g = y->global[cell - y->base];
        if (!isfinite(g) || g < 0)
            continue;
        n_all++, all_kwh += g;
        int c = cell % width - fp->col0, r = cell / width - fp->row0;
        if (!clear_of_edges(plane_at, fp->cols, fp->rows, c, r, p + 1, set->setback_m, cx, cy))
            continue;
        n_inner++, inner_kwh += g;
        if (g < set->min_irradiation || row->tilt_deg > set->max_tilt_deg ||
            off_equator_deg(row->azimuth_deg, job->frame.centre_lat_deg) >
                set->max_off_equator_deg ||
            !isfinite(y->pv_ac[cell - y->base]) || y->pv_ac[cell - y->base] < 0)
            continue;
        n_usable++;
        usable[r * fp->cols + c] = 1;
    }
    row->area_m2 = (double)row->fit.n_cells * cell_m2;
    row->inner_area_m2 = (double)n_inner * cell_m2;
    row->usable_area_m2 = (double)n_usable * cell_m2;
    /* the plane's irradiation over its inner cells (its edges' slopes mix
     * the eaves' and ridges' neighbours); all its cells where none is inner */
    row->kwh_m2_year = n_inner ? inner_kwh / (double)n_inner
                       : n_all ? all_kwh / (double)n_all
                               : NAN;
}

/* The layout of orientation `landscape` on a plane's usable cells. */
static int lay_panels(const roofs_run_view *v, const plane_row *row, int landscape,
                      const unsigned char *usable, panel_layout *l, panel_geometry *g)
{
    const ss_dem_frame *fr = &v->job->frame;
    double equator = (fr->centre_lat_deg >= 0 ? 180.0 : 0.0) - fr->grid_north_deg;
    *g = panel_geometry_on(&v->set->panel, landscape, row->tilt_deg, row->fit.aspect_grid_deg,
                           equator);
    return panels_lay(g, usable, v->fp->cols, v->fp->rows, v->job->dem.grid.cell_x_m,
                      v->job->dem.grid.cell_y_m, l);
}

/* Plane row's modules on its usable cells (the orientation asked, or the
 * one that fits more, portrait on a tie); none below the minimum panel
 * area. kwp is their nameplate; each module yields its kWp x the mean AC
 * kWh/kWp of the cells it overlaps; the months share the year as the
 * modules' cells share their irradiation. Returns 0, or -1 out of memory. */
static int plane_panels(const roofs_run_view *v, plane_row *row, const unsigned char *usable,
                        panel_layout *l)
{
    const panel_options *o = &v->set->panel;
    panel_geometry g;
    int landscape = o->orientation == PANELS_LANDSCAPE;
    if (lay_panels(v, row, landscape, usable, l, &g) < 0)
        return -1;
    if (o->orientation == PANELS_BEST) {
        size_t portrait = l->n;
        if (lay_panels(v, row, 1, usable, l, &g) < 0)
            return -1;
        if (l->n <= portrait && lay_panels(v, row, 0, usable, l, &g) < 0)
            return -1;
    }
    if ((double)l->n * o->length_m * o->width_m < o->min_panel_area_m2)
        l->n = 0;
    const ss_footprint *fp = v->fp;
    int width = v->job->dem.grid.width;
    const roof_window *y = v->win;
    double kw = o->power_w / 1000.0, poa = 0, month[12] = {0};
    row->n_panels = (int)l->n;
    row->racked = g.racked, row->landscape = g.landscape;
    row->panel_tilt_deg = g.tilt_deg;
    row->panel_azimuth_deg = fmod(fmod(g.facing_grid_deg + v->job->frame.grid_north_deg, 360.0) +
                                      360.0,
                                  360.0);
    row->kwp = (double)l->n * kw;
    row->kwh_ac_year = 0;
    row->kwh_dc_year = 0;
    for (size_t k = 0; k < l->n; ++k) {
        panel_place *p = &l->items[k];
        double ac = 0, dc = 0, g_sum = 0;
        for (int i = 0; i < p->n_cells; ++i) {
            int w = l->cells[p->first + (size_t)i];
            size_t cell = (size_t)(fp->row0 + w / fp->cols) * (size_t)width +
                          (size_t)(fp->col0 + w % fp->cols) - y->base;
            ac += y->pv_ac[cell];
            dc += y->pv_dc[cell];
            g_sum += y->global[cell];
            for (int m = 0; m < 12; ++m)
                month[m] += y->monthly[(size_t)m * y->n + cell] / p->n_cells;
        }
        p->kwh_ac_year = kw * ac / p->n_cells;
        row->kwh_ac_year += p->kwh_ac_year;
        row->kwh_dc_year += kw * dc / p->n_cells;
        poa += g_sum / p->n_cells;
    }
    row->kwh_per_kwp = row->kwp > 0 ? row->kwh_ac_year / row->kwp : NAN;
    for (int m = 0; m < 12; ++m)
        row->kwh_ac_month[m] = poa > 0 ? row->kwh_ac_year * month[m] / poa : 0;
    return 0;
}

/* ---- outputs --------------------------------------------------------------- */

#define PLANE_FIELDS 33
#define BUILDING_FIELDS 31
#define PANEL_FIELDS 7
#define SHADE_FIELDS 7
static ss_field plane_fields[PLANE_FIELDS], building_fields[BUILDING_FIELDS],
    panel_fields[PANEL_FIELDS], shade_fields[SHADE_FIELDS];
static char month_names[2][12][24];

static int common_fields(ss_field *f, int n, int slot)
{
    f[n++] = (ss_field){"usable_area_m2", SS_FIELD_REAL, "m2",
                        "true (3D) area of the usable cells: clear of edges and obstacles by the "
                        "setback, at least the minimum irradiation, tilt at most the maximum"};
    f[n++] = (ss_field){"n_panels", SS_FIELD_INT, "", "modules laid on the usable cells"};
    f[n++] = (ss_field){"kwp", SS_FIELD_REAL, "kWp", "n_panels x the module's power"};
    f[n++] = (ss_field){"kwh_ac_year", SS_FIELD_REAL, "kWh/year",
                        "AC energy of the modules: each its kWp x the mean AC kWh/kWp of the "
                        "cells it covers (PVWatts, as insolation --pv)"};
    f[n++] = (ss_field){"kwh_dc_year", SS_FIELD_REAL, "kWh/year",
                        "DC energy of the modules, after the system losses, before the inverter: "
                        "each its kWp x the mean DC kWh/kWp of the cells it covers (insolation "
                        "--pv's pv_yield)"};
    f[n++] = (ss_field){"kwh_per_kwp", SS_FIELD_REAL, "kWh/kWp/year", "kwh_ac_year / kwp"};
    for (int m = 0; m < 12; ++m) {
        snprintf(month_names[slot][m], sizeof month_names[slot][m], "kwh_ac_%s", month_abbr[m]);
        f[n++] = (ss_field){month_names[slot][m], SS_FIELD_REAL, "kWh/month",
                            "the month's share of kwh_ac_year (as its share of the modules' "
                            "cells' irradiation)"};
    }
    f[n++] = (ss_field){"kwh_m2_year", SS_FIELD_REAL, "kWh/m2/year",
                        "mean irradiation on the roof (its cells clear of edges by the setback)"};
    f[n++] = (ss_field){"unshaded_kwh_m2_year", SS_FIELD_REAL, "kWh/m2/year",
                        "the same surface with no horizon (no shade, sky to the horizontal)"};
    f[n++] = (ss_field){"shading_loss_pct", SS_FIELD_REAL, "%",
                        "100 x (1 - kwh_m2_year / unshaded_kwh_m2_year)"};
    f[n++] = (ss_field){"class", SS_FIELD_TEXT, "",
                        "suitability by kwh_m2_year (sonnendach.ch): low < 800, medium < 1000, "
                        "good < 1200, very good < 1400, excellent"};
    f[n++] = (ss_field){"class_code", SS_FIELD_INT, "", "1 low .. 5 excellent"};
    return n;
}

static void define_fields(void)
{
    int n = 0;
    ss_field *f = plane_fields;
    f[n++] = (ss_field){"building_id", SS_FIELD_TEXT, "", "the footprint's id field, else its "
                                                          "feature id"};
    f[n++] = (ss_field){"plane_id", SS_FIELD_INT, "", "1.. within the building"};
    f[n++] = (ss_field){"tilt_deg", SS_FIELD_REAL, "deg", "tilt from the horizontal"};
    f[n++] = (ss_field){"azimuth_deg", SS_FIELD_REAL, "deg",
                        "azimuth of the downslope direction, clockwise from true north (pvlib's "
                        "surface_azimuth); 180 (0 south of the equator) where tilt < 1"};
    f[n++] = (ss_field){"area_m2", SS_FIELD_REAL, "m2", "true (3D) area: planimetric / cos tilt"};
    f[n++] = (ss_field){"fit_rms_m", SS_FIELD_REAL, "m", "rms distance of its cells from the "
                                                          "plane"};
    n = common_fields(f, n, 0);
    f[n++] = (ss_field){"panel_tilt_deg", SS_FIELD_REAL, "deg",
                        "the modules' tilt: the plane's, or the racks' on a flat roof"};
    f[n++] = (ss_field){"panel_azimuth_deg", SS_FIELD_REAL, "deg",
                        "the way the modules face, clockwise from true north: the plane's, or "
                        "the equator on a flat roof"};
    f[n++] = (ss_field){"racked", SS_FIELD_INT, "", "1: a flat roof, modules on racks"};
    f[n++] = (ss_field){"landscape", SS_FIELD_INT, "",
                        "1: modules' long side along the rows, 0: up the slope (portrait)"};
    n = 0;
    f = panel_fields;
    f[n++] = (ss_field){"building_id", SS_FIELD_TEXT, "", "the footprint's id field, else its "
                                                          "feature id"};
    f[n++] = (ss_field){"plane_id", SS_FIELD_INT, "", "its roof plane"};
    f[n++] = (ss_field){"panel_id", SS_FIELD_INT, "", "1.. within the plane"};
    f[n++] = (ss_field){"tilt_deg", SS_FIELD_REAL, "deg", "the module's tilt"};
    f[n++] = (ss_field){"azimuth_deg", SS_FIELD_REAL, "deg",
                        "the way the module faces, clockwise from true north"};
    f[n++] = (ss_field){"kwp", SS_FIELD_REAL, "kWp", "the module's power"};
    f[n++] = (ss_field){"kwh_ac_year", SS_FIELD_REAL, "kWh/year",
                        "its kWp x the mean AC kWh/kWp of the cells it covers"};
    n = 0;
    f = shade_fields;
    f[n++] = (ss_field){"building_id", SS_FIELD_TEXT, "", "the footprint's id field, else its "
                                                          "feature id"};
    f[n++] = (ss_field){"plane_id", SS_FIELD_INT, "", "its roof plane"};
    f[n++] = (ss_field){"month", SS_FIELD_INT, "", "1..12, of the weather file's local time"};
    f[n++] = (ss_field){"hour", SS_FIELD_INT, "",
                        "0..23, the hour of the weather file's local (standard) time the "
                        "records' suns fall in"};
    f[n++] = (ss_field){"sun_fraction", SS_FIELD_REAL, "",
                        "share of the plane's cells in direct sun (sunlit, facing the sun), "
                        "averaged over the month's records of that hour; 0 at night"};
    f[n++] = (ss_field){"n_records", SS_FIELD_INT, "", "weather records averaged"};
    f[n++] = (ss_field){"usable_cells", SS_FIELD_INT, "",
                        "1: the plane's usable cells are counted, 0: all its cells (none "
                        "usable)"};
    n = 0;
    f = building_fields;
    f[n++] = (ss_field){"building_id", SS_FIELD_TEXT, "", "the footprint's id field, else its "
                                                          "feature id"};
    f[n++] = (ss_field){"partly_outside", SS_FIELD_INT, "", "1: part of the footprint lies "
                                                             "outside the DSM"};
    f[n++] = (ss_field){"repaired", SS_FIELD_INT, "", "1: invalid geometry made valid"};
    f[n++] = (ss_field){"n_planes", SS_FIELD_INT, "", "roof planes"};
    f[n++] = (ss_field){"footprint_area_m2", SS_FIELD_REAL, "m2", "cells of the footprint"};
    f[n++] = (ss_field){"area_m2", SS_FIELD_REAL, "m2", "true (3D) area of the roof planes"};
    f[n++] = (ss_field){"obstacle_area_m2", SS_FIELD_REAL, "m2", "planimetric area of obstacle "
                                                                 "cells"};
    f[n++] = (ss_field){"height_m", SS_FIELD_REAL, "m",
                        "highest roof-plane cell above the median ground (--dtm; null without)"};
    n = common_fields(f, n, 1);
}

static void plane_values(const plane_row *p, const char *building_id, ss_value *v)
{
    int n = 0;
    v[n++].text = building_id;
    v[n++].num = p->number;
    v[n++].num = p->tilt_deg;
    v[n++].num = p->azimuth_deg;
    v[n++].num = p->area_m2;
    v[n++].num = p->fit.rms_m;
    v[n++].num = p->usable_area_m2;
    v[n++].num = p->n_panels;
    v[n++].num = p->kwp;
    v[n++].num = p->kwh_ac_year;
    v[n++].num = p->kwh_dc_year;
    v[n++].num = p->kwh_per_kwp;
    for (int m = 0; m < 12; ++m)
        v[n++].num = p->kwh_ac_month[m];
    v[n++].num = p->kwh_m2_year;
    v[n++].num = p->unshaded_kwh_m2_year;
    v[n++].num = p->shading_loss_pct;
    int cls = suitability_class(p->kwh_m2_year);
    v[n++].text = class_names[cls];
    v[n++].num = cls ? cls : NAN;
    v[n++].num = p->panel_tilt_deg;
    v[n++].num = p->panel_azimuth_deg;
    v[n++].num = p->racked;
    v[n++].num = p->landscape;
}

static void building_values(const ss_footprint *fp, const building_sums *b, ss_value *v)
{
    int n = 0;
    v[n++].text = fp->id;
    v[n++].num = fp->partly_outside;
    v[n++].num = fp->repaired;
    v[n++].num = b->n_planes;
    v[n++].num = b->footprint_area_m2;
    v[n++].num = b->roof_area_m2;
    v[n++].num = b->obstacle_area_m2;
    v[n++].num = b->height_m;
    v[n++].num = b->usable_area_m2;
    v[n++].num = b->n_panels;
    v[n++].num = b->kwp;
    v[n++].num = b->kwh_ac_year;
    v[n++].num = b->kwh_dc_year;
    v[n++].num = b->kwp > 0 ? b->kwh_ac_year / b->kwp : NAN;
    for (int m = 0; m < 12; ++m)
        v[n++].num = b->kwh_ac_month[m];
    double mean = b->inner_area_m2 > 0 ? b->inner_kwh / b->inner_area_m2 : NAN;
    double unshaded = b->inner_area_m2 > 0 ? b->inner_unshaded_kwh / b->inner_area_m2 : NAN;
    v[n++].num = mean;
    v[n++].num = unshaded;
    v[n++].num = unshaded > 0 ? 100.0 * (1.0 - mean / unshaded) : NAN;
    int cls = suitability_class(mean);
    v[n++].text = class_names[cls];
    v[n++].num = cls ? cls : NAN;
}

/* A text as RFC 4180 quotes it (a quote doubled). */
static void write_csv_text(FILE *f, const char *text)
{
    fputc('"', f);
    for (const char *c = text; *c; ++c)
        fputs(*c == '"' ? "\"\"" : (char[2]){*c, 0}, f);
    fputc('"', f);
}

/* The planes as CSV, written to a temporary and renamed into place. */
static ss_status write_csv(ss_ctx *ctx, const char *path, const plane_row *rows, size_t n,
                           const ss_footprints *fps)
{
    char *tmp = ss_temporary_name(path, "tmp");
    FILE *f = tmp ? fopen(tmp, "w") : NULL;
    if (!f) {
        free(tmp);
        return ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s'", path);
    }
    ss_temporaries_track(path);
    for (int k = 0; k < PLANE_FIELDS; ++k)
        fprintf(f, "%s%s", k ? "," : "", plane_fields[k].name);
    fprintf(f, "\n");
    ss_value v[PLANE_FIELDS];
    for (size_t i = 0; i < n; ++i) {
        memset(v, 0, sizeof v);
        plane_values(&rows[i], fps->items[rows[i].building].id, v);
        for (int k = 0; k < PLANE_FIELDS; ++k) {
            fputs(k ? "," : "", f);
            if (plane_fields[k].type == SS_FIELD_TEXT)
                write_csv_text(f, v[k].text ? v[k].text : "");
            else if (isfinite(v[k].num))
                fprintf(f, "%.10g", v[k].num);
        }
        fprintf(f, "\n");
    }
    int ok = !ferror(f) & (fclose(f) == 0);
    ss_status st = SS_OK;
    if (!ok || !ss_temporaries_hold())
        st = ss_ctx_error(ctx, ok ? SS_ERR_CANCELLED : SS_ERR_OUTPUT, "cannot write '%s'", path);
    else {
        if (rename(tmp, path) != 0)
            st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot rename '%s' to '%s'", tmp, path);
        ss_temporaries_release();
    }
    if (st != SS_OK)
        remove(tmp);
    ss_temporaries_forget(path);
    free(tmp);
    return st;
}

/* ---- the run ---------------------------------------------------------------- */

typedef struct {
    roofs_settings set;
    sweep_job job;
    ss_footprints fps;
    ss_weather weather;
    char raster[PATH_MAX + 40]; /* the insolation run's, read back a window at a time */
    roof_window win;            /* the window of rows being worked on */
    int n_windows, most_rows;   /* windows worked in, and the rows of the largest */
    ss_dem dtm;                 /* --dtm, read a window at a time */
    ss_dem_source *dtm_src;
    sky_steps sky;
    plane_row *planes;
    size_t n_planes, cap_planes;
    building_sums *sums;
    panel_row *panels; /* with --panels */
    size_t n_panels, cap_panels;
    roof_shade shade;              /* planes in the order of planes */
    char clear_sky[PATH_MAX + 40]; /* without --weather: the clear sky's records ("": none) */
    char sky_note[400];            /* the sky the yield is summed under */
    double seconds_planes, seconds_panels, seconds_insolation, seconds_unshaded, seconds_shade;
    double seconds_write;
} roofs_run;

/* A banded job's height origin before any window is read: rows from the
 * first until one holds a height, as a whole read sets it (the windows'
 * heights and the DSM's height the sun is taken at are then the whole
 * grid's). */
static ss_status settle_origin(sweep_job *job)
{
    int width = job->dem.grid.width;
    float *row = malloc(sizeof(float) * (size_t)width);
    ss_status st = row ? SS_OK : command_out_of_memory(&job->run);
    int found = 0;
    for (int r = 0; st == SS_OK && !found && r < job->dem.grid.height; ++r) {
        st = job_read_rows(job, r, 1, row);
        for (int c = 0; st == SS_OK && c < width && !found; ++c)
            found = isfinite(row[c]);
    }
    free(row);
    return st;
}

/* The files' overlaps were refused when the options were parsed (every
 * file option is declared an input or an output, run_parse); what is left
 * is the CSV's and the masks' own check as existing outputs. */
static ss_status check_files(roofs_run *r)
{
    ss_status st = r->set.csv ? ss_output_check(r->job.run.ctx, r->set.csv) : SS_OK;
    if (st == SS_OK && r->set.shade_masks)
        st = ss_output_check(r->job.run.ctx, r->set.shade_masks);
    if (st == SS_OK && r->set.cell_raster)
        st = ss_output_check(r->job.run.ctx, r->set.cell_raster);
    return st;
}

/* Opens --dtm, on the DSM's grid, for the windows to read. */
static ss_status open_dtm(roofs_run *r)
{
    ss_dem_read_options o = {0};
    const char *paths[1] = {r->set.dtm};
    ss_status st = ss_dem_open(r->job.run.ctx, paths, 1, &o, &r->dtm, &r->dtm_src);
    if (st != SS_OK)
        return st;
    const ss_dem *s = &r->job.dem, *d = &r->dtm;
    int same = d->grid.width == s->grid.width && d->grid.height == s->grid.height;
    for (int k = 0; same && k < 6; ++k)
        same =
            fabs(d->geotransform[k] - s->geotransform[k]) <= 1e-6 * (1 + fabs(s->geotransform[k]));
    return same ? SS_OK
                : ss_ctx_error(r->job.run.ctx, SS_ERR_INPUT,
                               "--dtm '%s' must lie on the DSM's grid (size and geotransform)",
                               r->set.dtm);
}

static int by_float(const void *x, const void *y)
{
    float a = *(const float *)x, b = *(const float *)y;
    return (a > b) - (a < b);
}

/* Highest roof-plane cell above the median ground under the footprint. */
static double building_height(const roofs_run *r, const ss_footprint *fp, const int *label)
{
    float *ground = malloc(sizeof(float) * (fp->n_cells + 1));
    size_t n = 0;
    double top = -INFINITY;
    const roof_window *y = &r->win;
    for (size_t i = 0; ground && i < fp->n_cells; ++i) {
        size_t cell = (size_t)fp->cells[i] - y->base;
        if (isfinite(y->dtm[cell]))
            ground[n++] = y->dtm[cell];
        if (label[i] >= 0)
            top = fmax(top, y->z[cell] + r->job.dem.grid.z_origin_m);
    }
    if (n)
        qsort(ground, n, sizeof *ground, by_float);
    double h = n && isfinite(top) ? top - ground[n / 2] : NAN;
    free(ground);
    return h;
}

/* One building: its planes, their yield and polygons, and its sums. */
/* Keeps plane row's modules (layout l) for the layer panels. */
static ss_status keep_panels(roofs_run *r, size_t row, const ss_footprint *fp,
                             const panel_layout *l)
{
    if (r->n_panels + l->n > r->cap_panels) {
        size_t cap = 2 * (r->n_panels + l->n) + 64;
        panel_row *q = realloc(r->panels, cap * sizeof *q);
        if (!q)
            return command_out_of_memory(&r->job.run);
        r->panels = q, r->cap_panels = cap;
    }
    double cx = r->job.dem.grid.cell_x_m, cy = r->job.dem.grid.cell_y_m;
    for (size_t k = 0; k < l->n; ++k) {
        double col_row[4][2];
        for (int i = 0; i < 4; ++i) {
            col_row[i][0] = fp->col0 + l->items[k].corner[i][0] / cx;
            col_row[i][1] = fp->row0 - l->items[k].corner[i][1] / cy;
        }
        void *geometry = ss_polygon_of_grid_points(&r->job.dem, col_row, 4);
        if (!geometry)
            return command_out_of_memory(&r->job.run);
        r->panels[r->n_panels++] = (panel_row){row, (int)k + 1, l->items[k].kwh_ac_year,
                                               geometry};
    }
    return SS_OK;
}

/* Plane p's cells for the shade table (its usable ones, or all its cells
 * where none is usable), as grid cells into cells (fp->n_cells at most). */
static ss_status add_shade_plane(roofs_run *r, const ss_footprint *fp, const int *label, int p,
                                 const unsigned char *usable, plane_row *row, int *cells)
{
    int width = r->job.dem.grid.width, n = 0, n_all = 0;
    for (size_t i = 0; i < fp->n_cells; ++i) {
        int c = fp->cells[i] % width - fp->col0, rr = fp->cells[i] / width - fp->row0;
        if (label[i] == p && usable[rr * fp->cols + c])
            cells[n++] = fp->cells[i];
    }
    row->shade_on_usable = n > 0;
    for (size_t i = 0; n == 0 && i < fp->n_cells; ++i)
        if (label[i] == p)
            cells[n_all++] = fp->cells[i];
    return roof_shade_add_plane(&r->shade, row->tilt_deg, row->fit.aspect_grid_deg, cells,
                                n ? n : n_all) == 0
               ? SS_OK
               : command_out_of_memory(&r->job.run);
}

/* Room for n more plane rows (they grow with the planes found, not with
 * the footprints' cells: a city's would not fit). Returns 0, or -1. */
static int room_for_planes(roofs_run *r, size_t n)
{
    if (r->n_planes + n <= r->cap_planes)
        return 0;
    size_t cap = 2 * (r->n_planes + n) + 64;
    plane_row *p = realloc(r->planes, cap * sizeof *p);
    if (!p)
        return -1;
    r->planes = p, r->cap_planes = cap;
    return 0;
}

static ss_status do_building(roofs_run *r, size_t b, int *label, int *plane_at,
                             unsigned char *usable, panel_layout *layout, int *cells)
{
    const ss_footprint *fp = &r->fps.items[b];
    sweep_job *job = &r->job;
    const ss_grid *g = &job->dem.grid;
    roof_plane_options o = {r->set.min_area_m2, r->set.max_angle_deg, r->set.tolerance_m,
                            r->set.obstacle_m};
    double t0 = run_now();
    roof_plane *found;
    /* the footprint's cells in the window (cells is scratch until the planes') */
    for (size_t i = 0; i < fp->n_cells; ++i)
        cells[i] = (int)((size_t)fp->cells[i] - r->win.base);
    int n = roof_planes_find(r->win.z, g->width, g->cell_x_m, g->cell_y_m, fp->col0,
                             fp->row0 - r->win.row0, fp->cols, fp->rows, cells, fp->n_cells, &o,
                             &found, label);
    if (n < 0)
        return command_out_of_memory(&job->run);
    building_sums *s = &r->sums[b];
    memset(s, 0, sizeof *s);
    s->n_planes = n;
    s->footprint_area_m2 = (double)fp->n_cells * g->cell_x_m * g->cell_y_m;
    for (int k = 0; k < fp->cols * fp->rows; ++k)
        plane_at[k] = 0;
    for (size_t i = 0; i < fp->n_cells; ++i) {
        int c = fp->cells[i] % g->width - fp->col0, row = fp->cells[i] / g->width - fp->row0;
        plane_at[row * fp->cols + c] = label[i] >= 0 ? label[i] + 1 : 0;
        s->obstacle_area_m2 += label[i] == ROOF_OBSTACLE ? g->cell_x_m * g->cell_y_m : 0;
    }
    void **geoms = calloc((size_t)n + 1, sizeof *geoms);
    ss_status st = geoms && room_for_planes(r, (size_t)n) == 0
                       ? ss_polygons_of_labels(job->run.ctx, &job->dem, plane_at, fp->col0,
                                               fp->row0, fp->cols, fp->rows, n, geoms)
                       : command_out_of_memory(&job->run);
    r->seconds_planes += run_now() - t0;
    for (int p = 0; st == SS_OK && p < n; ++p) {
        plane_row *row = &r->planes[r->n_planes++];
        memset(row, 0, sizeof *row);
        row->building = b;
        row->number = p + 1;
        row->fit = found[p];
        row->tilt_deg = found[p].tilt_deg;
        double az = found[p].aspect_grid_deg + job->frame.grid_north_deg;
        az = fmod(fmod(az, 360.0) + 360.0, 360.0);
        row->azimuth_deg = row->tilt_deg < 1.0 ? (job->frame.centre_lat_deg >= 0 ? 180.0 : 0.0)
                                               : az;
        row->geometry = geoms[p];
        geoms[p] = NULL;
        roof_plane_centre(fp->cells, label, fp->n_cells, g->width, p, &row->centre_col,
                          &row->centre_row);
        memset(usable, 0, (size_t)fp->cols * (size_t)fp->rows);
        plane_irradiation(job, &r->set, &r->win, fp, label, plane_at, p, row, usable);
        roofs_run_view view = {job, &r->set, fp, &r->win};
        double t1 = run_now();
        if (plane_panels(&view, row, usable, layout) < 0)
            st = command_out_of_memory(&job->run);
        if (st == SS_OK && r->set.panels_layer)
            st = keep_panels(r, r->n_planes - 1, fp, layout);
        if (st == SS_OK)
            st = add_shade_plane(r, fp, label, p, usable, row, cells);
        r->seconds_panels += run_now() - t1;
        s->n_panels += row->n_panels;
        s->roof_area_m2 += row->area_m2;
        s->usable_area_m2 += row->usable_area_m2;
        s->kwp += row->kwp;
        s->kwh_ac_year += row->kwh_ac_year;
        s->kwh_dc_year += row->kwh_dc_year;
        for (int m = 0; m < 12; ++m)
            s->kwh_ac_month[m] += row->kwh_ac_month[m];
    }
    s->height_m = r->win.dtm ? building_height(r, fp, label) : NAN;
    for (int p = 0; geoms && p < n; ++p)
        ss_geometry_free(geoms[p]);
    free(geoms);
    free(found);
    return st;
}

/* ---- windows of rows (doc/roofs.md, "Scale") -------------------------------- */

static void free_window(roof_window *w)
{
    free(w->z_read);
    free(w->dtm);
    free(w->global);
    free(w->monthly);
    free(w->pv_dc);
    free(w->pv_ac);
    memset(w, 0, sizeof *w);
}

/* Room for windows of up to rows rows. */
static ss_status alloc_window(roofs_run *r, int rows)
{
    roof_window *w = &r->win;
    size_t n = (size_t)rows * (size_t)r->job.dem.grid.width + 1;
    w->global = malloc(sizeof(float) * n);
    w->monthly = malloc(sizeof(float) * n * 12);
    w->pv_dc = malloc(sizeof(float) * n);
    w->pv_ac = malloc(sizeof(float) * n);
    w->z_read = r->job.source ? malloc(sizeof(float) * n) : NULL;
    w->dtm = r->set.dtm ? malloc(sizeof(float) * n) : NULL;
    return w->global && w->monthly && w->pv_dc && w->pv_ac && (w->z_read || !r->job.source) &&
                   (w->dtm || !r->set.dtm)
               ? SS_OK
               : command_out_of_memory(&r->job.run);
}

/* Rows [row0, row0 + rows) into the window: the DSM's (read from its files
 * where the job holds it in bands), the ground's (--dtm) and the
 * insolation run's results. */
static ss_status read_window(roofs_run *r, int row0, int rows)
{
    roof_window *w = &r->win;
    sweep_job *job = &r->job;
    ss_ctx *ctx = job->run.ctx;
    int width = job->dem.grid.width, height = job->dem.grid.height;
    w->row0 = row0, w->rows = rows;
    w->base = (size_t)row0 * (size_t)width, w->n = (size_t)rows * (size_t)width;
    ss_status st = SS_OK;
    if (job->source)
        st = job_read_rows(job, row0, rows, w->z_read);
    w->z = job->source ? w->z_read : job->dem.grid.z + w->base;
    if (st == SS_OK && w->dtm) {
        st = ss_dem_source_read(ctx, r->dtm_src, &r->dtm, row0, rows, w->dtm);
        for (size_t i = 0; st == SS_OK && i < w->n; ++i)
            w->dtm[i] += (float)r->dtm.grid.z_origin_m;
    }
    const char *raster = r->raster;
    if (st == SS_OK)
        st = ss_raster_read_rows(ctx, raster, BAND_GLOBAL, 1, width, height, row0, rows, w->global);
    if (st == SS_OK)
        st = ss_raster_read_rows(ctx, raster, BAND_MONTHS, 12, width, height, row0, rows,
                                 w->monthly);
    if (st == SS_OK)
        st = ss_raster_read_rows(ctx, raster, BAND_PV_DC, 1, width, height, row0, rows, w->pv_dc);
    if (st == SS_OK)
        st = ss_raster_read_rows(ctx, raster, BAND_PV_AC, 1, width, height, row0, rows, w->pv_ac);
    return st;
}

/* The most rows a window may hold: the job's band where --memory keeps the
 * DSM in its files, else the grid's; a test hook (doc/roofs.md, "Scale")
 * makes windows of fewer rows on a DSM held whole, so that a small test
 * grid runs in several windows. */
static int window_rows(const roofs_run *r)
{
    int rows = r->job.source ? r->job.band_rows : r->job.dem.grid.height;
    const char *hook = getenv("SKYSWEEP_TEST_ROOF_WINDOW_ROWS");
    int test = hook ? atoi(hook) : 0;
    return test > 0 && test < rows ? test : rows;
}

/* Refuses, before the insolation run, what windows cannot do: a footprint
 * taller than a window, and what needs the whole grid held (the horizon
 * files' sweeps, the shade masks). */
static ss_status check_windows(roofs_run *r)
{
    ss_ctx *ctx = r->job.run.ctx;
    const char *memory = r->set.common.memory ? r->set.common.memory : "half the machine's memory";
    int most = window_rows(r);
    double row_mib = (double)r->job.dem.grid.width * (double)WINDOW_CELL_BYTES / 1048576.0;
    for (size_t b = 0; b < r->fps.n; ++b) {
        const ss_footprint *fp = &r->fps.items[b];
        /* bands of 256 rows and more come in whole 256-row strips */
        int need = fp->rows <= 256 ? fp->rows : 256 * ((fp->rows + 255) / 256);
        if (fp->rows > most)
            return ss_ctx_error(ctx, SS_ERR_MEMORY,
                                "the memory budget (%s) holds windows of %d rows, and footprint "
                                "'%s' spans %d: windows of %d rows need at least %.0f MiB more "
                                "--memory (doc/roofs.md)",
                                memory, most, fp->id, fp->rows, need,
                                ceil((need - most) * row_mib));
    }
    if (r->job.source && (r->set.horizon_dir || r->set.shade_masks))
        return ss_ctx_error(ctx, SS_ERR_MEMORY,
                            "%s needs the DSM held whole, and the memory budget (%s) keeps it "
                            "in its files: give more --memory or leave it out",
                            r->set.horizon_dir ? "--horizon-files" : "--shade-masks", memory);
    return SS_OK;
}

/* A footprint's first row and index. */
typedef struct {
    int row0;
    size_t index;
} footprint_start;

static int by_start(const void *x, const void *y)
{
    const footprint_start *a = x, *b = y;
    return a->row0 != b->row0 ? (a->row0 > b->row0) - (a->row0 < b->row0)
                              : (a->index > b->index) - (a->index < b->index);
}

static int by_index(const void *x, const void *y)
{
    const footprint_start *a = x, *b = y;
    return (a->index > b->index) - (a->index < b->index);
}

/* Puts the planes (with their modules and shade cells) in the order of
 * their buildings, as one window over the whole grid gives them: windows
 * take the buildings by their rows. Returns 0, or -1 out of memory. */
static int order_planes(roofs_run *r)
{
    size_t n = r->n_planes, nb = r->fps.n;
    size_t *next = calloc(nb + 1, sizeof *next), *to = malloc(sizeof *to * (n + 1));
    size_t *at = calloc(n + 1, sizeof *at);
    plane_row *planes = malloc(sizeof *planes * (n + 1));
    shade_plane *shade = malloc(sizeof *shade * (n + 1));
    panel_row *panels = malloc(sizeof *panels * (r->n_panels + 1));
    int ok = next && to && at && planes && shade && panels && r->shade.n_planes == n;
    for (size_t i = 0; ok && i < n; ++i)
        next[r->planes[i].building + 1]++;
    for (size_t b = 1; ok && b <= nb; ++b)
        next[b] += next[b - 1];
    for (size_t i = 0; ok && i < n; ++i) {
        to[i] = next[r->planes[i].building]++;
        planes[to[i]] = r->planes[i];
        shade[to[i]] = r->shade.planes[i];
    }
    /* the modules by their plane's new place, in their order within it */
    for (size_t k = 0; ok && k < r->n_panels; ++k)
        at[to[r->panels[k].plane] + 1]++;
    for (size_t i = 1; ok && i <= n; ++i)
        at[i] += at[i - 1];
    for (size_t k = 0; ok && k < r->n_panels; ++k) {
        panel_row p = r->panels[k];
        p.plane = to[p.plane];
        panels[at[p.plane]++] = p;
    }
    if (ok && n) {
        memcpy(r->planes, planes, sizeof *planes * n);
        memcpy(r->shade.planes, shade, sizeof *shade * n);
        if (r->n_panels)
            memcpy(r->panels, panels, sizeof *panels * r->n_panels);
    }
    free(next);
    free(to);
    free(at);
    free(planes);
    free(shade);
    free(panels);
    return ok ? 0 : -1;
}

/* Every building, a window of rows at a time: footprints by their first
 * row, each window taking the next while their rows fit in it, its
 * buildings in their own order. */
static ss_status do_windows(roofs_run *r, int *label, int *plane_at, unsigned char *usable,
                            panel_layout *layout, int *cells)
{
    size_t n = r->fps.n;
    int most = window_rows(r);
    footprint_start *order = malloc(sizeof *order * (n + 1));
    ss_status st = order ? alloc_window(r, most) : command_out_of_memory(&r->job.run);
    for (size_t b = 0; st == SS_OK && b < n; ++b)
        order[b] = (footprint_start){r->fps.items[b].row0, b};
    if (st == SS_OK)
        qsort(order, n, sizeof *order, by_start);
    for (size_t i = 0, j; st == SS_OK && i < n; i = j) {
        const ss_footprint *fp = r->fps.items;
        int row0 = order[i].row0, end = row0 + fp[order[i].index].rows;
        for (j = i + 1; j < n; ++j) {
            int e = order[j].row0 + fp[order[j].index].rows;
            if ((e > end ? e : end) - row0 > most)
                break;
            end = e > end ? e : end;
        }
        qsort(order + i, j - i, sizeof *order, by_index);
        st = read_window(r, row0, end - row0);
        r->n_windows++;
        r->most_rows = end - row0 > r->most_rows ? end - row0 : r->most_rows;
        for (size_t k = i; st == SS_OK && k < j; ++k)
            st = do_building(r, order[k].index, label, plane_at, usable, layout, cells);
    }
    free(order);
    free_window(&r->win);
    if (st == SS_OK && r->n_windows > 1 && order_planes(r) != 0)
        st = command_out_of_memory(&r->job.run);
    return st;
}

/* Every plane's irradiation (kWh/m2) with no horizon: the same records,
 * sky model and albedo on an open plane of its tilt and true azimuth over
 * level ground (ss_insolation_open_planes). */
static ss_status unshaded_planes(roofs_run *r)
{
    ss_ctx *ctx = r->job.run.ctx;
    size_t n = r->n_planes;
    double *tilt = malloc(sizeof(double) * (n + 1)), *az = malloc(sizeof(double) * (n + 1));
    double *wh = malloc(sizeof(double) * (n + 1));
    ss_insolation_options io;
    ss_status st = tilt && az && wh ? ss_insolation_params_options(ctx, &r->set.ins,
                                                                   SS_SHADOW_EXACT, &io)
                                    : command_out_of_memory(&r->job.run);
    for (size_t i = 0; st == SS_OK && i < n; ++i)
        tilt[i] = r->planes[i].tilt_deg, az[i] = r->planes[i].azimuth_deg;
    if (st == SS_OK)
        st = ss_insolation_open_planes(ctx, &io, r->sky.n, step_at, &r->sky, (int)n, tilt, az, wh);
    for (size_t i = 0; st == SS_OK && i < n; ++i) {
        plane_row *p = &r->planes[i];
        p->unshaded_kwh_m2_year = wh[i] / 1000.0;
        p->shading_loss_pct = p->unshaded_kwh_m2_year > 0
                                  ? 100.0 * (1.0 - p->kwh_m2_year / p->unshaded_kwh_m2_year)
                                  : NAN;
        building_sums *s = &r->sums[p->building];
        if (isfinite(p->kwh_m2_year)) {
            double a = p->inner_area_m2 > 0 ? p->inner_area_m2 : p->area_m2;
            s->inner_area_m2 += a;
            s->inner_kwh += a * p->kwh_m2_year;
            s->inner_unshaded_kwh += a * p->unshaded_kwh_m2_year;
        }
    }
    free(tilt);
    free(az);
    free(wh);
    return st;
}

/* Plane ids of a building go 1..n; the ids in plane_at are p + 1. */
static ss_status find_all(roofs_run *r)
{
    size_t most_cells = 1, most_window = 1;
    for (size_t b = 0; b < r->fps.n; ++b) {
        const ss_footprint *fp = &r->fps.items[b];
        most_cells = fp->n_cells > most_cells ? fp->n_cells : most_cells;
        size_t win = (size_t)fp->cols * (size_t)fp->rows;
        most_window = win > most_window ? win : most_window;
    }
    int *label = malloc(sizeof(int) * most_cells), *plane_at = malloc(sizeof(int) * most_window);
    unsigned char *usable = malloc(most_window);
    int *cells = malloc(sizeof(int) * most_cells);
    panel_layout layout = {0};
    r->sums = calloc(r->fps.n + 1, sizeof *r->sums);
    ss_status st = label && plane_at && usable && cells && r->sums
                       ? SS_OK
                       : command_out_of_memory(&r->job.run);
    if (st == SS_OK)
        st = do_windows(r, label, plane_at, usable, &layout, cells);
    double t0 = run_now();
    if (st == SS_OK)
        st = unshaded_planes(r);
    r->seconds_unshaded = run_now() - t0;
    free(label);
    free(plane_at);
    free(usable);
    free(cells);
    panel_layout_free(&layout);
    t0 = run_now();
    size_t grid_cells = (size_t)r->job.dem.grid.width * (size_t)r->job.dem.grid.height;
    if (st == SS_OK && r->set.shade_masks &&
        !(r->shade.masks = calloc(SHADE_SLOTS * grid_cells, sizeof *r->shade.masks)))
        st = ss_ctx_error(r->job.run.ctx, SS_ERR_MEMORY,
                          "out of memory for --shade-masks (%zu MB: 1.2 kB a cell)",
                          SHADE_SLOTS * grid_cells * sizeof *r->shade.masks >> 20);
    ss_source src = job_source(&r->job, NULL);
    if (st == SS_OK && (r->set.shade_table || r->set.shade_masks))
        st = roof_shade_sweep(r->job.run.ctx, &src, &r->job.opt, r->job.frame.grid_north_deg,
                              r->sky.steps, r->sky.n, r->weather.utc_offset_h, &r->shade);
    r->seconds_shade = run_now() - t0;
    return st;
}

/* --horizon-files: one file per plane, at its centre (roof_horizons.c). */
static ss_status plane_horizon_files(roofs_run *r)
{
    roof_horizon_site *s = malloc(sizeof *s * (r->n_planes + 1));
    if (!s)
        return command_out_of_memory(&r->job.run);
    for (size_t i = 0; i < r->n_planes; ++i)
        s[i] = (roof_horizon_site){r->fps.items[r->planes[i].building].id, r->planes[i].number,
                                   r->planes[i].centre_col, r->planes[i].centre_row};
    ss_status st = roof_horizon_files(r->job.run.ctx, &r->job.dem, &r->job.frame,
                                      r->set.horizon_dir, r->set.horizon_format, s, r->n_planes);
    free(s);
    return st;
}

/* The table plane_shade: a row per plane, month and hour with records. */
static ss_status write_shade_table(ss_vector_writer *w, const roofs_run *r)
{
    int layer;
    ss_status st = ss_vector_table(w, "plane_shade",
                                   "skysweep roofs: each roof plane's share in direct sun by "
                                   "month and hour (doc/roofs.md)",
                                   shade_fields, SHADE_FIELDS, &layer);
    for (size_t i = 0; st == SS_OK && i < r->n_planes; ++i)
        for (int m = 0; st == SS_OK && m < 12; ++m)
            for (int h = 0; st == SS_OK && h < 24; ++h) {
                int n = r->shade.records[m * 24 + h];
                if (!n)
                    continue;
                const plane_row *p = &r->planes[i];
                ss_value v[SHADE_FIELDS] = {{.text = r->fps.items[p->building].id},
                                            {.num = p->number},
                                            {.num = m + 1},
                                            {.num = h},
                                            {.num = roof_shade_fraction(&r->shade, i, m, h)},
                                            {.num = n},
                                            {.num = p->shade_on_usable}};
                st = ss_vector_add(w, layer, NULL, v);
            }
    return st;
}

/* --shade-masks into a temporary (renamed with the GeoPackage). */
static ss_status write_masks(roofs_run *r, char **tmp)
{
    static char names[SHADE_SLOTS][40];
    const char *descriptions[SHADE_SLOTS];
    for (int m = 0; m < 12; ++m)
        for (int h = 0; h < 24; ++h) {
            snprintf(names[m * 24 + h], sizeof names[0], "month %02d hour %02d", m + 1, h);
            descriptions[m * 24 + h] = names[m * 24 + h];
        }
    return ss_masks_write(r->job.run.ctx, r->set.shade_masks, &r->job.dem, SHADE_SLOTS,
                          r->shade.masks, descriptions, tmp);
}

/* --cell-raster: the insolation run's raster, beside it, moved into place
 * whole (close_run no longer finds it to remove). */
static ss_status keep_cell_raster(roofs_run *r)
{
    ss_ctx *ctx = r->job.run.ctx;
    if (!ss_temporaries_hold())
        return ss_ctx_error(ctx, SS_ERR_CANCELLED, "stopped before '%s' was renamed",
                            r->set.cell_raster);
    ss_status st = SS_OK;
    if (ss_output_rename(r->raster, r->set.cell_raster) != 0)
        st = ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot rename '%s' to '%s'", r->raster,
                          r->set.cell_raster);
    else
        *r->raster = '\0';
    ss_temporaries_release();
    return st;
}

static ss_status write_outputs(roofs_run *r)
{
    double t0 = run_now();
    ss_ctx *ctx = r->job.run.ctx;
    ss_vector_writer *w;
    char *masks_tmp = NULL;
    ss_status st = r->set.shade_masks ? write_masks(r, &masks_tmp) : SS_OK;
    if (st == SS_OK)
        st = ss_vector_open(ctx, r->job.output, &r->job.dem, &w);
    if (st != SS_OK) {
        ss_masks_abort(r->set.shade_masks, masks_tmp);
        return st;
    }
    int lb, lp;
    char trees_note[600] = "", light[200], described[1300];
    const insolation_tree_settings *t = &r->set.trees;
    if (t->trees.canopy) {
        crown_light_describe(&t->light, t->trees.transmissivity, light, sizeof light);
        snprintf(trees_note, sizeof trees_note,
                 "; with trees from %s, transmissivity %.4g leaf on, %.4g leaf off, crown "
                 "light: %s (doc/vegetation.md)",
                 t->trees.canopy, t->trees.transmissivity, t->transmissivity_leaf_off, light);
    }
    snprintf(described, sizeof described,
             "skysweep roofs: per building, sums over its roof planes (doc/roofs.md); under %s%s",
             r->sky_note, trees_note);
    st = ss_vector_layer(w, "buildings", described, building_fields, BUILDING_FIELDS, &lb);
    snprintf(described, sizeof described,
             "skysweep roofs: roof planes fitted in the DSM inside each footprint "
             "(doc/roofs.md); under %s%s",
             r->sky_note, trees_note);
    if (st == SS_OK)
        st = ss_vector_layer(w, "roof_planes", described, plane_fields, PLANE_FIELDS, &lp);
    ss_value v[BUILDING_FIELDS];
    for (size_t b = 0; st == SS_OK && b < r->fps.n; ++b) {
        memset(v, 0, sizeof v);
        building_values(&r->fps.items[b], &r->sums[b], v);
        st = ss_vector_add(w, lb, r->fps.items[b].geometry, v);
    }
    ss_value pv_row[PLANE_FIELDS]; /* a plane has more fields than a building */
    for (size_t i = 0; st == SS_OK && i < r->n_planes; ++i) {
        memset(pv_row, 0, sizeof pv_row);
        plane_values(&r->planes[i], r->fps.items[r->planes[i].building].id, pv_row);
        st = ss_vector_add(w, lp, r->planes[i].geometry, pv_row);
    }
    int lpanels;
    if (st == SS_OK && r->set.panels_layer)
        st = ss_vector_layer(w, "panels",
                             "skysweep roofs: each module of the panel layout, its footprint on "
                             "the ground (doc/roofs.md)",
                             panel_fields, PANEL_FIELDS, &lpanels);
    for (size_t i = 0; st == SS_OK && r->set.panels_layer && i < r->n_panels; ++i) {
        const panel_row *k = &r->panels[i];
        const plane_row *p = &r->planes[k->plane];
        ss_value pv[PANEL_FIELDS] = {{.text = r->fps.items[p->building].id},
                                     {.num = p->number},
                                     {.num = k->number},
                                     {.num = p->panel_tilt_deg},
                                     {.num = p->panel_azimuth_deg},
                                     {.num = r->set.panel.power_w / 1000.0},
                                     {.num = k->kwh_ac_year}};
        st = ss_vector_add(w, lpanels, k->geometry, pv);
    }
    if (st == SS_OK && r->set.shade_table)
        st = write_shade_table(w, r);
    if (st == SS_OK && r->set.csv)
        st = write_csv(ctx, r->set.csv, r->planes, r->n_planes, &r->fps);
    if (st == SS_OK)
        st = ss_vector_commit(w);
    else
        ss_vector_abort(w);
    if (st == SS_OK && masks_tmp)
        st = ss_masks_commit(ctx, r->set.shade_masks, masks_tmp);
    else
        ss_masks_abort(r->set.shade_masks, masks_tmp);
    if (st == SS_OK && r->set.cell_raster)
        st = keep_cell_raster(r);
    r->seconds_write = run_now() - t0;
    return st;
}

static void print_summary(roofs_run *r)
{
    const ss_footprints *f = &r->fps;
    printf("buildings %zu read from '%s': %zu placed (%zu partly outside the DSM, flagged), "
           "%zu repaired; skipped %zu invalid, %zu empty, %zu outside the DSM, %zu covering no "
           "cell centre; ids from %s\n",
           f->read, r->set.buildings, f->n, f->partly_outside, f->repaired, f->invalid, f->empty,
           f->outside, f->no_cell, *f->id_field ? f->id_field : "the feature ids");
    for (size_t i = 0; i < f->n_notes; ++i)
        printf("          %s\n", f->notes[i]);
    printf("sky       %s\n", r->sky_note);
    double kwp = 0, kwh = 0, dc = 0, usable = 0, area = 0;
    for (size_t b = 0; b < f->n; ++b)
        kwp += r->sums[b].kwp, kwh += r->sums[b].kwh_ac_year, dc += r->sums[b].kwh_dc_year,
            usable += r->sums[b].usable_area_m2, area += r->sums[b].roof_area_m2;
    printf("planes    %zu roof planes, %.0f m2 (true area), %.0f m2 usable\n", r->n_planes, area,
           usable);
    int panels = 0;
    for (size_t b = 0; b < f->n; ++b)
        panels += r->sums[b].n_panels;
    printf("yield     %d modules, %.1f kWp, %.0f kWh AC a year (%.0f kWh/kWp), %.0f kWh DC\n",
           panels, kwp, kwh, kwp > 0 ? kwh / kwp : 0.0, dc);
    if (r->job.source)
        printf("memory    the DSM read in %d windows of up to %d rows (%d rows a window under "
               "--memory)\n",
               r->n_windows, r->most_rows, r->job.band_rows);
    else
        printf("memory    the DSM held whole, %d window%s of up to %d rows\n", r->n_windows,
               r->n_windows == 1 ? "" : "s", r->most_rows);
    printf("time      insolation %.2f s, planes %.2f s, panels %.2f s, unshaded planes %.2f s, "
           "shade table %.2f s (%zu sweeps), output %.2f s -> %s\n",
           r->seconds_insolation, r->seconds_planes, r->seconds_panels, r->seconds_unshaded,
           r->seconds_shade, r->shade.sweeps, r->seconds_write, r->job.output);
}

static void close_run(roofs_run *r)
{
    for (size_t i = 0; r->planes && i < r->n_planes; ++i)
        ss_geometry_free(r->planes[i].geometry);
    free(r->planes);
    for (size_t i = 0; i < r->n_panels; ++i)
        ss_geometry_free(r->panels[i].geometry);
    free(r->panels);
    roof_shade_free(&r->shade);
    free(r->sums);
    free_window(&r->win);
    if (*r->raster)
        remove(r->raster);
    if (r->set.cell_raster)
        ss_temporaries_forget(r->set.cell_raster);
    free(r->sky.steps);
    ss_dem_source_close(r->dtm_src);
    ss_dem_free(&r->dtm);
    if (*r->clear_sky) {
        remove(r->clear_sky);
        ss_temporaries_forget(r->job.output);
    }
    ss_weather_free(&r->weather);
    ss_footprints_free(&r->fps);
    job_close(&r->job);
}

/* The sweep options of the shade table's sweeps: those the planner gives
 * `skysweep shadow` on this DSM (the line model: box lines where walls
 * stand), so that a cell's verdict is the shadow product's. Its plan is
 * not printed (the insolation run's was). Returns -1 to go on, else the
 * exit code. */
static int plan_shade_sweeps(roofs_run *r)
{
    int quiet = r->job.run.quiet;
    r->job.run.quiet = 1;
    int rc = job_plan(&r->job, &r->set.common, ss_product_named("shadow"), NULL, 0, NULL);
    r->job.run.quiet = quiet;
    return rc;
}

/* The panel options from their words: --module-size L x W, both positive
 * (the longer is the length). Returns -1, or exit 2 with one line. */
static int settle_panel_options(roofs_settings *set)
{
    double a = 0, b = 0;
    char tail;
    if (sscanf(set->module_size, "%lf%*[xX]%lf%c", &a, &b, &tail) != 2 || !isfinite(a) ||
        !isfinite(b) || a <= 0 || b <= 0 || a > 10 || b > 10)
        return run_usage_error("roofs", "--module-size must be LENGTHxWIDTH in metres, both "
                                        "above 0 and at most 10 (e.g. 1.7x1.0)");
    set->panel = (panel_options){fmax(a, b), fmin(a, b), set->module_power_w,
                                 (panel_orientation)set->orientation, set->module_spacing_m,
                                 set->row_spacing_m, set->flat_tilt_deg, set->rack_tilt_deg,
                                 set->rack_sun_elevation_deg, set->min_panel_area_m2};
    return -1;
}

/* The racks' design sun where none was given: the noon sun at the winter
 * solstice at the DSM's centre (the rule of thumb of row spacing: no row
 * shades the next on the year's shortest day at noon), at least 5 deg. */
static void settle_rack_sun(roofs_settings *set, double lat_deg)
{
    if (set->panel.rack_sun_elevation_deg <= 0)
        set->panel.rack_sun_elevation_deg = fmax(5.0, 90.0 - fabs(lat_deg) - 23.44);
}

/* Options that make no sense for roofs, refused in one line. */
/* Whether a file's name ends as a GeoTIFF's does. */
static int raster_is_geotiff(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot && (strcasecmp(dot, ".tif") == 0 || strcasecmp(dot, ".tiff") == 0);
}

static int refuse_options(const roofs_settings *set, const opt_spec *const *tables)
{
    if (!set->buildings)
        return run_usage_error("roofs", "--buildings FILE is needed (the footprints)");
    if (!set->weather && (set->weather_zone || set->weather_far_ok))
        return run_usage_error("roofs", "--weather-zone and --weather-far-ok are for --weather: "
                                        "without it the sky is clear");
    if (set->common.projwin)
        return run_usage_error("roofs", "the footprints say where: -projwin is for rasters");
    if (strcmp(set->common.format, opt_find(tables, "of")->default_text) != 0 ||
        set->common.creation_options.count)
        return run_usage_error("roofs", "the output is a GeoPackage: -of and -co are for "
                                        "rasters");
    if (strcmp(set->ins.surface, opt_find(tables, "surface")->default_text) != 0)
        return run_usage_error("roofs", "roofs take each cell's own surface: --surface is for "
                                        "insolation");
    if (set->cell_raster && !raster_is_geotiff(set->cell_raster))
        return run_usage_error("roofs", "--cell-raster writes the insolation run's GeoTIFF: "
                                        "name it .tif or .tiff");
    int bad_folder = roof_horizon_check(set->horizon_dir);
    return bad_folder ? bad_folder : -1;
}

int cmd_roofs(int argc, char **argv)
{
    roofs_run *r = calloc(1, sizeof *r);
    if (!r) {
        fprintf(stderr, "skysweep roofs: out of memory\n");
        return SS_ERR_MEMORY;
    }
    roofs_settings *set = &r->set;
    common_settings_init(&set->common);
    opt_spec insolation_options[32];
    opt_from_params("insolation", offsetof(roofs_settings, ins), insolation_options, 32);
    /* Trees and their seasons, as insolation's (doc/vegetation.md). */
    opt_spec tree_opts[TREE_OPTIONS_MAX], season_opts[INSOLATION_TREE_OPTIONS_MAX];
    insolation_tree_options(offsetof(roofs_settings, trees), tree_opts, season_opts);
    const opt_spec *tables[] = {own_options,
                                passed_on,
                                insolation_options,
                                tree_opts,
                                season_opts,
                                crown_light_options(offsetof(roofs_settings, trees) +
                                                    offsetof(insolation_tree_settings, light)),
                                sun_options(),
                                common_options(),
                                NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse(
        "roofs", tables, set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 2,
        "skysweep roofs --buildings FOOTPRINTS [--weather FILE] [--dtm DTM] [--csv FILE] "
        "[options] DSM... OUT.gpkg",
        "A solar cadastre: roof planes fitted in the DSM inside each footprint, their tilt, "
        "azimuth,\ntrue area and usable area, a panel layout on the usable area, and per plane "
        "and per\nbuilding the modules' kWp, AC and DC kWh per year, AC kWh per month "
        "(PVWatts), kWh/kWp,\nshading loss and a suitability class, from the insolation run "
        "with --weather and --pv\non the DSM (its options apply; without --weather a clear "
        "sky); on request each plane's\nshare in direct sun by month and hour. A GeoPackage "
        "with layers buildings and roof_planes,\nand panels (--panels) and plane_shade "
        "(--shade-table) on request (doc/roofs.md).",
        &set->common.device);
    if (rc < 0)
        rc = refuse_options(set, tables);
    if (rc < 0)
        rc = crown_light_alone("roofs", tables, set, &set->trees.light,
                               set->trees.trees.canopy != NULL, 1);
    if (rc < 0)
        rc = settle_panel_options(set);
    /* What roofs' own stage holds per cell of a window; its shade table
     * sweeps (with the job's bands). */
    band_cost cost = {.cell_bytes = (double)WINDOW_CELL_BYTES,
                      .no_sweep = !set->shade_table,
                      .plans_late = 1};
    if (rc < 0)
        rc = job_open_banded(&r->job, "roofs", &set->common, pos, n_pos, cost);
    if (rc != 0 || !r->job.run.ctx) {
        free(r);
        return rc;
    }
    define_fields();
    sweep_job *job = &r->job;
    settle_rack_sun(set, job->frame.centre_lat_deg);
    set->ins.pv = 1;
    ss_status st = check_files(r);
    if (st == SS_OK && job->source)
        st = settle_origin(job);
    double zone_h = NAN;
    char zone_err[160];
    if (st == SS_OK && set->weather_zone &&
        !opt_parse_zone(set->weather_zone, &zone_h, zone_err, sizeof zone_err))
        st = ss_ctx_error(job->run.ctx, SS_ERR_ARGUMENT, "%s", zone_err);
    if (st == SS_OK && !set->weather) {
        st = write_clear_sky(job, set, r->clear_sky, sizeof r->clear_sky, r->sky_note,
                             sizeof r->sky_note);
        if (*r->clear_sky)
            ss_temporaries_track(job->output); /* the records are among its temporaries */
        set->weather = r->clear_sky;
    } else {
        snprintf(r->sky_note, sizeof r->sky_note, "the weather records of '%s'", set->weather);
    }
    if (st == SS_OK)
        st = ss_weather_read(job->run.ctx, set->weather, zone_h, &r->weather);
    if (st == SS_OK)
        st = make_sky_steps(job, set, &r->weather, &r->sky);
    if (st == SS_OK && set->dtm)
        st = open_dtm(r);
    if (st == SS_OK)
        st = ss_footprints_read(job->run.ctx, set->buildings, set->buildings_layer, set->id_field,
                                    &job->dem, &r->fps);
    if (st == SS_OK)
        st = check_windows(r);
    if (st != SS_OK) {
        rc = job_finish(job, st);
        close_run(r);
        free(r);
        return rc;
    }
    double t0 = run_now();
    rc = run_insolation(job, tables, argc, argv, *r->clear_sky ? r->clear_sky : NULL,
                        set->cell_raster, r->raster, sizeof r->raster);
    r->seconds_insolation = run_now() - t0;
    /* Under mpirun the processes shared the insolation run's steps, and
     * rank 0 wrote its raster: the roofs' own stage is rank 0's alone. */
    if (rc == 0 && share_rank() > 0) {
        close_run(r);
        free(r);
        return 0;
    }
    if (rc == 0 && !job->run.plan_only)
        rc = set->shade_table || set->shade_masks ? plan_shade_sweeps(r) : -1;
    if (rc < 0) {
        st = find_all(r);
        if (st == SS_OK && set->horizon_dir)
            st = plane_horizon_files(r);
        if (st == SS_OK)
            st = write_outputs(r);
        rc = job_finish(job, st);
        if (st == SS_OK && !job->run.quiet)
            print_summary(r);
    }
    close_run(r);
    free(r);
    return rc;
}
