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

static const opt_spec weather_options[] = {OPT_END};

/* A value, or nothing where it is missing (pandas reads that as NaN). */
static void value(float v)
{
    if (isfinite(v))
        printf(",%.6g", v);
    else
        printf(",");
}

static const char weather_usage[] = "skysweep weather FILE";
static const char weather_summary[] =
    "The records of a weather file (EPW, TMY3, PVGIS TMY CSV or JSON, NSRDB PSM, or a CSV\n"
    "with time, ghi, dni, dhi) as skysweep reads them: '#' lines give the format, the site\n"
    "and what the stamps mean; each row gives the stamp (UTC), the instant the values\n"
    "stand for (where the sun is taken), the hours it covers and the values (W/m^2, C,\n"
    "m/s, 0..1, hPa; empty where missing). doc/weather.md has the conventions.";

int cmd_weather(int argc, char **argv)
{
    const opt_spec *tables[] = {weather_options, NULL};
    if (opt_print_reference(tables, argc, argv, "weather", weather_usage, weather_summary,
                            ss_version()))
        return 0;
    const char *pos[1];
    int n_pos = 0;
    char err[512];
    int r = opt_parse(tables, NULL, argc, argv, pos, &n_pos, 1, err, sizeof err);
    if (r < 0)
        return run_usage_error("weather", err);
    if (r > 0) {
        opt_print_help(tables, weather_usage, weather_summary);
        return 0;
    }
    if (n_pos != 1)
        return run_usage_error("weather", "needs one weather file");
    ss_ctx *ctx = ss_ctx_new();
    if (!ctx) {
        fprintf(stderr, "skysweep weather: out of memory\n");
        return SS_ERR_MEMORY;
    }
    ss_weather w;
    ss_status st = ss_weather_read(ctx, pos[0], &w);
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
    printf("# records %zu, %zu with an irradiance value missing\n", w.n, w.missing);
    static const char *const components[] = {
        [SS_WEATHER_GHI_DNI_DHI] = "GHI, DNI and DHI as the file gives them",
        [SS_WEATHER_GHI_DHI] = "GHI and DHI from the file; DNI = (GHI - DHI) / cos(zenith) at "
                               "each record's sun at run time (pvlib.irradiance.dni)",
        [SS_WEATHER_GHI] = "GHI alone: DNI and DHI split from it at each record's sun at run "
                           "time by Erbs et al. 1982 (pvlib.irradiance.erbs)"};
    printf("# irradiance %s\n", components[w.components]);
    printf("stamp,sun_time,duration_h,ghi,dni,dhi,temp_air,wind_speed,albedo,pressure\n");
    for (size_t i = 0; i < w.n; ++i) {
        const ss_weather_record *rec = &w.records[i];
        char stamp[48], sun[48];
        ss_format_instant(rec->stamp_unix_s, stamp, sizeof stamp);
        ss_format_instant(rec->sun_unix_s, sun, sizeof sun);
        printf("%s,%s,%.6g", stamp, sun, rec->duration_h);
        value(rec->ghi);
        value(rec->dni);
        value(rec->dhi);
        value(rec->temp_air_c);
        value(rec->wind_speed_m_s);
        value(rec->albedo);
        value(rec->pressure_hpa);
        printf("\n");
    }
    ss_weather_free(&w);
    ss_ctx_free(ctx);
    return 0;
}
