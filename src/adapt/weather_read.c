/* Weather file readers (weather.h). Each follows pvlib 0.16's reader of the
 * format for columns, units, zones and missing values (doc/weather.md):
 * read_epw, read_tmy3, read_tmy2, read_pvgis_tmy, read_nsrdb_psm4. */
#include "config.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <json-c/json.h>

#include "skysweep.h"
#include "skysweep_sun.h"
#include "text_input.h"
#include "weather.h"

#define MAX_FILE_BYTES (512L * 1024 * 1024)
#define MAX_FIELDS 128
/* Irradiance beyond this (W/m^2) is a marker or corruption: missing. */
#define IRRADIANCE_MAX 2000.0
#define IRRADIANCE_MIN -100.0

typedef struct {
    ss_ctx *ctx;
    const char *path;
    char *text;  /* the file, lines split in place */
    long size;   /* its bytes */
    char **lines;
    int n_lines;
    double zone_h; /* --weather-zone: the stamps' zone, hours east of UTC; NAN: the file's */
    ss_weather *w;
} reader;

static ss_status fail_at(reader *r, int line, const char *what)
{
    return ss_ctx_error(r->ctx, SS_ERR_INPUT, "'%s' line %d: %s", r->path, line + 1, what);
}

/* Spreadsheets and Windows editors start a UTF-8 file with a byte-order
 * mark (EF BB BF), which would hide the first line's keyword. */
static void skip_bom(reader *r)
{
    if (r->size >= 3 && memcmp(r->text, "\xEF\xBB\xBF", 3) == 0) {
        memmove(r->text, r->text + 3, (size_t)r->size - 2); /* with the final NUL */
        r->size -= 3;
    }
}

/* A spreadsheet set to a European locale exports with ';' between fields
 * and ',' as the decimal mark. Its first lines then hold more semicolons than
 * commas (each ',' of a decimal stands in a field that a ';' ends), where a
 * comma-separated file holds none or a stray one in a comment. */
static int semicolon_separated(const char *text)
{
    long semicolons = 0, commas = 0;
    int lines = 0;
    for (const char *p = text; *p && lines < 50; ++p) {
        semicolons += *p == ';';
        commas += *p == ',';
        lines += *p == '\n';
    }
    return semicolons > commas;
}

/* Decimal commas become points, semicolons field separators. */
static void to_comma_separated(char *text)
{
    for (char *p = text; *p; ++p)
        *p = *p == ',' ? '.' : *p == ';' ? ',' : *p;
}

/* A day past its month's end, named as such: 29 February in a year that is
 * not a leap year is the likeliest (a typical year stitches months of
 * different years, and an edited file may keep a leap year's day under
 * another year's number). `record` counts JSON records where line is < 0. */
static ss_status bad_day(reader *r, int line, int record, long long year, int month, int day)
{
    static const char *const names[12] = {"January", "February", "March",     "April",
                                          "May",     "June",     "July",      "August",
                                          "September", "October", "November", "December"};
    char what[120], where[40];
    if (month == 2 && day == 29)
        snprintf(what, sizeof what, "29 February in %lld, which is not a leap year", year);
    else
        snprintf(what, sizeof what, "day %d of %s %lld, which has %d days", day, names[month - 1],
                 year, ss_days_in_month(year, month));
    if (line >= 0)
        snprintf(where, sizeof where, "line %d", line + 1);
    else
        snprintf(where, sizeof where, "record %d of tmy_hourly", record + 1);
    return ss_ctx_error(r->ctx, SS_ERR_INPUT, "'%s': %s, %s", r->path, what, where);
}

/* The file in memory, split into lines (\n or \r\n). */
static ss_status load(reader *r)
{
    /* A folder opens too (and seeks to a huge end): only a regular file is read. */
    char why[1200];
    if (!ss_text_input_ok(r->path, "weather file", MAX_FILE_BYTES, why, sizeof why))
        return ss_ctx_error(r->ctx, SS_ERR_INPUT, "%s", why);
    FILE *f = fopen(r->path, "rb");
    if (!f)
        return ss_ctx_error(r->ctx, SS_ERR_INPUT, "cannot open weather file '%s': %s", r->path,
                       strerror(errno));
    long size = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    rewind(f);
    if (size < 0 || size > MAX_FILE_BYTES) { /* replaced since it was looked at */
        fclose(f);
        return ss_ctx_error(r->ctx, SS_ERR_INPUT, "cannot read weather file '%s'", r->path);
    }
    r->text = malloc((size_t)size + 1);
    if (!r->text) {
        fclose(f);
        return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
    }
    size_t got = fread(r->text, 1, (size_t)size, f);
    fclose(f);
    if (got != (size_t)size)
        return ss_ctx_error(r->ctx, SS_ERR_INPUT, "cannot read '%s'", r->path);
    r->text[size] = '\0';
    r->size = size;
    if (size == 0)
        return ss_ctx_error(r->ctx, SS_ERR_INPUT, "'%s' is empty, not a weather file", r->path);
    if (memchr(r->text, '\0', (size_t)size))
        return ss_ctx_error(r->ctx, SS_ERR_INPUT, "'%s' is binary, not a weather file", r->path);
    skip_bom(r);
    if (semicolon_separated(r->text))
        to_comma_separated(r->text);
    int cap = 1;
    for (long i = 0; i < size; ++i)
        cap += r->text[i] == '\n';
    r->lines = malloc(sizeof *r->lines * (size_t)cap);
    if (!r->lines)
        return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
    char *p = r->text;
    while (*p) {
        char *end = strchr(p, '\n');
        if (end)
            *end = '\0';
        size_t len = strlen(p);
        if (len && p[len - 1] == '\r')
            p[len - 1] = '\0';
        r->lines[r->n_lines++] = p;
        if (!end)
            break;
        p = end + 1;
    }
    return SS_OK;
}

/* Splits a CSV line in place (double quotes protect commas); returns the
 * number of fields, at most MAX_FIELDS (-1 if more). */
static int split_csv(char *line, char **fields)
{
    int n = 0;
    char *p = line;
    for (;;) {
        if (n == MAX_FIELDS)
            return -1;
        while (*p == ' ')
            ++p;
        if (*p == '"') {
            char *start = ++p, *out = p;
            while (*p && !(*p == '"' && p[1] != '"')) {
                if (*p == '"')
                    ++p;
                *out++ = *p++;
            }
            if (*p == '"')
                ++p;
            *out = '\0';
            fields[n++] = start;
            p = strchr(p, ',');
        } else {
            fields[n++] = p;
            p = strchr(p, ',');
        }
        if (!p)
            return n;
        *p++ = '\0';
    }
}

/* A number filling the field (surrounding blanks allowed). */
static int number(const char *s, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(s, &end);
    if (end == s || errno == ERANGE)
        return 0;
    while (isspace((unsigned char)*end))
        ++end;
    return *end == '\0' && isfinite(*v);
}

static int integer(const char *s, int lo, int hi, int *v)
{
    double d;
    if (!number(s, &d) || d != floor(d) || d < lo || d > hi)
        return 0;
    *v = (int)d;
    return 1;
}

/* An irradiance value: NAN for the format's missing marker or anything
 * outside a physical range. */
static float irradiance(double v, double marker)
{
    return v == marker || !(v >= IRRADIANCE_MIN && v <= IRRADIANCE_MAX) ? NAN : (float)v;
}

/* A value in [lo, hi], else NAN (not given). */
static float optional(double v, double lo, double hi)
{
    return v >= lo && v <= hi ? (float)v : NAN;
}

/* Files write 0 (IWEC, TMY3) or 999 (EPW) where they have no albedo: no
 * ground reflects nothing, so 0 counts as not given. */
static float albedo(double v)
{
    return v > 0 && v <= 1 ? (float)v : NAN;
}

static ss_weather_record *add_record(reader *r, size_t *cap)
{
    ss_weather *w = r->w;
    if (w->n == *cap) {
        size_t c = *cap ? 2 * *cap : 9000;
        ss_weather_record *grown = realloc(w->records, c * sizeof *grown);
        if (!grown)
            return NULL;
        w->records = grown;
        *cap = c;
    }
    ss_weather_record *rec = &w->records[w->n++];
    rec->ghi = rec->dni = rec->dhi = NAN;
    rec->temp_air_c = rec->wind_speed_m_s = rec->albedo = rec->pressure_hpa = NAN;
    rec->duration_h = 1.0;
    return rec;
}

static int find_column(char **fields, int n, const char *name)
{
    for (int i = 0; i < n; ++i)
        if (strcasecmp(fields[i], name) == 0)
            return i;
    return -1;
}

/* A record's values as a reader found them: irradiance (W/m^2, or the
 * format's missing marker), air temperature (C), wind (m/s), albedo and
 * pressure (hPa), NAN where the format has none. */
typedef struct {
    double ghi, dni, dhi, temp_air_c, wind_speed_m_s, albedo, pressure_hpa;
} raw_values;

/* Stores v into rec, values out of range as missing or not given (the
 * records missing a value are counted once the file's components are
 * known: settle_components). */
static void set_values(ss_weather_record *rec, const raw_values *v, double marker)
{
    rec->ghi = irradiance(v->ghi, marker);
    rec->dni = irradiance(v->dni, marker);
    rec->dhi = irradiance(v->dhi, marker);
    rec->temp_air_c = optional(v->temp_air_c, -90, 70);
    rec->wind_speed_m_s = optional(v->wind_speed_m_s, 0, 100);
    rec->albedo = albedo(v->albedo);
    rec->pressure_hpa = optional(v->pressure_hpa, 300, 1200);
}

/* The zone the stamps are read in: --weather-zone where given, else the
 * file's; kept as the file's zone (months go by it). */
static double stamps_zone(reader *r, double file_zone_h)
{
    double tz = isnan(r->zone_h) ? file_zone_h : r->zone_h;
    r->w->utc_offset_h = tz;
    return tz;
}

/* ---- EPW ---------------------------------------------------------------- */

/* EnergyPlus weather: LOCATION gives the site and the zone; records are
 * sums over the hour ending at the stamp, local standard time. A PVGIS
 * export states "Irradiance Time Offset (h)" in its comments: its values are
 * PVGIS's UTC hours under the LOCATION zone's label, so its stamps are
 * taken as UTC and the sun at stamp + offset. */
static ss_status read_epw(reader *r)
{
    ss_weather *w = r->w;
    char *f[MAX_FIELDS];
    char location[4096];
    snprintf(location, sizeof location, "%s", r->lines[0]);
    int n = split_csv(location, f);
    double lat, lon, tz, elev;
    if (n < 10 || !number(f[6], &lat) || !number(f[7], &lon) || !number(f[8], &tz) ||
        !number(f[9], &elev) || fabs(lat) > 90 || fabs(lon) > 180 || fabs(tz) > 14)
        return fail_at(r, 0, "the LOCATION line needs latitude, longitude, time zone and "
                             "elevation (fields 7 to 10)");
    w->has_site = 1;
    w->latitude_deg = lat;
    w->longitude_deg = lon;
    w->elevation_m = elev;
    tz = stamps_zone(r, tz);
    double pvgis_offset_h = NAN;
    int data = -1;
    for (int i = 1; i < r->n_lines && data < 0; ++i) {
        const char *mark = strstr(r->lines[i], "Irradiance Time Offset (h):");
        if (strncmp(r->lines[i], "COMMENTS", 8) == 0 && mark)
            pvgis_offset_h = strtod(mark + strlen("Irradiance Time Offset (h):"), NULL);
        if (strncmp(r->lines[i], "DATA PERIODS", 12) == 0)
            data = i + 1;
    }
    if (data < 0)
        return fail_at(r, 0, "an EPW file needs its eight header lines (no DATA PERIODS line)");
    int pvgis = isfinite(pvgis_offset_h) && fabs(pvgis_offset_h) <= 1.0;
    if (pvgis)
        w->utc_offset_h = 0.0; /* its values are UTC hours: months go by UTC, as its CSV's */
    if (pvgis)
        snprintf(w->stamps, sizeof w->stamps,
                 "EPW exported by PVGIS: its values are PVGIS's UTC hours (its CSV's at the "
                 "same clock hour) although LOCATION says zone %+g, so the zone is not applied: "
                 "the sun is taken at the end of the hour read as UTC %+.4f h (the file's "
                 "irradiance time offset)",
                 tz, pvgis_offset_h);
    else
        snprintf(w->stamps, sizeof w->stamps,
                 "EPW: sums over the hour ending at the hour field, local standard time UTC%+g "
                 "(stamped, as pvlib does, at the hour's start); the sun is taken at the "
                 "middle of the hour",
                 tz);
    size_t cap = 0;
    for (int i = data; i < r->n_lines; ++i) {
        if (!r->lines[i][0])
            continue;
        n = split_csv(r->lines[i], f);
        int year, month, day, hour;
        if (n < 22)
            return fail_at(r, i, "an EPW record has at least 22 fields");
        if (!integer(f[0], -9999, 99999, &year) || !integer(f[1], 1, 12, &month) ||
            !integer(f[2], 1, 31, &day) || !integer(f[3], 1, 24, &hour))
            return fail_at(r, i, "an EPW record starts with year, month (1-12), day and hour "
                                 "(1-24)");
        if (day > ss_days_in_month(year, month))
            return bad_day(r, i, 0, year, month, day);
        double v[35];
        const int want[] = {6, 9, 13, 14, 15, 21, 32};
        for (size_t k = 0; k < sizeof want / sizeof want[0]; ++k) {
            int c = want[k];
            v[c] = NAN;
            if (c < n && !number(f[c], &v[c]) && !(c == 32 && !*f[c]))
                return fail_at(r, i, "a field of an EPW record is not a number");
        }
        ss_weather_record *rec = add_record(r, &cap);
        if (!rec)
            return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
        /* As pvlib: the stamp is the start of the hour the record sums
         * (hour 1 is 00:00-01:00). PVGIS's offset counts from its end. */
        rec->stamp_unix_s = ss_unix_from_civil(year, month, day, hour - 1, 0, 0) - tz * 3600.0;
        rec->sun_unix_s = pvgis ? rec->stamp_unix_s + (tz + 1.0 + pvgis_offset_h) * 3600.0
                                : rec->stamp_unix_s + 1800.0;
        set_values(rec,
                   &(raw_values){v[13], v[14], v[15], v[6], v[21], v[32], v[9] / 100.0}, 9999);
    }
    return SS_OK;
}

/* ---- TMY3 --------------------------------------------------------------- */

/* A column name's meaning: lower case, letters and digits alone, without a
 * unit in brackets; the unit, the same way ("W/m^2" is "wm2"), into unit. */
static void column_key(const char *name, char *key, size_t key_size, char *unit,
                       size_t unit_size)
{
    size_t k = 0, u = 0;
    int depth = 0;
    for (const char *p = name; *p; ++p) {
        unsigned char c = (unsigned char)*p;
        if (c == '(' || c == '[')
            ++depth;
        else if (c == ')' || c == ']')
            depth -= depth > 0;
        else if (depth && isalnum(c) && u + 1 < unit_size)
            unit[u++] = (char)tolower(c);
        else if (!depth && isalnum(c) && k + 1 < key_size)
            key[k++] = (char)tolower(c);
    }
    key[k] = unit[u] = '\0';
}

typedef struct {
    const char *key, *name; /* the meaning, and NREL's name for it */
    const char *units[2];   /* the units it may be written in ("": none given) */
} tmy3_meaning;

/* The one column that means m (-1: none); refused where two do, or where
 * its unit is not one of m's. */
static ss_status tmy3_column(reader *r, char **names, int n, const tmy3_meaning *m, int *col)
{
    *col = -1;
    for (int i = 0; i < n; ++i) {
        char key[64], unit[64];
        column_key(names[i], key, sizeof key, unit, sizeof unit);
        if (strcmp(key, m->key) != 0)
            continue;
        char what[200];
        if (*col >= 0) {
            snprintf(what, sizeof what, "columns %d and %d both read as %s: which one is meant?",
                     *col + 1, i + 1, m->name);
            return fail_at(r, 1, what);
        }
        if (*unit && strcmp(unit, m->units[0]) != 0 && strcmp(unit, m->units[1]) != 0) {
            snprintf(what, sizeof what, "column %d ('%.40s') is not in %s's unit", i + 1,
                     names[i], m->name);
            return fail_at(r, 1, what);
        }
        *col = i;
    }
    return SS_OK;
}

/* NREL's second line begins "Date (MM/DD/YYYY),Time (HH:MM)"; an export
 * may change case, blanks, brackets. */
static int tmy3_header(const char *line)
{
    char copy[256], *f[MAX_FIELDS], key[64], unit[64];
    snprintf(copy, sizeof copy, "%s", line);
    if (split_csv(copy, f) < 2)
        return 0;
    column_key(f[0], key, sizeof key, unit, sizeof unit);
    if (strcmp(key, "date") != 0)
        return 0;
    column_key(f[1], key, sizeof key, unit, sizeof unit);
    return strcmp(key, "time") == 0;
}

/* NREL TMY3: station line (id, name, state, zone, lat, lon, elevation),
 * column names, then records summed over the hour ending at the stamp, local
 * standard time (24:00 is the end of the day); -9900 marks missing. */
static ss_status read_tmy3(reader *r)
{
    ss_weather *w = r->w;
    char *f[MAX_FIELDS];
    int n = split_csv(r->lines[0], f);
    double tz, lat, lon, elev;
    if (n < 7 || !number(f[3], &tz) || !number(f[4], &lat) || !number(f[5], &lon) ||
        !number(f[6], &elev) || fabs(lat) > 90 || fabs(lon) > 180 || fabs(tz) > 14)
        return fail_at(r, 0, "the TMY3 station line needs time zone, latitude, longitude and "
                             "elevation (fields 4 to 7)");
    w->has_site = 1;
    w->latitude_deg = lat;
    w->longitude_deg = lon;
    w->elevation_m = elev;
    tz = stamps_zone(r, tz);
    snprintf(w->stamps, sizeof w->stamps,
             "TMY3: sums over the hour ending at the stamp, local standard time UTC%+g; the sun "
             "is taken at the middle of the hour",
             tz);
    char *names[MAX_FIELDS];
    int n_names = split_csv(r->lines[1], names);
    /* By meaning: the name without case, blanks, punctuation or its unit
     * (NREL's "GHI (W/m^2)", an export's "ghi [W/m2]"), in a unit NREL's
     * means or none. */
    static const tmy3_meaning meanings[7] = {
        {"ghi", "GHI", {"wm2", "wm2"}},   {"dni", "DNI", {"wm2", "wm2"}},
        {"dhi", "DHI", {"wm2", "wm2"}},   {"drybulb", "Dry-bulb", {"c", "degc"}},
        {"wspd", "Wspd", {"ms", "ms1"}},   {"alb", "Alb", {"unitless", "unitless"}},
        {"pressure", "Pressure", {"mbar", "hpa"}}};
    int found[7];
    for (int k = 0; k < 7; ++k) {
        ss_status st = tmy3_column(r, names, n_names, &meanings[k], &found[k]);
        if (st != SS_OK)
            return st;
    }
    int c_ghi = found[0], c_dni = found[1], c_dhi = found[2], c_temp = found[3],
        c_wind = found[4], c_alb = found[5], c_pres = found[6];
    if (n_names < 2 || c_ghi < 0)
        return fail_at(r, 1, "the TMY3 column names lack GHI (W/m^2)");
    size_t cap = 0;
    for (int i = 2; i < r->n_lines; ++i) {
        if (!r->lines[i][0])
            continue;
        n = split_csv(r->lines[i], f);
        int month, day, year, hour, minute;
        if (n != n_names)
            return fail_at(r, i, "a TMY3 record has as many fields as the column names");
        /* Short fields, so that sscanf's numbers cannot overflow. */
        if (strlen(f[0]) > 10 || strlen(f[1]) > 5 ||
            sscanf(f[0], "%d/%d/%d", &month, &day, &year) != 3 || month < 1 || month > 12 ||
            day < 1 || day > 31 || sscanf(f[1], "%d:%d", &hour, &minute) != 2 || hour < 0 ||
            hour > 24 || minute < 0 || minute > 59)
            return fail_at(r, i, "a TMY3 record starts with MM/DD/YYYY and HH:MM");
        if (day > ss_days_in_month(year, month))
            return bad_day(r, i, 0, year, month, day);
        double v[7] = {NAN, NAN, NAN, NAN, NAN, NAN, NAN};
        const int cols[7] = {c_ghi, c_dni, c_dhi, c_temp, c_wind, c_alb, c_pres};
        for (int k = 0; k < 7; ++k)
            if (cols[k] >= 0 && !number(f[cols[k]], &v[k]))
                return fail_at(r, i, "a value of a TMY3 record is not a number");
        ss_weather_record *rec = add_record(r, &cap);
        if (!rec)
            return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
        rec->stamp_unix_s = ss_unix_from_civil(year, month, day, hour, minute, 0) - tz * 3600.0;
        rec->sun_unix_s = rec->stamp_unix_s - 1800.0;
        set_values(rec, &(raw_values){v[0], v[1], v[2], v[3], v[4], v[5], v[6]}, -9900);
    }
    return SS_OK;
}

/* ---- TMY2 --------------------------------------------------------------- */

/* A fixed-width field of a TMY2 record (the manual's columns, counted from
 * 0 as pvlib's read_tmy2 does: a blank, then year at 1..2). */
typedef struct {
    int start, width;
} tmy2_field;

static const tmy2_field TMY2_YEAR = {1, 2}, TMY2_MONTH = {3, 2}, TMY2_DAY = {5, 2},
                        TMY2_HOUR = {7, 2}, TMY2_ETR = {9, 4}, TMY2_GHI = {17, 4},
                        TMY2_DNI = {23, 4}, TMY2_DHI = {29, 4}, TMY2_DRY_BULB = {67, 4},
                        TMY2_PRESSURE = {84, 4}, TMY2_WSPD = {95, 3};
#define TMY2_RECORD_LENGTH 142

/* The field's integer (blanks allowed around it), 0 if it is not one. */
static int tmy2_value(const char *line, tmy2_field f, double *v)
{
    char s[8];
    memcpy(s, line + f.start, (size_t)f.width);
    s[f.width] = '\0';
    return number(s, v);
}

/* TMY2's first line, fixed width: WBAN, city, state, zone, N|S deg min,
 * E|W deg min, elevation. Read from its end, since a city's name holds
 * blanks. */
static int tmy2_station(const char *line, double *tz, double *lat, double *lon, double *elev)
{
    char copy[256], *t[32];
    snprintf(copy, sizeof copy, "%s", line);
    int n = 0;
    for (char *p = strtok(copy, " \t"); p && n < 32; p = strtok(NULL, " \t"))
        t[n++] = p;
    double d[6];
    if (n < 10 || strlen(t[n - 7]) != 1 || !strchr("NS", *t[n - 7]) || strlen(t[n - 4]) != 1 ||
        !strchr("EW", *t[n - 4]) || !number(t[n - 8], tz) || !number(t[n - 6], &d[0]) ||
        !number(t[n - 5], &d[1]) || !number(t[n - 3], &d[2]) || !number(t[n - 2], &d[3]) ||
        !number(t[n - 1], elev) || d[1] >= 60 || d[3] >= 60)
        return 0;
    *lat = (d[0] + d[1] / 60.0) * (*t[n - 7] == 'N' ? 1 : -1);
    *lon = (d[2] + d[3] / 60.0) * (*t[n - 4] == 'E' ? 1 : -1);
    return fabs(*lat) <= 90 && fabs(*lon) <= 180 && fabs(*tz) <= 14;
}

/* A TMY2 file: the station line, then records whose second to ninth
 * characters are digits (year, month, day, hour); a record cut short is
 * named by the reader. */
static int tmy2_file(const char *first, const char *second)
{
    double tz, lat, lon, elev;
    if (strlen(second) < 9)
        return 0;
    for (int i = 1; i < 9; ++i)
        if (!isdigit((unsigned char)second[i]) && second[i] != ' ')
            return 0;
    return tmy2_station(first, &tz, &lat, &lon, &elev);
}

/* An irradiance field whose source flag (TMY2 manual, Table 3-3) is '?'
 * while the sun is up (extraterrestrial > 0) is missing data: the manual
 * uses '?' "mostly for missing data", and at night for the zeros. */
static double tmy2_irradiance(const char *line, tmy2_field f, double etr, double v,
                              int *flagged)
{
    if (line[f.start + f.width] == '?' && etr > 0) {
        *flagged = 1;
        return NAN;
    }
    return v;
}

/* NREL TMY2 (Marion and Urban 1995): the station line, then fixed-width
 * records: sums over the hour ending at the hour field (1-24), local
 * standard time; each value followed by a source and an uncertainty flag;
 * temperature and wind in tenths, pressure in mbar; 9999 missing. */
static ss_status read_tmy2(reader *r)
{
    ss_weather *w = r->w;
    double tz;
    if (!tmy2_station(r->lines[0], &tz, &w->latitude_deg, &w->longitude_deg, &w->elevation_m))
        return fail_at(r, 0, "the TMY2 station line needs zone, N|S degrees minutes, E|W "
                             "degrees minutes and elevation");
    w->has_site = 1;
    tz = stamps_zone(r, tz);
    snprintf(w->stamps, sizeof w->stamps,
             "TMY2: sums over the hour ending at the hour field, local standard time UTC%+g "
             "(stamped, as pvlib does, at the hour's start, in the record's own year); the sun "
             "is taken at the middle of the hour",
             tz);
    size_t cap = 0;
    for (int i = 1; i < r->n_lines; ++i) {
        const char *line = r->lines[i];
        if (!line[strspn(line, " ")])
            continue;
        if (strlen(line) < TMY2_RECORD_LENGTH)
            return fail_at(r, i, "a TMY2 record has 142 characters (the manual's fixed-width "
                                 "fields)");
        double yy, month, day, hour;
        if (!tmy2_value(line, TMY2_YEAR, &yy) || !tmy2_value(line, TMY2_MONTH, &month) ||
            !tmy2_value(line, TMY2_DAY, &day) || !tmy2_value(line, TMY2_HOUR, &hour) ||
            yy < 0 || month < 1 || month > 12 || day < 1 || day > 31 || hour < 1 || hour > 24)
            return fail_at(r, i, "a TMY2 record starts with year (2 digits), month (1-12), day "
                                 "and hour (1-24)");
        long long year = 1900 + (long long)yy;
        if (day > ss_days_in_month(year, (int)month))
            return bad_day(r, i, 0, year, (int)month, (int)day);
        /* extraterrestrial, GHI, DNI, DHI, dry bulb, pressure, wind */
        const tmy2_field fields[7] = {TMY2_ETR, TMY2_GHI, TMY2_DNI, TMY2_DHI, TMY2_DRY_BULB,
                                      TMY2_PRESSURE, TMY2_WSPD};
        double v[7];
        for (int k = 0; k < 7; ++k)
            if (!tmy2_value(line, fields[k], &v[k]))
                return fail_at(r, i, "a value of a TMY2 record is not a number");
        int flagged = 0;
        for (int k = 1; k < 4; ++k)
            v[k] = tmy2_irradiance(line, fields[k], v[0], v[k], &flagged);
        ss_weather_record *rec = add_record(r, &cap);
        if (!rec)
            return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
        rec->stamp_unix_s =
            ss_unix_from_civil(year, (int)month, (int)day, (int)hour - 1, 0, 0) - tz * 3600.0;
        rec->sun_unix_s = rec->stamp_unix_s + 1800.0;
        w->flagged += flagged;
        set_values(rec,
                   &(raw_values){v[1], v[2], v[3], v[4] / 10.0, v[6] == 999 ? NAN : v[6] / 10.0,
                                 NAN, v[5]},
                   9999);
    }
    return SS_OK;
}

/* ---- PVGIS TMY ---------------------------------------------------------- */

/* "20180101:0000" (UTC) as its fields; 0 if malformed (a day past its
 * month's end is left to the caller to name). */
static int pvgis_time(const char *s, int *year, int *month, int *day, double *unix_s)
{
    int hour, minute;
    if (strlen(s) != 13 || s[8] != ':')
        return 0;
    for (int i = 0; i < 13; ++i)
        if (i != 8 && !isdigit((unsigned char)s[i]))
            return 0;
    if (sscanf(s, "%4d%2d%2d:%2d%2d", year, month, day, &hour, &minute) != 5 || *month < 1 ||
        *month > 12 || *day < 1 || *day > 31 || hour > 23 || hour < 0 || minute < 0 ||
        minute > 59)
        return 0;
    *unix_s = ss_unix_from_civil(*year, *month, *day, hour, minute, 0);
    return 1;
}

static void pvgis_stamps(ss_weather *w, double offset_h)
{
    snprintf(w->stamps, sizeof w->stamps,
             "PVGIS TMY: hourly values at UTC stamps; the sun is taken at the stamp %+.4f h "
             "(%s)",
             offset_h,
             isfinite(offset_h) ? "the file's irradiance time offset" : "no offset stated");
}

/* One PVGIS record from its fields (time, G(h), Gb(n), Gd(h), T2m, WS10m,
 * SP in Pa) on line `line` of a CSV, or (line < 0) record `record` of the
 * JSON. */
static ss_status pvgis_record(reader *r, int line, int record, size_t *cap, double offset_h,
                              const char *time, const double v[6])
{
    double t;
    int year, month, day;
    if (!pvgis_time(time, &year, &month, &day, &t))
        return line < 0 ? ss_ctx_error(r->ctx, SS_ERR_INPUT,
                                  "'%s': a tmy_hourly time(UTC) is written YYYYMMDD:HHMM, not '%.40s'",
                                  r->path, time)
                        : fail_at(r, line, "a PVGIS time is written YYYYMMDD:HHMM");
    if (day > ss_days_in_month(year, month))
        return bad_day(r, line, record, year, month, day);
    ss_weather_record *rec = add_record(r, cap);
    if (!rec)
        return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
    rec->stamp_unix_s = t;
    rec->sun_unix_s = t + offset_h * 3600.0;
    set_values(rec, &(raw_values){v[0], v[1], v[2], v[3], v[4], NAN, v[5] / 100.0}, NAN);
    return SS_OK;
}

/* PVGIS's hourly series (seriescalc) gives irradiance on the plane it
 * was asked for: only a horizontal one (slope 0) gives GHI (G(i), or
 * Gb(i) + Gd(i) + Gr(i)) and DHI (Gd(i)). Its stamps are the instants the
 * values stand for (UTC, the minutes of the satellite's hourly reading). */
static ss_status pvgis_series_plane(reader *r, double slope_deg)
{
    if (slope_deg == 0)
        return SS_OK;
    if (isnan(slope_deg))
        return ss_ctx_error(r->ctx, SS_ERR_INPUT,
                            "'%s' is a PVGIS hourly series that states no slope: skysweep "
                            "needs the horizontal plane's (slope 0) to read GHI", r->path);
    return ss_ctx_error(r->ctx, SS_ERR_INPUT,
                        "'%s' is a PVGIS hourly series on a plane tilted %g degrees, not "
                        "global horizontal irradiance: ask PVGIS for slope 0 (the terrain "
                        "tilts the planes itself)", r->path, slope_deg);
}

static void pvgis_series_stamps(ss_weather *w)
{
    w->format_name = "PVGIS hourly series";
    snprintf(w->stamps, sizeof w->stamps,
             "PVGIS hourly series (seriescalc, horizontal plane): values at UTC stamps (the "
             "minutes of the satellite's reading); the sun is taken at the stamp");
}

/* A series record's values in a TMY record's order (G(h), Gb(n), Gd(h),
 * T2m, WS10m, SP) from G(i) or its three parts, Gd(i), T2m, WS10m. */
static void pvgis_series_values(const double in[6], double v[6])
{
    double g = !isnan(in[0]) ? in[0] : in[1] + in[2] + (isnan(in[3]) ? 0 : in[3]);
    const double out[6] = {g, NAN, in[2], in[4], in[5], NAN};
    memcpy(v, out, sizeof out);
}

static ss_status read_pvgis_csv(reader *r)
{
    ss_weather *w = r->w;
    double offset_h = NAN, slope_deg = NAN, v;
    int header = -1, series = 0;
    for (int i = 0; i < r->n_lines && header < 0; ++i) {
        const char *line = r->lines[i], *colon = strchr(line, ':');
        if (strncmp(line, "time(UTC),", 10) == 0 || strncmp(line, "time,", 5) == 0) {
            header = i;
            series = line[4] == ',';
        } else if (strncmp(line, "Slope:", 6) == 0) {
            char *end;
            slope_deg = strtod(line + 6, &end);
            if (end == line + 6)
                slope_deg = NAN;
        } else if (colon && number(colon + 1, &v)) {
            if (strncmp(line, "Latitude", 8) == 0)
                w->latitude_deg = v, w->has_site |= 1;
            else if (strncmp(line, "Longitude", 9) == 0)
                w->longitude_deg = v, w->has_site |= 2;
            else if (strncmp(line, "Elevation", 9) == 0)
                w->elevation_m = v;
            else if (strncmp(line, "Irradiance Time Offset", 22) == 0)
                offset_h = v;
        }
    }
    if (header < 0)
        return fail_at(r, 0, "a PVGIS CSV has a 'time(UTC),...' (TMY) or 'time,...' (hourly "
                             "series) column line");
    if (w->has_site != 3 || fabs(w->latitude_deg) > 90 || fabs(w->longitude_deg) > 180)
        return fail_at(r, 0, "a PVGIS TMY CSV states its latitude and longitude");
    w->has_site = 1;
    ss_status st = series ? pvgis_series_plane(r, slope_deg) : SS_OK;
    if (st != SS_OK)
        return st;
    if (series)
        offset_h = 0.0;
    else if (!(fabs(offset_h) <= 1.0))
        offset_h = 0.5; /* hourly means: the middle of the hour */
    if (series)
        pvgis_series_stamps(w);
    else
        pvgis_stamps(w, offset_h);
    char *names[MAX_FIELDS], *f[MAX_FIELDS];
    int n_names = split_csv(r->lines[header], names);
    const char *tmy[6] = {"G(h)", "Gb(n)", "Gd(h)", "T2m", "WS10m", "SP"};
    const char *hourly[6] = {"G(i)", "Gb(i)", "Gd(i)", "Gr(i)", "T2m", "WS10m"};
    int cols[6];
    for (int k = 0; k < 6; ++k)
        cols[k] = find_column(names, n_names, series ? hourly[k] : tmy[k]);
    if (!series && cols[0] < 0)
        return fail_at(r, header, "the PVGIS columns lack G(h)");
    if (series && cols[0] < 0 && (cols[1] < 0 || cols[2] < 0))
        return fail_at(r, header, "the PVGIS hourly columns lack G(i), or Gb(i) and Gd(i)");
    size_t cap = 0;
    for (int i = header + 1; i < r->n_lines; ++i) {
        /* The records end where the footer (a blank line, then notes) begins. */
        if (!isdigit((unsigned char)r->lines[i][0]))
            break;
        int n = split_csv(r->lines[i], f);
        if (n != n_names)
            return fail_at(r, i, "a PVGIS record has as many fields as the column names");
        double val[6] = {NAN, NAN, NAN, NAN, NAN, NAN};
        for (int k = 0; k < 6; ++k)
            if (cols[k] >= 0 && !number(f[cols[k]], &val[k]))
                return fail_at(r, i, "a value of a PVGIS record is not a number");
        if (series)
            pvgis_series_values(val, val);
        st = pvgis_record(r, i, 0, &cap, offset_h, f[0], val);
        if (st != SS_OK)
            return st;
    }
    return SS_OK;
}

static int json_number(json_object *obj, const char *key, double *v)
{
    json_object *x;
    if (!json_object_object_get_ex(obj, key, &x) ||
        !(json_object_is_type(x, json_type_double) || json_object_is_type(x, json_type_int)))
        return 0;
    *v = json_object_get_double(x);
    return isfinite(*v);
}

static ss_status read_pvgis_json(reader *r)
{
    ss_weather *w = r->w;
    /* The lines were split in place: their ends become blanks again, which
     * JSON takes as white space (no string holds a raw line end). */
    for (long i = 0; i < r->size; ++i)
        if (r->text[i] == '\0')
            r->text[i] = ' ';
    json_tokener *tok = json_tokener_new();
    if (!tok)
        return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
    json_object *root = json_tokener_parse_ex(tok, r->text, (int)r->size);
    enum json_tokener_error err = json_tokener_get_error(tok);
    json_tokener_free(tok);
    if (!root || err != json_tokener_success) {
        json_object_put(root);
        return ss_ctx_error(r->ctx, SS_ERR_INPUT, "'%s' is not valid JSON: %s", r->path,
                       err == json_tokener_continue ? "it ends inside a value"
                                                    : json_tokener_error_desc(err));
    }
    json_object *inputs, *location, *outputs, *hourly = NULL;
    ss_status st = SS_OK;
    double offset_h = NAN;
    int series = 0;
    if (!json_object_object_get_ex(root, "inputs", &inputs) ||
        !json_object_object_get_ex(inputs, "location", &location) ||
        !json_number(location, "latitude", &w->latitude_deg) ||
        !json_number(location, "longitude", &w->longitude_deg) ||
        fabs(w->latitude_deg) > 90 || fabs(w->longitude_deg) > 180 ||
        !json_object_object_get_ex(root, "outputs", &outputs) ||
        !((json_object_object_get_ex(outputs, "tmy_hourly", &hourly)) ||
          (series = json_object_object_get_ex(outputs, "hourly", &hourly))) ||
        !json_object_is_type(hourly, json_type_array))
        st = ss_ctx_error(r->ctx, SS_ERR_INPUT,
                     "'%s' is not a PVGIS JSON file (inputs.location with latitude and "
                     "longitude, outputs.tmy_hourly or outputs.hourly)",
                     r->path);
    if (st == SS_OK && series) {
        json_object *mounting, *fixed, *slope;
        double slope_deg = NAN;
        if (json_object_object_get_ex(inputs, "mounting_system", &mounting) &&
            json_object_object_get_ex(mounting, "fixed", &fixed) &&
            json_object_object_get_ex(fixed, "slope", &slope))
            json_number(slope, "value", &slope_deg);
        st = pvgis_series_plane(r, slope_deg);
        offset_h = 0.0;
        if (st == SS_OK)
            pvgis_series_stamps(w);
    } else if (st == SS_OK) {
        if (!json_number(location, "irradiance_time_offset", &offset_h) ||
            !(fabs(offset_h) <= 1.0))
            offset_h = 0.5;
        pvgis_stamps(w, offset_h);
    }
    if (st == SS_OK) {
        w->has_site = 1;
        json_number(location, "elevation", &w->elevation_m);
    }
    size_t cap = 0, n = st == SS_OK ? json_object_array_length(hourly) : 0;
    const char *tmy[6] = {"G(h)", "Gb(n)", "Gd(h)", "T2m", "WS10m", "SP"};
    const char *per_hour[6] = {"G(i)", "Gb(i)", "Gd(i)", "Gr(i)", "T2m", "WS10m"};
    const char *const *keys = series ? per_hour : tmy;
    const char *time_key = series ? "time" : "time(UTC)", *list = series ? "hourly" : "tmy_hourly";
    for (size_t i = 0; i < n && st == SS_OK; ++i) {
        json_object *rec = json_object_array_get_idx(hourly, i), *time;
        double v[6] = {NAN, NAN, NAN, NAN, NAN, NAN};
        int ok = json_object_is_type(rec, json_type_object) &&
                 json_object_object_get_ex(rec, time_key, &time) &&
                 json_object_is_type(time, json_type_string);
        for (int k = 0; k < 6 && ok; ++k)
            json_number(rec, keys[k], &v[k]);
        if (series)
            pvgis_series_values(v, v);
        if (!ok || isnan(v[0]))
            st = ss_ctx_error(r->ctx, SS_ERR_INPUT, "'%s': record %zu of %s lacks %s or %s",
                              r->path, i + 1, list, time_key,
                              series ? "G(i) (or Gb(i) and Gd(i))" : "G(h)");
        else
            st = pvgis_record(r, -1, (int)i, &cap, offset_h, json_object_get_string(time), v);
    }
    json_object_put(root);
    return st;
}

/* ---- NSRDB PSM ---------------------------------------------------------- */

/* The first of a meaning's names that the header holds (SAM's CSV takes
 * NREL's short names beside the NSRDB's), -1 if none. */
static int find_alias(char **fields, int n, const char *const *aliases)
{
    for (; *aliases; ++aliases) {
        int c = find_column(fields, n, *aliases);
        if (c >= 0)
            return c;
    }
    return -1;
}

static const char *const SAM_LATITUDE[] = {"Latitude", "lat", NULL},
                         *const SAM_LONGITUDE[] = {"Longitude", "lon", NULL},
                         *const SAM_ZONE[] = {"Time Zone", "tz", NULL},
                         *const SAM_ELEVATION[] = {"Elevation", "elev", NULL};

/* SAM's CSV weather format (NREL, "SAM CSV Files for Solar Resource
 * Data"), of which an NSRDB PSM file is one: the metadata's names on the
 * first line (latitude and longitude among them; the zone, which SAM
 * itself may do without, read_psm asks for), their values on the second,
 * the columns on the third, starting with Year. */
static int sam_csv(const reader *r)
{
    if (r->n_lines < 3 || strncasecmp(r->lines[2], "Year,", 5) != 0)
        return 0;
    char copy[4096], *keys[MAX_FIELDS];
    snprintf(copy, sizeof copy, "%s", r->lines[0]);
    int nk = split_csv(copy, keys);
    return nk > 0 && find_alias(keys, nk, SAM_LATITUDE) >= 0 &&
           find_alias(keys, nk, SAM_LONGITUDE) >= 0;
}

/* NSRDB PSM3/PSM4 and other SAM CSV files: metadata names and values,
 * column names, then records of instantaneous values at the stamp, in the
 * metadata's zone. */
static ss_status read_psm(reader *r)
{
    ss_weather *w = r->w;
    char *keys[MAX_FIELDS], *vals[MAX_FIELDS], *names[MAX_FIELDS], *f[MAX_FIELDS];
    if (r->n_lines < 3)
        return fail_at(r, 0, "a PSM file has two metadata lines and a column line");
    int nk = split_csv(r->lines[0], keys), nv = split_csv(r->lines[1], vals);
    int c;
    double tz = 0;
    if (nk < 0 || nv < nk)
        return fail_at(r, 1, "the PSM metadata values do not match their names");
    if ((c = find_alias(keys, nk, SAM_LATITUDE)) < 0 || !number(vals[c], &w->latitude_deg) ||
        (c = find_alias(keys, nk, SAM_LONGITUDE)) < 0 || !number(vals[c], &w->longitude_deg) ||
        fabs(w->latitude_deg) > 90 || fabs(w->longitude_deg) > 180)
        return fail_at(r, 1, "the PSM/SAM metadata needs Latitude and Longitude in degrees");
    if ((c = find_alias(keys, nk, SAM_ZONE)) < 0 && isnan(r->zone_h))
        return ss_ctx_error(r->ctx, SS_ERR_ARGUMENT,
                            "'%s' is a SAM CSV file whose metadata states no Time Zone: give its "
                            "stamps' zone with --weather-zone (e.g. -05:00 for US Eastern "
                            "standard time)",
                            r->path);
    if (c >= 0 && (!number(vals[c], &tz) || fabs(tz) > 14))
        return fail_at(r, 1, "the PSM/SAM metadata's Time Zone is not hours from UTC (-14..14)");
    if ((c = find_alias(keys, nk, SAM_ELEVATION)) >= 0)
        number(vals[c], &w->elevation_m);
    c = find_column(keys, nk, "Source");
    if (c < 0 || strcasecmp(vals[c], "NSRDB") != 0)
        w->format_name = "SAM CSV";
    w->has_site = 1;
    tz = stamps_zone(r, tz);
    snprintf(w->stamps, sizeof w->stamps,
             "%s: instantaneous values at the stamp, UTC%+g; the sun is taken at the stamp",
             w->format_name, tz);
    int n_names = split_csv(r->lines[2], names);
    while (n_names > 0 && !names[n_names - 1][0])
        --n_names; /* spreadsheets leave empty columns */
    /* The NSRDB's names, then SAM's short ones. */
    static const char *const wanted[12][4] = {
        {"Year", NULL},           {"Month", NULL},     {"Day", NULL},
        {"Hour", NULL},           {"Minute", NULL},    {"GHI", NULL},
        {"DNI", NULL},            {"DHI", NULL},       {"Temperature", "Tdry", NULL},
        {"Wind Speed", "Wspd", NULL}, {"Surface Albedo", "Albedo", "Alb", NULL},
        {"Pressure", "Pres", NULL}};
    int cols[12];
    for (int k = 0; k < 12; ++k)
        if ((cols[k] = find_alias(names, n_names, wanted[k])) < 0 && k < 6)
            return fail_at(r, 2, "the PSM/SAM columns lack Year, Month, Day, Hour, Minute or "
                                 "GHI");
    size_t cap = 0;
    for (int i = 3; i < r->n_lines; ++i) {
        if (!r->lines[i][0])
            continue;
        int n = split_csv(r->lines[i], f);
        if (n < n_names)
            return fail_at(r, i, "a PSM record has as many fields as the column names");
        double v[12];
        for (int k = 0; k < 12; ++k) {
            v[k] = NAN;
            if (cols[k] >= 0 && !number(f[cols[k]], &v[k]))
                return fail_at(r, i, "a value of a PSM record is not a number");
        }
        if (v[0] != floor(v[0]) || fabs(v[0]) > 9999 || v[1] != floor(v[1]) || v[1] < 1 ||
            v[1] > 12 || v[2] != floor(v[2]) || v[2] < 1 || v[2] > 31 || v[3] < 0 || v[3] > 23 ||
            v[4] < 0 || v[4] > 59)
            return fail_at(r, i, "a PSM record's date or time is not valid");
        if (v[2] > ss_days_in_month((long long)v[0], (int)v[1]))
            return bad_day(r, i, 0, (long long)v[0], (int)v[1], (int)v[2]);
        ss_weather_record *rec = add_record(r, &cap);
        if (!rec)
            return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
        rec->stamp_unix_s = ss_unix_from_civil((long long)v[0], (int)v[1], (int)v[2], (int)v[3],
                                               (int)v[4], 0) -
                            tz * 3600.0;
        rec->sun_unix_s = rec->stamp_unix_s;
        set_values(rec, &(raw_values){v[5], v[6], v[7], v[8], v[9], v[10], v[11]}, -9999);
    }
    return SS_OK;
}

/* ---- UMEP / SUEWS met file ---------------------------------------------- */

/* Splits a line at blanks in place; returns the number of fields, -1 if
 * more than MAX_FIELDS. */
static int split_blanks(char *line, char **fields)
{
    int n = 0;
    char *p = line + strspn(line, " \t");
    while (*p) {
        if (n == MAX_FIELDS)
            return -1;
        fields[n++] = p;
        p += strcspn(p, " \t");
        if (*p)
            *p++ = '\0';
        p += strspn(p, " \t");
    }
    return n;
}

/* A column any of whose records holds a value other than UMEP's -999:
 * UMEP's tools write kdiff and kdir as -999 throughout where they have
 * only kdown, and split it themselves. */
static int umep_column_given(reader *r, int column)
{
    for (int i = 1; i < r->n_lines; ++i) {
        const char *p = r->lines[i];
        for (int k = 0; k < column && *p; ++k) { /* past `column` fields */
            p += strspn(p, " \t");
            p += strcspn(p, " \t");
        }
        double v = strtod(p, NULL);
        if (*p && v != -999.0)
            return 1;
    }
    return 0;
}

/* UMEP / SUEWS met file: blank-separated columns named on the first line
 * (iy id it imin ... kdown ... kdiff kdir ...), year, day of the year,
 * hour and minute, -999 for missing; means over the interval ending at the
 * stamp. It states neither site nor zone: the zone is --weather-zone's. */
static ss_status read_umep(reader *r)
{
    ss_weather *w = r->w;
    if (isnan(r->zone_h))
        return ss_ctx_error(r->ctx, SS_ERR_ARGUMENT,
                            "'%s' is a UMEP/SUEWS met file, which states no time zone: give its "
                            "stamps' zone with --weather-zone (e.g. +01:00 for Central European "
                            "standard time)",
                            r->path);
    char *names[MAX_FIELDS], *f[MAX_FIELDS];
    char header[4096];
    snprintf(header, sizeof header, "%s", r->lines[0]);
    int n_names = split_blanks(header, names);
    const char *wanted[10] = {"iy", "id", "it", "imin", "kdown", "kdiff", "kdir", "Tair", "U",
                              "pres"};
    int cols[10];
    for (int k = 0; k < 10; ++k)
        if ((cols[k] = n_names > 0 ? find_column(names, n_names, wanted[k]) : -1) < 0 && k < 5)
            return fail_at(r, 0, "a UMEP met file's first line names iy, id, it, imin and kdown");
    if (cols[6] >= 0 && !umep_column_given(r, cols[6]))
        cols[6] = -1;
    if (cols[5] >= 0 && !umep_column_given(r, cols[5]))
        cols[5] = -1;
    if (cols[6] >= 0 && cols[5] < 0)
        return fail_at(r, 0, "a UMEP met file gives kdir without kdiff: skysweep needs kdown "
                             "alone, kdown and kdiff, or all three");
    w->components = cols[5] < 0   ? SS_WEATHER_GHI
                    : cols[6] < 0 ? SS_WEATHER_GHI_DHI
                                  : SS_WEATHER_GHI_DNI_DHI;
    w->utc_offset_h = r->zone_h;
    snprintf(w->stamps, sizeof w->stamps,
             "UMEP/SUEWS: means over the interval ending at the stamp, local time UTC%+g "
             "(--weather-zone; the file states none); the sun is taken at the middle of the "
             "interval",
             r->zone_h);
    size_t cap = 0;
    for (int i = 1; i < r->n_lines; ++i) {
        int n = split_blanks(r->lines[i], f);
        if (n == 0)
            continue;
        if (n != n_names)
            return fail_at(r, i, "a UMEP record has as many fields as the column names");
        int year, doy, hour, minute;
        if (!integer(f[cols[0]], -9999, 99999, &year) || !integer(f[cols[1]], 1, 366, &doy) ||
            !integer(f[cols[2]], 0, 24, &hour) || !integer(f[cols[3]], 0, 59, &minute))
            return fail_at(r, i, "a UMEP record starts with year, day of the year (1-366), "
                                 "hour (0-24) and minute");
        if (doy == 366 && ss_days_in_month(year, 2) == 28) {
            char what[80];
            snprintf(what, sizeof what, "day 366 in %d, which is not a leap year", year);
            return fail_at(r, i, what);
        }
        double v[6];
        for (int k = 4; k < 10; ++k) {
            v[k - 4] = NAN;
            if (cols[k] >= 0 && !number(f[cols[k]], &v[k - 4]))
                return fail_at(r, i, "a value of a UMEP record is not a number");
        }
        ss_weather_record *rec = add_record(r, &cap);
        if (!rec)
            return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
        rec->stamp_unix_s =
            ss_unix_from_civil(year, 1, doy, hour, minute, 0) - r->zone_h * 3600.0;
        rec->sun_unix_s = rec->stamp_unix_s; /* moved to the interval's middle once its length is known */
        /* -999 marks missing; pressure in kPa. */
        set_values(rec,
                   &(raw_values){v[0], v[2], v[1], v[3] == -999 ? NAN : v[3],
                                 v[4] == -999 ? NAN : v[4], NAN, v[5] * 10.0},
                   -999);
    }
    return SS_OK;
}

/* ---- plain CSV ---------------------------------------------------------- */

/* The first line of a file no reader recognised, quoted with what it
 * lacks, so that a user sees whether the file is of another kind or a CSV
 * with other column names. */
static ss_status not_a_weather_file(reader *r, char *first, int cut, int n_names,
                                    const int cols[4])
{
    for (char *p = first; *p; ++p)
        if (!isprint((unsigned char)*p))
            *p = '?';
    const char *lack = n_names < 2   ? "no separated columns"
                       : cols[0] < 0 ? "no 'time' column"
                       : cols[1] < 0 ? "no 'ghi' column"
                                     : "'dni' without 'dhi'";
    return ss_ctx_error(r->ctx, SS_ERR_INPUT,
                        "'%s' is not a weather file skysweep reads: its first line '%s%s' is "
                        "none of EPW's, TMY3's, TMY2's, PVGIS's or NSRDB PSM/SAM CSV's, and as a CSV header "
                        "it has %s (time, ghi, and dhi or dhi and dni; comma or semicolon "
                        "separated)",
                        r->path, first, cut ? "..." : "", lack);
}

/* A header line naming `time` and `ghi` (and `dni`, `dhi`; optionally
 * `temp_air`, `wind_speed`, `albedo`, `pressure` in hPa), then records with
 * ISO 8601 times that carry a zone. A value stands for its stamp (an
 * instantaneous value, or a mean centred on it). */
static ss_status read_plain_csv(reader *r)
{
    ss_weather *w = r->w;
    char *names[MAX_FIELDS], *f[MAX_FIELDS];
    char first_line[64]; /* to quote, before the split cuts it */
    int cut = snprintf(first_line, sizeof first_line, "%s", r->lines[0]) >= (int)sizeof first_line;
    int n_names = split_csv(r->lines[0], names);
    const char *wanted[8] = {"time", "ghi", "dni", "dhi", "temp_air", "wind_speed", "albedo",
                             "pressure"};
    int cols[8];
    for (int k = 0; k < 8; ++k)
        cols[k] = n_names > 0 ? find_column(names, n_names, wanted[k]) : -1;
    if (cols[0] < 0 || cols[1] < 0 || (cols[2] >= 0 && cols[3] < 0))
        return not_a_weather_file(r, first_line, cut, n_names, cols);
    w->components = cols[3] < 0   ? SS_WEATHER_GHI
                    : cols[2] < 0 ? SS_WEATHER_GHI_DHI
                                  : SS_WEATHER_GHI_DNI_DHI;
    snprintf(w->stamps, sizeof w->stamps,
             "CSV: each value stands for its stamp (instantaneous, or a mean centred on it); "
             "the sun is taken at the stamp");
    size_t cap = 0;
    for (int i = 1; i < r->n_lines; ++i) {
        if (!r->lines[i][0])
            continue;
        int n = split_csv(r->lines[i], f);
        if (n != n_names)
            return fail_at(r, i, "a record has as many fields as the column names");
        double t;
        ss_status st = ss_parse_instant(r->ctx, f[cols[0]], &t);
        if (st != SS_OK) { /* the parser's words: a day past the month's end, no zone, ... */
            char why[400];
            snprintf(why, sizeof why, "%s (ISO 8601 with a zone, e.g. 2026-06-21T10:30Z)",
                     ss_ctx_message(r->ctx));
            return fail_at(r, i, why);
        }
        double v[8];
        for (int k = 1; k < 8; ++k) {
            v[k] = NAN;
            if (cols[k] >= 0 && *f[cols[k]] && !number(f[cols[k]], &v[k]))
                return fail_at(r, i, "a value is not a number");
        }
        ss_weather_record *rec = add_record(r, &cap);
        if (!rec)
            return ss_ctx_error(r->ctx, SS_ERR_MEMORY, "out of memory reading '%s'", r->path);
        rec->stamp_unix_s = rec->sun_unix_s = t;
        set_values(rec, &(raw_values){v[1], v[2], v[3], v[4], v[5], v[6], v[7]}, NAN);
    }
    return SS_OK;
}

/* What the file gives, from its values: a DNI (or DHI) column absent or
 * missing throughout leaves GHI and DHI (or GHI alone) for the models to
 * complete at each record's sun, as a plain CSV without those columns.
 * Without DHI a DNI is not used: the models complete from GHI and DHI, or
 * from GHI alone. Then counts the records lacking a value the file gives. */
static void settle_components(ss_weather *w)
{
    int any_dni = 0, any_dhi = 0;
    for (size_t i = 0; i < w->n; ++i) {
        any_dni |= !isnan(w->records[i].dni);
        any_dhi |= !isnan(w->records[i].dhi);
    }
    ss_weather_components found = !any_dhi   ? SS_WEATHER_GHI
                                  : !any_dni ? SS_WEATHER_GHI_DHI
                                             : SS_WEATHER_GHI_DNI_DHI;
    if (found > w->components)
        w->components = found;
    w->missing = 0;
    for (size_t i = 0; i < w->n; ++i) {
        ss_weather_record *rec = &w->records[i];
        if (w->components != SS_WEATHER_GHI_DNI_DHI)
            rec->dni = NAN;
        if (w->components == SS_WEATHER_GHI)
            rec->dhi = NAN;
        w->missing += isnan(rec->ghi) || (w->components == SS_WEATHER_GHI_DNI_DHI && isnan(rec->dni)) ||
                      (w->components != SS_WEATHER_GHI && isnan(rec->dhi));
    }
}

/* Instantaneous values stand for the spacing of their stamps: the smallest
 * positive gap (a gap can span missing records). Stamps must increase; in a
 * PSM file they may go back where the month (in the file's zone) changes,
 * as a typical year stitches months of different years. */
static ss_status set_durations(reader *r)
{
    ss_weather *w = r->w;
    double step = 0;
    for (size_t i = 1; i < w->n; ++i) {
        double d = w->records[i].stamp_unix_s - w->records[i - 1].stamp_unix_s;
        if (d > 0 && (step == 0 || d < step))
            step = d;
        if (d <= 0) {
            /* The months the file names: in its zone (a US typical year's
             * 31 January 23:30 at UTC-7 is 1 February in UTC). */
            ss_civil_time a, b;
            double zone_s = w->utc_offset_h * 3600.0;
            ss_civil_from_unix(w->records[i - 1].stamp_unix_s + zone_s, &a);
            ss_civil_from_unix(w->records[i].stamp_unix_s + zone_s, &b);
            if (w->format != SS_WEATHER_PSM || a.month == b.month)
                return ss_ctx_error(r->ctx, SS_ERR_INPUT,
                               "'%s': the records' times do not increase (record %zu)", r->path,
                               i + 1);
        }
    }
    if (step > 86400.0)
        return ss_ctx_error(r->ctx, SS_ERR_INPUT,
                       "'%s': records %.0f h apart are too far apart for irradiance (at most a "
                       "day)",
                       r->path, step / 3600.0);
    for (size_t i = 0; i < w->n; ++i)
        w->records[i].duration_h = step > 0 ? step / 3600.0 : 1.0;
    return SS_OK;
}

/* Records absent from the file: where consecutive stamps of one year (in
 * the file's zone) lie further apart than a record's duration. A typical
 * year's stitches change the year, and are not gaps; a plain CSV lists the
 * instants its user chose, and has none. Refuses a file most of whose
 * records are absent or lack a value: too few to sum a period. */
static ss_status count_gaps(reader *r)
{
    ss_weather *w = r->w;
    double zone_s = w->utc_offset_h * 3600.0;
    for (size_t i = 1; i < w->n && w->format != SS_WEATHER_CSV; ++i) {
        const ss_weather_record *a = &w->records[i - 1], *b = &w->records[i];
        double step_s = a->duration_h * 3600.0, d = b->stamp_unix_s - a->stamp_unix_s;
        ss_civil_time ca, cb;
        ss_civil_from_unix(a->stamp_unix_s + zone_s, &ca);
        ss_civil_from_unix(b->stamp_unix_s + zone_s, &cb);
        if (ca.year == cb.year && d > 1.5 * step_s)
            w->gaps += (size_t)(d / step_s + 0.5) - 1;
    }
    size_t expected = w->n + w->gaps, lacking = w->missing + w->gaps;
    if (2 * lacking > expected)
        return ss_ctx_error(r->ctx, SS_ERR_INPUT,
                            "'%s' (%s) is mostly gaps: %zu of its %zu records are absent (%zu) "
                            "or lack an irradiance value (%zu), more than half",
                            r->path, w->format_name, lacking, expected, w->gaps, w->missing);
    return SS_OK;
}

/* A UMEP / SUEWS met file's first line: iy id it imin, blank-separated. */
static int umep_header(const char *line)
{
    const char *names[4] = {"iy", "id", "it", "imin"};
    for (int k = 0; k < 4; ++k) {
        line += strspn(line, " \t");
        size_t len = strcspn(line, " \t");
        if (len != strlen(names[k]) || strncasecmp(line, names[k], len) != 0)
            return 0;
        line += len;
    }
    return 1;
}

ss_status ss_weather_read(ss_ctx *ctx, const char *path, double zone_h, ss_weather *w)
{
    memset(w, 0, sizeof *w);
    reader r = {.ctx = ctx, .path = path, .zone_h = zone_h, .w = w};
    ss_status st = load(&r);
    const char *first = st == SS_OK && r.n_lines ? r.lines[0] : "";
    const char *second = r.n_lines > 1 ? r.lines[1] : "";
    while (st == SS_OK && isspace((unsigned char)*first))
        ++first;
    static const char *const names[] = {"EPW",       "TMY3",          "TMY2",     "PVGIS TMY CSV",
                                        "PVGIS TMY JSON", "NSRDB PSM", "UMEP/SUEWS met",
                                        "CSV"};
    if (st != SS_OK)
        ;
    else if (strncmp(first, "LOCATION,", 9) == 0)
        w->format = SS_WEATHER_EPW;
    else if (*first == '{')
        w->format = SS_WEATHER_PVGIS_JSON;
    else if (strncmp(first, "Latitude (decimal degrees):", 27) == 0)
        w->format = SS_WEATHER_PVGIS_CSV;
    else if (tmy3_header(second))
        w->format = SS_WEATHER_TMY3;
    else if (tmy2_file(first, second))
        w->format = SS_WEATHER_TMY2;
    else if ((strncmp(first, "Source,", 7) == 0 && strstr(first, "Time Zone")) || sam_csv(&r))
        w->format = SS_WEATHER_PSM;
    else if (umep_header(first))
        w->format = SS_WEATHER_UMEP;
    else
        w->format = SS_WEATHER_CSV;
    /* PVGIS stamps are UTC by definition, a CSV's carry their zone: there
     * is no file zone to override. */
    if (st == SS_OK && !isnan(zone_h) &&
        (w->format == SS_WEATHER_PVGIS_CSV || w->format == SS_WEATHER_PVGIS_JSON ||
         w->format == SS_WEATHER_CSV))
        st = ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                          "--weather-zone applies to files whose stamps are local time (EPW, "
                          "TMY3, TMY2, NSRDB PSM, UMEP/SUEWS), not to '%s' (%s), whose %s",
                          path, names[w->format],
                          w->format == SS_WEATHER_CSV ? "times carry their zone"
                                                      : "stamps are UTC");
    if (st == SS_OK) {
        w->format_name = names[w->format];
        switch (w->format) {
        case SS_WEATHER_EPW: st = read_epw(&r); break;
        case SS_WEATHER_TMY3: st = read_tmy3(&r); break;
        case SS_WEATHER_TMY2: st = read_tmy2(&r); break;
        case SS_WEATHER_PVGIS_CSV: st = read_pvgis_csv(&r); break;
        case SS_WEATHER_PVGIS_JSON: st = read_pvgis_json(&r); break;
        case SS_WEATHER_PSM: st = read_psm(&r); break;
        case SS_WEATHER_UMEP: st = read_umep(&r); break;
        case SS_WEATHER_CSV: st = read_plain_csv(&r); break;
        }
    }
    if (st == SS_OK)
        settle_components(w);
    if (st == SS_OK && w->n == 0)
        st = ss_ctx_error(ctx, SS_ERR_INPUT, "'%s' (%s) holds no records", path, w->format_name);
    else if (st == SS_OK && w->missing == w->n)
        st = ss_ctx_error(ctx, SS_ERR_INPUT,
                          "'%s' (%s): every one of its %zu records lacks an irradiance value",
                          path, w->format_name, w->n);
    if (st == SS_OK && (w->format == SS_WEATHER_PSM || w->format == SS_WEATHER_CSV ||
                        w->format == SS_WEATHER_UMEP))
        st = set_durations(&r);
    if (st == SS_OK)
        st = count_gaps(&r);
    for (size_t i = 0; st == SS_OK && w->format == SS_WEATHER_UMEP && i < w->n; ++i)
        w->records[i].sun_unix_s -= 1800.0 * w->records[i].duration_h; /* the middle */
    free(r.lines);
    free(r.text);
    if (st != SS_OK)
        ss_weather_free(w);
    return st;
}

void ss_weather_free(ss_weather *w)
{
    free(w->records);
    w->records = NULL;
    w->n = 0;
}

const char *ss_weather_components_text(ss_weather_components c)
{
    switch (c) {
    case SS_WEATHER_GHI_DHI:
        return "GHI and DHI from the file; DNI = (GHI - DHI) / cos(zenith) at each record's "
               "sun (pvlib.irradiance.dni; 0 where pvlib's is undefined)";
    case SS_WEATHER_GHI:
        return "GHI alone from the file; DNI and DHI split from it at each record's sun by "
               "Erbs et al. 1982 (pvlib.irradiance.erbs)";
    case SS_WEATHER_GHI_DNI_DHI: break;
    }
    return "GHI, DNI and DHI from the file";
}
