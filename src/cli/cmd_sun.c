/* skysweep sun: sun position table for a site over an ISO 8601 time range,
 * optionally marking the steps when the sun is behind the terrain horizon
 * of a DEM (--horizon-from). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "horizon_points.h"
#include "skysweep_sun.h"

#define SUN_MAX_ROWS 1000000LL

typedef struct {
    const char *at;
    const char *time;
    int format;
    double delta_t_s;
    double pressure_hpa;
    double temperature_c;
    double altitude_m;
    int algorithm;
    const char *horizon_from; /* DEM for the terrain horizon, or NULL */
    site_horizon_settings horizon;
} sun_settings;

enum { FORMAT_CSV, FORMAT_JSON };
static const char *const algorithm_names[] = {"spa", "psa"};
static const ss_sun_algorithm algorithm_of_choice[] = {SS_SUN_SPA, SS_SUN_PSA};

#define SET(field) offsetof(sun_settings, field)
static const opt_spec sun_table_options[] = {
    {"at", OPT_STRING, SET(at), "LON,LAT", NULL, 0, 0, NULL,
     "site longitude and latitude, degrees, east and north positive (required)"},
    {"time", OPT_STRING, SET(time), "ISO8601", NULL, 0, 0, NULL,
     "an instant, or START/END/STEP, START/DURATION/STEP, DURATION/END/STEP, e.g. "
     "2026-06-21T00:00Z/P1D/PT30M (end excluded); times need Z or +-hh:mm (required)"},
    {"format", OPT_CHOICE, SET(format), NULL, "csv", 0, 0, "csv|json", "output format"},
    {"delta-t", OPT_DOUBLE, SET(delta_t_s), "SECONDS", NULL, -8000, 8000, NULL,
     "TT - UT1 (default: the Espenak-Meeus model for each month)"},
    {"pressure", OPT_DOUBLE, SET(pressure_hpa), "HPA", NULL, 0, 5000, NULL,
     "air pressure for refraction (default 1013.25, or the standard atmosphere at "
     "--altitude)"},
    {"temperature", OPT_DOUBLE, SET(temperature_c), "C", "12", -273, 6000, NULL,
     "air temperature for refraction"},
    {"altitude", OPT_DOUBLE, SET(altitude_m), "METRES", NULL, -6500000, 1e7, NULL,
     "site height above the ellipsoid, for parallax (default 0)"},
    {"algorithm", OPT_CHOICE, SET(algorithm), NULL, "spa", 0, 0, "spa|psa",
     "spa: NREL SPA, +-0.0003 deg; psa: PSA 2020, faster, about 0.01 deg near 2020-2050"},
    {"horizon-from", OPT_INPUT, SET(horizon_from), "DEM", NULL, 0, 0, NULL,
     "add the terrain horizon at the sun's azimuth (exact, doc/pv-horizons.md) and whether the "
     "sun is behind it; the DEM's height is then the default --altitude"},
    {"height", OPT_DOUBLE, SET(horizon.height_m), "METRES", "0", 0, 1e6, NULL,
     "with --horizon-from: observer (e.g. PV module) height above the ground"},
    {"lines", OPT_CHOICE, SET(horizon.lines), NULL, "interpolated", 0, 0, "interpolated|digital",
     "with --horizon-from: line model (doc/model.md)"},
    {"curvature", OPT_CHOICE, SET(horizon.curvature), NULL, "off", 0, 0, "off|on",
     "with --horizon-from: earth curvature with terrestrial refraction"},
    {"refraction", OPT_DOUBLE, SET(horizon.refraction_k), "K", "0.13", 0, 0.99, NULL,
     "with --horizon-from and curvature: terrestrial refraction coefficient k"},
    OPT_END};

/* horizon_deg: the terrain horizon at the sun's azimuth, NAN without --horizon-from. */
static void print_row(const sun_settings *set, const char *time, const ss_spa_result *r,
                      double horizon_deg, int first)
{
    int behind = r->apparent_elevation_deg < horizon_deg;
    if (set->format == FORMAT_CSV) {
        printf("%s,%.6f,%.6f,%.6f,%.6f,%.6f,%.4f", time, r->azimuth_deg, r->elevation_deg,
               r->apparent_elevation_deg, r->zenith_deg, r->declination_deg,
               r->equation_of_time_min);
        if (set->horizon_from)
            printf(",%.6f,%d", horizon_deg, behind);
        printf("\n");
        return;
    }
    printf("%s\n    {\"time\": \"%s\", \"azimuth\": %.6f, \"elevation\": %.6f, "
           "\"apparent_elevation\": %.6f, \"zenith\": %.6f, \"declination\": %.6f, "
           "\"equation_of_time\": %.4f",
           first ? "" : ",", time, r->azimuth_deg, r->elevation_deg, r->apparent_elevation_deg,
           r->zenith_deg, r->declination_deg, r->equation_of_time_min);
    if (set->horizon_from)
        printf(", \"horizon_elevation\": %.6f, \"behind_terrain\": %s", horizon_deg,
               behind ? "true" : "false");
    printf("}");
}

static void json_quoted(const char *text)
{
    putchar('"');
    for (const char *c = text; *c; ++c) {
        if (*c == '"' || *c == '\\')
            putchar('\\');
        putchar((unsigned char)*c < 0x20 ? ' ' : *c);
    }
    putchar('"');
}

/* horizon: what the terrain horizon is, or NULL without --horizon-from. */
static void print_head(const sun_settings *set, double lon_deg, double lat_deg,
                       const ss_spa_params *p, const char *horizon)
{
    if (set->format == FORMAT_CSV) {
        if (horizon)
            printf("# %s; behind_terrain = 1 when apparent_elevation < horizon_elevation\n",
                   horizon);
        printf("time,azimuth,elevation,apparent_elevation,zenith,declination,equation_of_time%s\n",
               horizon ? ",horizon_elevation,behind_terrain" : "");
        return;
    }
    printf("{\n  \"longitude\": %.9g, \"latitude\": %.9g, \"altitude_m\": %.9g,\n", lon_deg,
           lat_deg, p->elevation_m);
    printf("  \"algorithm\": \"%s\", \"pressure_hpa\": %.6g, \"temperature_c\": %.6g, ",
           algorithm_names[set->algorithm], p->pressure_hpa, p->temperature_c);
    if (isnan(p->delta_t_s))
        printf("\"delta_t_s\": null, \"delta_t_source\": \"Espenak-Meeus model\",\n");
    else
        printf("\"delta_t_s\": %.6g, \"delta_t_source\": \"given\",\n", p->delta_t_s);
    printf("  \"conventions\": \"times UTC; degrees; azimuth clockwise from true north; "
           "elevation topocentric without refraction; apparent_elevation with refraction; "
           "zenith = 90 - apparent_elevation; declination geocentric; equation_of_time in "
           "minutes%s\",\n",
           horizon ? "; behind_terrain when apparent_elevation < horizon_elevation" : "");
    if (horizon) {
        printf("  \"horizon\": ");
        json_quoted(horizon);
        printf(",\n");
    }
    printf("  \"rows\": [");
}

static const char sun_usage[] =
    "skysweep sun --at LON,LAT --time ISO8601[/ISO8601/STEP] [options]";
static const char sun_summary[] =
    "Sun position (NREL SPA) at a site, one row per instant: azimuth, elevation with and\n"
    "without refraction, zenith, declination, equation of time. doc/sun.md has the "
    "conventions.";

int cmd_sun(int argc, char **argv)
{
    sun_settings set = {0};
    set.delta_t_s = set.pressure_hpa = set.altitude_m = NAN; /* NAN: not given */
    const opt_spec *tables[] = {sun_table_options, NULL};
    if (opt_print_reference(tables, argc, argv, "sun", sun_usage, sun_summary, ss_version()))
        return 0;
    const char *pos[1];
    int n_pos = 0;
    char err[512];
    int r = opt_parse(tables, &set, argc, argv, pos, &n_pos, 0, err, sizeof err);
    if (r < 0)
        return run_usage_error("sun", err);
    if (r > 0) {
        opt_print_help(tables, sun_usage, sun_summary);
        return 0;
    }
    double lon_deg, lat_deg;
    if (!set.at || !set.time)
        return run_usage_error("sun", "needs --at LON,LAT and --time ISO8601");
    if (!opt_parse_site(set.at, &lon_deg, &lat_deg))
        return run_usage_error("sun", "--at expects LON,LAT in degrees, e.g. 15.6,78.2");

    ss_spa_params p;
    ss_spa_params_default(&p);
    p.algorithm = algorithm_of_choice[set.algorithm];
    p.delta_t_s = set.delta_t_s;
    p.temperature_c = set.temperature_c;
    p.elevation_m = isnan(set.altitude_m) ? 0 : set.altitude_m;
    if (!isnan(set.pressure_hpa))
        p.pressure_hpa = set.pressure_hpa;
    else if (!isnan(set.altitude_m))
        p.pressure_hpa = ss_pressure_from_altitude_hpa(set.altitude_m);

    /* No run_begin: its SIGINT handler waits for a progress callback that a
     * table loop never calls, and Ctrl-C should stop a long table at once. */
    ss_ctx *ctx = ss_ctx_new();
    if (!ctx) {
        fprintf(stderr, "skysweep sun: out of memory\n");
        return SS_ERR_MEMORY;
    }
    ss_time_range range;
    ss_spa_result res;
    site_horizon sh;
    char horizon[1024] = "";
    ss_status st = SS_OK;
    if (set.horizon_from) {
        st = site_horizon_open(&sh, ctx, set.horizon_from, lon_deg, lat_deg, &set.horizon);
        site_horizon_describe(&sh, horizon, sizeof horizon);
        /* The site's own height, for parallax and the standard pressure
         * (geoid minus ellipsoid is ignored: its parallax is below 1e-5 deg). */
        if (st == SS_OK && isnan(set.altitude_m)) {
            p.elevation_m = sh.ground_m + set.horizon.height_m;
            if (isnan(set.pressure_hpa))
                p.pressure_hpa = ss_pressure_from_altitude_hpa(p.elevation_m);
        }
    }
    if (st == SS_OK)
        st = ss_parse_time_range(ctx, set.time, &range);
    if (st == SS_OK && range.count == 0) {
        if (set.horizon_from)
            site_horizon_close(&sh);
        ss_ctx_free(ctx);
        return run_usage_error("sun", "--time START/END needs a step: START/END/STEP, e.g. "
                                      "2026-06-21T00:00Z/P1D/PT30M");
    }
    if (st == SS_OK && range.count > SUN_MAX_ROWS) {
        snprintf(err, sizeof err,
                 "--time '%s' gives %lld rows, more than %lld; use a larger step or a shorter "
                 "range",
                 set.time, range.count, SUN_MAX_ROWS);
        if (set.horizon_from)
            site_horizon_close(&sh);
        ss_ctx_free(ctx);
        return run_usage_error("sun", err);
    }
    /* Both ends first, so that a range leaving SPA's years fails before any
     * output. */
    if (st == SS_OK)
        st = ss_spa(ctx, range.start_unix_s, lat_deg, lon_deg, &p, &res);
    if (st == SS_OK)
        st = ss_spa(ctx, ss_time_range_at(&range, range.count - 1), lat_deg, lon_deg, &p, &res);
    if (st == SS_OK)
        print_head(&set, lon_deg, lat_deg, &p, set.horizon_from ? horizon : NULL);
    for (long long k = 0; st == SS_OK && k < range.count; ++k) {
        char time[48];
        double t = ss_time_range_at(&range, k), horizon_deg = NAN;
        ss_format_instant(t, time, sizeof time);
        st = ss_spa(ctx, t, lat_deg, lon_deg, &p, &res);
        if (st == SS_OK && set.horizon_from)
            st = site_horizon_at(&sh, res.azimuth_deg, &horizon_deg);
        if (st == SS_OK)
            print_row(&set, time, &res, horizon_deg, k == 0);
    }
    if (st == SS_OK && set.format == FORMAT_JSON)
        printf("\n  ]\n}\n");
    if (st != SS_OK)
        fprintf(stderr, "skysweep sun: %s\n", ss_ctx_message(ctx));
    if (set.horizon_from)
        site_horizon_close(&sh);
    ss_ctx_free(ctx);
    return st;
}
