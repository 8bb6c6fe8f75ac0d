/* skysweep weather: what a weather file holds as skysweep reads it (the
 * site, what its stamps mean, and one CSV row per record with the instant
 * the sun is taken at), so that a user can check a file before a run and
 * the tests can compare the readers with pvlib's. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "commands.h"
#include "skysweep_sun.h"
#include "weather.h"

typedef struct {
    const char *at;
    const char *zone;
} weather_settings;

#define SET(field) offsetof(weather_settings, field)
static const opt_spec weather_options[] = {
    {"at", OPT_STRING, SET(at), "LON,LAT", NULL, 0, 0, NULL,
     "where the file names no site: the place whose sun completes a file of GHI alone, or of "
     "GHI and DHI (the rows then show the model's DNI and DHI)"},
    {"weather-zone", OPT_STRING, SET(zone), "+HH:MM", NULL, 0, 0, NULL,
     "the zone the file's local stamps are in, over the one it states (EPW, TMY3, NSRDB PSM); "
     "needed for a UMEP/SUEWS met file, which states none"},
    OPT_END};

/* A value, or nothing where it is missing (pandas reads that as NaN). */
static void value(double v)
{
    if (isfinite(v))
        printf(",%.6g", v);
    else
        printf(",");
}

static const char weather_usage[] =
    "skysweep weather [--at LON,LAT] [--weather-zone +HH:MM] FILE";
static const char weather_summary[] =
    "The records of a weather file (EPW, TMY3, TMY2, PVGIS TMY CSV or JSON, NSRDB PSM, UMEP/SUEWS\n"
    "met, or a CSV with time, ghi, dhi, dni) as skysweep reads them: '#' lines give the format, the site,\n"
    "what the stamps mean and which irradiance the file gives; each row gives the stamp\n"
    "(UTC), the instant the values stand for (where the sun is taken), the hours it covers\n"
    "and the values (W/m^2, C, m/s, 0..1, hPa; empty where missing). A file without DNI\n"
    "(or DHI) gets them from the model a run uses, at the site's sun, with the sun's true\n"
    "zenith and the model in two more columns. doc/weather.md has the conventions.";

static const char *const source_names[] = {[SS_IRRADIANCE_AS_GIVEN] = "",
                                           [SS_IRRADIANCE_CLOSURE] = "closure",
                                           [SS_IRRADIANCE_ERBS] = "erbs"};

/* Prints the records, completing those without DNI at the site's sun as a
 * run would (complete: the site is known and the file lacks DNI). */
static ss_status print_records(ss_ctx *ctx, const ss_weather *w, int complete, double lon_deg,
                               double lat_deg)
{
    printf("stamp,sun_time,duration_h,ghi,dni,dhi,temp_air,wind_speed,albedo,pressure%s\n",
           complete ? ",zenith,model" : "");
    ss_spa_params params;
    ss_spa_params_default(&params);
    for (size_t i = 0; i < w->n; ++i) {
        const ss_weather_record *rec = &w->records[i];
        double dni = rec->dni, dhi = rec->dhi, zenith = NAN;
        ss_irradiance_source source = SS_IRRADIANCE_AS_GIVEN;
        if (complete) {
            ss_spa_result sun;
            ss_status st = ss_spa(ctx, rec->sun_unix_s, lat_deg, lon_deg, &params, &sun);
            if (st != SS_OK)
                return st;
            zenith = 90.0 - sun.elevation_deg; /* true, as a run takes it */
            source = ss_irradiance_complete(rec->ghi, &dni, &dhi, zenith, rec->sun_unix_s);
        }
        char stamp[48], sun_time[48];
        ss_format_instant(rec->stamp_unix_s, stamp, sizeof stamp);
        ss_format_instant(rec->sun_unix_s, sun_time, sizeof sun_time);
        printf("%s,%s,%.6g", stamp, sun_time, rec->duration_h);
        value(rec->ghi);
        value(dni);
        value(dhi);
        value(rec->temp_air_c);
        value(rec->wind_speed_m_s);
        value(rec->albedo);
        value(rec->pressure_hpa);
        if (complete)
            printf(",%.6f,%s", zenith, source_names[source]);
        printf("\n");
    }
    return SS_OK;
}

int cmd_weather(int argc, char **argv)
{
    const opt_spec *tables[] = {weather_options, NULL};
    if (opt_print_reference(tables, argc, argv, "weather", weather_usage, weather_summary,
                            ss_version()))
        return 0;
    weather_settings set = {0};
    const char *pos[1];
    int n_pos = 0;
    char err[512];
    int r = opt_parse(tables, &set, argc, argv, pos, &n_pos, 1, err, sizeof err);
    if (r < 0)
        return run_usage_error("weather", err);
    if (r > 0) {
        opt_print_help(tables, weather_usage, weather_summary);
        return 0;
    }
    if (n_pos != 1)
        return run_usage_error("weather", "needs one weather file");
    double at_lon = NAN, at_lat = NAN;
    if (set.at && !(opt_parse_site(set.at, &at_lon, &at_lat) && fabs(at_lon) <= 180 &&
                    fabs(at_lat) <= 90))
        return run_usage_error("weather", "--at expects LON,LAT in degrees (longitude "
                                          "-180..180, latitude -90..90)");
    double zone_h = NAN;
    char zone_err[160];
    if (set.zone && !opt_parse_zone(set.zone, &zone_h, zone_err, sizeof zone_err))
        return run_usage_error("weather", zone_err);
    ss_ctx *ctx = ss_ctx_new();
    if (!ctx) {
        fprintf(stderr, "skysweep weather: out of memory\n");
        return SS_ERR_MEMORY;
    }
    ss_weather w;
    ss_status st = ss_weather_read(ctx, pos[0], zone_h, &w);
    if (st != SS_OK) {
        fprintf(stderr, "skysweep weather: %s\n", ss_ctx_message(ctx));
        ss_ctx_free(ctx);
        return st;
    }
    printf("# format %s\n", w.format_name);
    if (w.has_site)
        printf("# site %.6f, %.6f (lon, lat), %.1f m\n", w.longitude_deg, w.latitude_deg,
               w.elevation_m);
    printf("# stamps %s\n", w.stamps);
    printf("# records %zu, %zu with an irradiance value missing", w.n, w.missing);
    if (w.flagged)
        printf(" (%zu of them flagged missing by the file)", w.flagged);
    printf(", %zu absent from the file's spacing\n", w.gaps);
    printf("# irradiance %s\n", ss_weather_components_text(w.components));
    /* The file's own site first: --at is for files that name none. */
    double lon = w.has_site ? w.longitude_deg : at_lon, lat = w.has_site ? w.latitude_deg : at_lat;
    int complete = w.components != SS_WEATHER_GHI_DNI_DHI && isfinite(lat);
    if (w.components != SS_WEATHER_GHI_DNI_DHI)
        printf("# model %s\n", complete ? "the DNI and DHI columns are the model's, at the "
                                          "site's sun (zenith: true, degrees)"
                                        : "applied at the DEM's sun in a run (--at LON,LAT "
                                          "shows it here)");
    st = print_records(ctx, &w, complete, lon, lat);
    if (st != SS_OK)
        fprintf(stderr, "skysweep weather: %s\n", ss_ctx_message(ctx));
    ss_weather_free(&w);
    ss_ctx_free(ctx);
    return st;
}
