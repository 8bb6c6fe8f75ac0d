/* Weather files for real-sky irradiation: EPW, NREL TMY3 CSV and TMY2, PVGIS TMY
 * (CSV and JSON), NSRDB PSM CSV, UMEP/SUEWS met files and a plain CSV, read as pvlib's readers
 * read them (units, zones, missing values; doc/weather.md). Each record
 * keeps the file's time stamp, as pvlib's index has it, and the instant its
 * values stand for, where the sun is to be taken. */
#ifndef SS_WEATHER_H
#define SS_WEATHER_H

#include <stddef.h>

#include "skysweep.h"

typedef enum {
    SS_WEATHER_EPW,
    SS_WEATHER_TMY3,
    SS_WEATHER_TMY2,
    SS_WEATHER_PVGIS_CSV,
    SS_WEATHER_PVGIS_JSON,
    SS_WEATHER_PSM,
    SS_WEATHER_UMEP,
    SS_WEATHER_CSV
} ss_weather_format;

/* The irradiance a file gives; what it lacks is derived at run time at
 * each record's sun (doc/weather.md): DNI from GHI and DHI by closure, or
 * both from GHI by Erbs et al. (1982), as pvlib computes them. */
typedef enum {
    SS_WEATHER_GHI_DNI_DHI,
    SS_WEATHER_GHI_DHI, /* dni NAN throughout */
    SS_WEATHER_GHI      /* dni and dhi NAN throughout */
} ss_weather_components;

typedef struct {
    double stamp_unix_s; /* the file's time stamp (pvlib's index), UTC seconds */
    double sun_unix_s;   /* the instant the values stand for */
    double duration_h;   /* hours the record stands for */
    /* Irradiance, W/m^2 (hourly sums in Wh/m^2 are the hour's mean in
     * W/m^2): global and diffuse horizontal, direct normal. NAN: missing,
     * or not given (components). */
    float ghi, dni, dhi;
    float temp_air_c, wind_speed_m_s, albedo, pressure_hpa; /* NAN: not given */
} ss_weather_record;

typedef struct {
    ss_weather_format format;
    const char *format_name;
    int has_site;
    double latitude_deg, longitude_deg, elevation_m;
    double utc_offset_h; /* the zone the file's stamps are written in */
    char stamps[400];    /* what a stamp means and where the sun is taken, for the plan */
    ss_weather_components components;
    size_t n;
    ss_weather_record *records;
    size_t missing; /* records with an irradiance value missing */
    size_t flagged; /* of those, records a quality flag marks missing (TMY2) */
    size_t gaps;    /* records absent: stamps further apart than the file's spacing */
} ss_weather;

/* Reads a weather file, the format found from its content, its stamps in
 * zone_h (hours east of UTC; NAN: the file's, which a UMEP/SUEWS met file
 * does not state). Refuses, in one line naming the file and line, a file it
 * cannot parse, values out of any physical range, a file with no records or
 * none with irradiance, a UMEP file without zone_h (SS_ERR_ARGUMENT), and
 * zone_h for a file whose stamps are UTC or carry their zone (idem). */
ss_status ss_weather_read(ss_ctx *ctx, const char *path, double zone_h, ss_weather *w);
void ss_weather_free(ss_weather *w);

/* What a file's components mean for a run, in words naming the model: for
 * the summary, the metadata and `skysweep weather`. */
const char *ss_weather_components_text(ss_weather_components c);

#endif
