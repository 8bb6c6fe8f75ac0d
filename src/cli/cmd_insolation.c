/* skysweep insolation: beam, diffuse, reflected and global irradiation and
 * hours of direct sun, each step's sun from SPA at the DEM (per cell where it
 * matters). Clear sky: steps over a time range, each evaluated at its
 * middle (Wh/m^2). Real sky (--weather): one step per record of a weather
 * file, the sun at the instant the record stands for, sums in kWh/m^2 for
 * the year (or the period) and each month. The library computes them
 * (ss_insolation_rows) on the DEM held whole or read band by band. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "insolation_trees.h"
#include "skysweep_sun.h"
#include "mpi_share.h"
#include "run.h"
#include "sun_field.h"
#include "weather.h"

typedef struct {
    common_settings common;   /* first: common_options()' offsets are relative to it */
    ss_insolation_params ins; /* the library's "insolation" table */
    const char *steps_path;   /* the command line's files */
    const char *weather;
    int weather_far_ok;
    const char *weather_zone;
    int years; /* YEARS_TOTAL, YEARS_MEAN, YEARS_EACH */
    insolation_tree_settings trees;
} insolation_settings;

/* What a weather run gives over several calendar years (--years). */
enum { YEARS_TOTAL, YEARS_MEAN, YEARS_EACH };

#define SET(field) offsetof(insolation_settings, field)
static const opt_spec file_options[] = {
    {"steps", OPT_OUTPUT, SET(steps_path), "FILE", NULL, 0, 0, NULL,
     "also write each step's global irradiation (Wh/m^2), one band per step"},
    {"weather", OPT_INPUT, SET(weather), "FILE", NULL, 0, 0, NULL,
     "real sky: one step per record of an EPW, TMY3, PVGIS TMY (CSV, JSON), NSRDB PSM or CSV "
     "file (skysweep weather FILE shows them); --time then selects records; outputs in "
     "kWh/m2 for the year and each month (doc/insolation.md)"},
    {"weather-far-ok", OPT_FLAG, SET(weather_far_ok), NULL, NULL, 0, 0, NULL,
     "with --weather: use a file whose site lies farther than 100 km from the DEM's centre "
     "(refused without it: its hours and clouds are not the DEM's; doc/weather.md)"},
    {"weather-zone", OPT_STRING, SET(weather_zone), "+HH:MM", NULL, 0, 0, NULL,
     "with --weather: the zone the file's local stamps are in, over the one it states (EPW, "
     "TMY3, NSRDB PSM); needed for a UMEP/SUEWS met file, which states none"},
    {"years", OPT_CHOICE, SET(years), NULL, "total", 0, 0, "total|mean|each",
     "with --weather over several calendar years: total sums them all; mean gives the mean "
     "year (whole years only); each gives every year's bands in turn, named by the year. A "
     "typical year (months of different years) is one year (doc/weather.md)"},
    OPT_END};

/* The run's time steps: each one's instant (where the sun is taken) and
 * length, and for a weather run its record and month. */
typedef struct {
    sweep_job *job;
    const insolation_settings *set;
    int n;
    double *mid_s, *hours;
    const ss_weather_record **record; /* NULL: clear sky */
    int *month;                       /* 1..12 in the weather file's zone */
    int *year;                        /* the calendar year, in the same zone */
    double linke[12];
    ss_sun_field field;
    ss_sun_lattice lattice; /* a view of field's, per step */
    int have_field;
    ss_sun_nodes nodes; /* the sun lattice's nodes, made at the first step that needs them */
    int have_nodes;
    double sun_spread_deg; /* the planner's bound when one sun serves all cells */
    char **labels; /* ISO time of each step's start (a record's stamp) */
} steps_state;


/* The sun of step k for rows [row0, row0 + n_rows) of the DEM; n_rows 0:
 * the centre's sun alone, with the spread of the cells' suns over the
 * whole DEM (from the lattice the cells' suns are interpolated from). */
static ss_status sun_of_step_rows(ss_ctx *ctx, int k, int row0, int n_rows, ss_sun_step *step,
                                  void *user)
{
    steps_state *ss = user;
    sweep_job *job = ss->job;
    if (ss->have_field)
        ss_sun_field_free(&ss->field);
    ss->have_field = 0;
    double mid = ss->mid_s[k];
    ss_spa_params p;
    ss_sun_params_spa(&ss->set->common.sun, &p);
    /* The plan decided whether the sun is needed per cell. Without it the
     * run still allows for the spread the planner bounded. */
    int per_cell = job->plan.sun_per_cell;
    int lo = n_rows > 0 ? row0 : 0, hi = n_rows > 0 ? row0 + n_rows : job->dem.grid.height;
    ss_status st = SS_OK;
    if (per_cell && !ss->have_nodes) {
        st = ss_sun_nodes_make(ctx, &job->dem, &job->frame, job->source ? job_rows_reader : NULL,
                               job, &ss->nodes);
        ss->have_nodes = st == SS_OK;
    }
    if (st == SS_OK)
        st = ss_sun_field_lattice(ctx, &job->dem, &job->frame, mid, &p, per_cell, lo, hi,
                                  &ss->nodes, &ss->field);
    if (st != SS_OK)
        return st;
    ss->have_field = 1;
    if (!per_cell)
        ss->field.spread_deg = ss->sun_spread_deg;
    const ss_sun_field *f = &ss->field;
    ss_civil_time civil;
    ss_civil_from_unix(mid, &civil);
    ss_sun_step_clear_sky(&f->centre, f->centre_grid_azimuth_deg, job->opt.grid_north_deg,
                          ss->hours[k], ss->linke[civil.month - 1], ss->set->ins.solar_constant,
                          step);
    step->spread_deg = f->spread_deg;
    /* The cells' suns as the lattice they are interpolated from: the
     * library interpolates each run of cells as it takes it. */
    if (per_cell && n_rows > 0) {
        ss_sun_field_lattice_of(f, &ss->lattice);
        step->lattice = &ss->lattice;
    }
    const ss_weather_record *rec = ss->record ? ss->record[k] : NULL;
    if (rec) {
        step->real_sky = 1;
        step->ghi_w_m2 = rec->ghi;
        step->dni_w_m2 = rec->dni;
        step->dhi_w_m2 = rec->dhi;
        step->albedo = rec->albedo;
        step->temp_air_c = rec->temp_air_c;
        step->wind_speed_m_s = rec->wind_speed_m_s;
        step->month = ss->month[k];
    }
    return SS_OK;
}

static ss_status steps_alloc(steps_state *ss, int n, int weather)
{
    ss->n = n;
    ss->mid_s = malloc(sizeof(double) * (size_t)n);
    ss->hours = malloc(sizeof(double) * (size_t)n);
    ss->labels = calloc((size_t)n, sizeof(char *));
    if (weather) {
        ss->record = malloc(sizeof *ss->record * (size_t)n);
        ss->month = malloc(sizeof(int) * (size_t)n);
        ss->year = malloc(sizeof(int) * (size_t)n);
    }
    int ok = ss->mid_s && ss->hours && ss->labels &&
             (!weather || (ss->record && ss->month && ss->year));
    for (int k = 0; ok && k < n; ++k)
        ok = (ss->labels[k] = malloc(40)) != NULL;
    return ok ? SS_OK : command_out_of_memory(&ss->job->run);
}

static void steps_free(steps_state *ss)
{
    if (ss->have_nodes)
        ss_sun_nodes_free(&ss->nodes);
    for (int k = 0; ss->labels && k < ss->n; ++k)
        free(ss->labels[k]);
    free(ss->labels);
    free(ss->mid_s);
    free(ss->hours);
    free(ss->record);
    free(ss->month);
    free(ss->year);
}

/* Clear sky: the steps of a time range, each evaluated at its middle. */
static ss_status steps_from_range(steps_state *ss, const ss_time_range *range)
{
    ss_status st = steps_alloc(ss, (int)range->count, 0);
    for (int k = 0; st == SS_OK && k < ss->n; ++k) {
        ss_time_range_step(range, k, &ss->mid_s[k], &ss->hours[k]);
        ss_format_instant(ss_time_range_at(range, k), ss->labels[k], 40);
    }
    return st;
}

/* Real sky: a step per record (those whose instant lies in `within`, if
 * given), the sun at the instant it stands for. */
static ss_status steps_from_weather(steps_state *ss, const ss_weather *w,
                                    const ss_time_range *within)
{
    int n = 0;
    for (size_t i = 0; i < w->n; ++i)
        n += !within || (w->records[i].sun_unix_s >= within->start_unix_s &&
                         w->records[i].sun_unix_s < within->end_unix_s);
    if (n == 0)
        return ss_ctx_error(ss->job->run.ctx, SS_ERR_ARGUMENT,
                            "no record of the weather file lies inside --time");
    ss_status st = steps_alloc(ss, n, 1);
    int k = 0;
    for (size_t i = 0; st == SS_OK && i < w->n; ++i) {
        const ss_weather_record *rec = &w->records[i];
        if (within && !(rec->sun_unix_s >= within->start_unix_s &&
                         rec->sun_unix_s < within->end_unix_s))
            continue;
        ss->mid_s[k] = rec->sun_unix_s;
        ss->hours[k] = rec->duration_h;
        ss->record[k] = rec;
        ss_civil_time local;
        ss_civil_from_unix(rec->sun_unix_s + w->utc_offset_h * 3600.0, &local);
        ss->month[k] = local.month;
        ss->year[k] = (int)local.year;
        ss_format_instant(rec->stamp_unix_s, ss->labels[k], 40);
        k++;
    }
    return st;
}

/* The calendar years of a weather run's steps (in the file's zone), each a
 * run of consecutive steps. A typical year, whose months come from
 * different years, is one year. */
typedef struct {
    int typical;    /* months of different years stitched: one year, never split */
    int n;          /* calendar years; 1 for a typical year */
    int first_year, last_year;
    int *year, *first, *count; /* each year's number and its steps */
    double *hours, *year_hours; /* the hours its steps span; the hours it has */
    int *whole;                 /* its steps span it, to within a record at each end */
} weather_years;

/* A typical year changes year where the month moves on (or back to an
 * earlier year); calendar years change only where the months start over. */
static int steps_stitched(const steps_state *ss)
{
    for (int k = 1; k < ss->n; ++k)
        if (ss->year[k] != ss->year[k - 1] &&
            (ss->year[k] < ss->year[k - 1] || ss->month[k] >= ss->month[k - 1]))
            return 1;
    return 0;
}

/* Year j's steps: how many hours they span and whether they span the
 * year, its start and end taken in the file's zone. */
static void year_extent(weather_years *y, int j, const steps_state *ss, double zone_h)
{
    int f = y->first[j], l = f + y->count[j] - 1;
    double start = ss_unix_from_civil(y->year[j], 1, 1, 0, 0, 0) - zone_h * 3600.0;
    double end = ss_unix_from_civil(y->year[j] + 1LL, 1, 1, 0, 0, 0) - zone_h * 3600.0;
    y->hours[j] = (ss->mid_s[l] - ss->mid_s[f]) / 3600.0 + ss->hours[l];
    y->year_hours[j] = (end - start) / 3600.0;
    y->whole[j] = y->typical || (ss->mid_s[f] - start <= ss->hours[f] * 3600.0 + 1.0 &&
                                 end - ss->mid_s[l] <= ss->hours[l] * 3600.0 + 1.0);
}

static ss_status years_of_steps(ss_ctx *ctx, const steps_state *ss, double zone_h,
                                weather_years *y)
{
    y->typical = steps_stitched(ss);
    y->n = 1;
    y->first_year = y->last_year = ss->year[0];
    for (int k = 1; k < ss->n; ++k) {
        y->n += !y->typical && ss->year[k] != ss->year[k - 1];
        y->first_year = ss->year[k] < y->first_year ? ss->year[k] : y->first_year;
        y->last_year = ss->year[k] > y->last_year ? ss->year[k] : y->last_year;
    }
    size_t n = (size_t)y->n;
    y->year = malloc(sizeof(int) * n);
    y->first = malloc(sizeof(int) * n);
    y->count = malloc(sizeof(int) * n);
    y->whole = malloc(sizeof(int) * n);
    y->hours = malloc(sizeof(double) * n);
    y->year_hours = malloc(sizeof(double) * n);
    if (!y->year || !y->first || !y->count || !y->whole || !y->hours || !y->year_hours)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for the weather's years");
    int j = 0;
    y->year[0] = ss->year[0];
    y->first[0] = 0;
    for (int k = 1; k < ss->n; ++k)
        if (!y->typical && ss->year[k] != ss->year[k - 1]) {
            y->count[j] = k - y->first[j];
            y->year[++j] = ss->year[k];
            y->first[j] = k;
        }
    y->count[j] = ss->n - y->first[j];
    for (j = 0; j < y->n; ++j)
        year_extent(y, j, ss, zone_h);
    return SS_OK;
}

static void years_free(weather_years *y)
{
    free(y->year);
    free(y->first);
    free(y->count);
    free(y->whole);
    free(y->hours);
    free(y->year_hours);
}

static const char *const band_names[5] = {"global", "beam", "diffuse", "reflected", "sun_hours"};
/* Bands of a weather run: the five sums, the global of each month, then
 * (--pv) the PV yield. */
#define WEATHER_BANDS 17
static const char *const month_names[12] = {"January", "February", "March",     "April",
                                            "May",     "June",     "July",      "August",
                                            "September", "October", "November", "December"};


/* Where the rows of the run go: rank 0's outputs (a weather run's sums in
 * kWh/m^2, of the mean year where asked; with --years each, a block of
 * bands per year), each step's global, and the statistics of the summary. */
typedef struct {
    ss_raster_writer *w, *steps_w; /* NULL on other ranks */
    int width, weather;
    int years;              /* the sums are divided by it: the mean year's */
    int block, block_bands; /* the year whose bands the rows go to, and bands per year */
    int step0;              /* the first step of the year's run */
    run_tally *tally;       /* per block: global (Wh/m^2), pv, pv_ac (kWh/kWp) */
    float *row;             /* a band's rows in kWh/m^2 */
} insolation_out;

/* The registry's outputs (its insolation entry): 0 the sums, band by
 * band in the output's order (the five, the months' globals, the PV
 * yields DC and AC), 1 each step's global. */
static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    insolation_out *o = user;
    size_t n = (size_t)n_rows * (size_t)o->width;
    if (output == 1)
        return ss_writer_rows(o->steps_w, o->step0 + index + 1, row0, n_rows, values);
    if (!o->w) /* another process's sums: rank 0 writes */
        return SS_OK;
    enum { PV_DC = WEATHER_BANDS, PV_AC = WEATHER_BANDS + 1 };
    run_tally *tally = index == SS_OUT_GLOBAL ? &o->tally[3 * o->block]
                       : index == PV_DC       ? &o->tally[3 * o->block + 1]
                       : index == PV_AC       ? &o->tally[3 * o->block + 2]
                                              : NULL;
    if (tally)
        run_tally_add(tally, values, n);
    int band = index + 1;
    /* A weather run's irradiation in kWh/m^2 (hours stay hours, the PV
     * yields are kWh/kWp already), and all of it of the mean year. */
    float kilo = o->weather && index != SS_OUT_SUN_HOURS && index < PV_DC ? 1000.0f : 1.0f;
    if (kilo != 1.0f || o->years > 1) {
        for (size_t c = 0; c < n; ++c)
            o->row[c] = values[c] == SS_NODATA ? SS_NODATA : values[c] / kilo / (float)o->years;
        values = o->row;
    }
    return ss_writer_rows(o->w, o->block * o->block_bands + band, row0, n_rows, values);
}


/* The steps from --time (and --step) or --weather; text gets the range
 * as parsed (malloc'ed), for the metadata. */
static ss_status make_steps(steps_state *steps, const insolation_settings *set,
                            const ss_weather *weather, char **text)
{
    ss_ctx *ctx = steps->job->run.ctx;
    *text = NULL;
    if (!set->common.sun.time && !weather)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                            "--time START/END (or START/DURATION) or --weather FILE is needed");
    ss_time_range range = {0};
    if (set->common.sun.time) {
        /* --time may carry its own /STEP; otherwise --step applies. */
        size_t len = strlen(set->common.sun.time) + strlen(set->ins.step) + 2;
        int slashes = 0;
        for (const char *p = set->common.sun.time; *p; ++p)
            slashes += *p == '/';
        if (!(*text = malloc(len)))
            return command_out_of_memory(&steps->job->run);
        snprintf(*text, len, "%s%s%s", set->common.sun.time, slashes == 1 && !weather ? "/" : "",
                 slashes == 1 && !weather ? set->ins.step : "");
        ss_status st = ss_parse_time_range(ctx, *text, &range);
        if (st != SS_OK)
            return st;
        /* The clear sky needs an interval to sum over; with weather,
         * --time only selects the records. */
        int interval = range.end_unix_s > range.start_unix_s;
        if (!interval && (!weather || range.count < 1))
            return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                                "--time must be a range (START/END or START/DURATION): "
                                "irradiation is summed over an interval, not an instant");
        if (!weather && range.count > 100000)
            return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                                "%lld time steps is more than 100000: choose a longer --step",
                                range.count);
    }
    if (weather)
        return steps_from_weather(steps, weather, set->common.sun.time ? &range : NULL);
    return steps_from_range(steps, &range);
}

/* Great-circle distance (km, mean earth radius) between two places. */
static double distance_km(double lon1, double lat1, double lon2, double lat2)
{
    double r = M_PI / 180.0, a = sin(0.5 * (lat2 - lat1) * r), b = sin(0.5 * (lon2 - lon1) * r);
    double h = a * a + cos(lat1 * r) * cos(lat2 * r) * b * b;
    return 2.0 * 6371.0088 * asin(sqrt(fmin(1.0, h)));
}

/* How far the weather file's site lies from the DEM's centre (km), NAN
 * where it names none. */
static double weather_distance_km(const ss_weather *w, const ss_dem_frame *frame)
{
    return w->has_site ? distance_km(w->longitude_deg, w->latitude_deg, frame->centre_lon_deg,
                                     frame->centre_lat_deg)
                       : NAN;
}

/* A file from elsewhere runs without error but sums the wrong hours (its
 * stamps' days fall in another place's nights) and another sky: refused
 * beyond SS_WEATHER_NEAR_KM unless the user says it is meant. */
static ss_status check_weather_site(ss_ctx *ctx, const ss_weather *w, const ss_dem_frame *frame,
                                   int far_ok)
{
    double km = weather_distance_km(w, frame);
    if (far_ok || !(km > SS_WEATHER_NEAR_KM))
        return SS_OK;
    return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                        "the weather file's site (%.4f, %.4f lon, lat) lies %.0f km from the "
                        "DEM's centre, farther than %.0f km: its hours and sky are not the "
                        "DEM's; use the DEM's own weather, or --weather-far-ok to run anyway",
                        w->longitude_deg, w->latitude_deg, km, SS_WEATHER_NEAR_KM);
}

/* The weather file's summary: format, site and its distance from the DEM,
 * what the stamps mean. */
static void describe_weather(const ss_weather *w, const char *path, const ss_dem_frame *frame,
                             char *buf, size_t size)
{
    int n = snprintf(buf, size, "%s '%s', %zu records (%zu with a value missing)",
                     w->format_name, path, w->n, w->missing);
    if (w->has_site && n > 0 && (size_t)n < size) {
        double km = weather_distance_km(w, frame);
        n += snprintf(buf + n, size - (size_t)n,
                      "; site %.4f, %.4f (lon, lat), %.1f km from the DEM's centre%s",
                      w->longitude_deg, w->latitude_deg, km,
                      km > SS_WEATHER_NEAR_KM ? ": its weather may not be the DEM's" : "");
    } else if (n > 0 && (size_t)n < size) {
        n += snprintf(buf + n, size - (size_t)n, "; no site given");
    }
    if (n > 0 && (size_t)n < size)
        snprintf(buf + n, size - (size_t)n, "; %s; irradiance: %s", w->stamps,
                 ss_weather_components_text(w->components));
}

/* Names a block of a run's bands from band first + 1: a weather run's in
 * kWh/m^2 (hours stay hours, the PV yields, DC then AC, are kWh/kWp), the
 * sums for `span` and the months' followed by `months`; a clear-sky run's in
 * Wh/m^2. */
static void describe_bands(ss_raster_writer *w, int first, int weather, int pv, const char *span,
                           const char *months)
{
    char name[96];
    for (int b = 0; b < (weather ? WEATHER_BANDS : 5); ++b) {
        if (weather && b < 5)
            snprintf(name, sizeof name, "%s, %s", band_names[b], span);
        else if (weather)
            snprintf(name, sizeof name, "global, %s%s", month_names[b - 5], months);
        ss_writer_describe(w, first + b + 1, weather ? name : band_names[b],
                           b == 4 ? "h" : weather ? "kWh/m2" : "Wh/m2");
    }
    for (int b = 0; b < 2 && pv; ++b) {
        snprintf(name, sizeof name, "%s, %s", b ? "pv_ac_yield" : "pv_yield", span);
        ss_writer_describe(w, first + WEATHER_BANDS + 1 + b, name, "kWh/kWp");
    }
}

/* A run of the command: its settings, job, steps and weather, the
 * options the library takes, and where the rows go. */
typedef struct {
    insolation_settings set;
    sweep_job job;
    steps_state steps;
    ss_weather weather;
    int have_weather;
    weather_years years;
    int blocks; /* blocks of bands: one per year with --years each, else 1 */
    char *text; /* --time as parsed (malloc'ed), for the metadata */
    char weather_note[1200], weather_what[300];
    ss_insolation_options io;
    insolation_out out;
    ss_band_stats bands;
    insolation_trees trees; /* --canopy */
    int shadows_forced;     /* --shadow auto made exact for the trees */
} insolation_run;

/* The weather's calendar years, and the blocks of bands --years asks for;
 * the mean year is refused over a year the steps do not span. */
static ss_status prepare_years(insolation_run *r)
{
    ss_ctx *ctx = r->job.run.ctx;
    weather_years *y = &r->years;
    ss_status st = years_of_steps(ctx, &r->steps, r->weather.utc_offset_h, y);
    for (int j = 0; st == SS_OK && r->set.years == YEARS_MEAN && j < y->n; ++j)
        if (!y->whole[j])
            st = ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                              "--years mean needs whole calendar years: the records of %d "
                              "span %.0f of its %.0f hours; select whole years with --time, "
                              "or use --years each",
                              y->year[j], y->hours[j], y->year_hours[j]);
    r->blocks = r->set.years == YEARS_EACH ? y->n : 1;
    return st;
}

/* What the run needs before it is planned: the options, the weather and
 * the time steps. */
static ss_status prepare(insolation_run *r)
{
    ss_ctx *ctx = r->job.run.ctx;
    const insolation_settings *set = &r->set;
    r->steps.job = &r->job;
    r->steps.set = set;
    if (!r->job.frame.georeferenced)
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                            "the DEM has no CRS, so where the sun stands is unknown");
    /* The plan chooses the shadow mode (plan_and_open). */
    ss_status st = ss_insolation_params_options(ctx, &set->ins, SS_SHADOW_EXACT, &r->io);
    if (st == SS_OK && !set->weather &&
        ss_insolation_params_shadow(&set->ins) == SS_SHADOW_CUMULATIVE)
        st = ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                          "--shadow cumulative needs --weather: it bins weather records' suns");
    double zone_h = NAN;
    char zone_err[160];
    if (st == SS_OK && set->weather_zone &&
        !opt_parse_zone(set->weather_zone, &zone_h, zone_err, sizeof zone_err))
        st = ss_ctx_error(ctx, SS_ERR_ARGUMENT, "%s", zone_err);
    if (st == SS_OK && set->weather) {
        st = ss_weather_read(ctx, set->weather, zone_h, &r->weather);
        r->have_weather = st == SS_OK;
    }
    if (st == SS_OK && r->have_weather)
        st = check_weather_site(ctx, &r->weather, &r->job.frame, set->weather_far_ok);
    if (st == SS_OK && r->have_weather) {
        describe_weather(&r->weather, set->weather, &r->job.frame, r->weather_note,
                         sizeof r->weather_note);
        snprintf(r->weather_what, sizeof r->weather_what, "%s '%s'", r->weather.format_name,
                 set->weather);
        r->job.weather = (ss_plan_weather){
            r->weather_what, weather_distance_km(&r->weather, &r->job.frame),
            r->io.sky_model == SS_SKY_MODEL_PEREZ, set->steps_path != NULL, set->ins.pv,
            set->ins.tolerance_percent};
    }
    if (st == SS_OK)
        st = make_steps(&r->steps, set, r->have_weather ? &r->weather : NULL, &r->text);
    r->blocks = 1;
    if (st == SS_OK && r->have_weather)
        st = prepare_years(r);
    if (st == SS_OK)
        st = ss_insolation_params_linke(ctx, &set->ins, r->steps.linke);
    if (st == SS_OK && set->ins.pv && !r->have_weather)
        st = ss_ctx_error(ctx, SS_ERR_ARGUMENT, "--pv needs --weather (air temperature and "
                                                "real-sky irradiance)");
    return st;
}

/* Rank 0's output (and the steps' file), opened before the run, to fail
 * early. */
static ss_status open_outputs(insolation_run *r)
{
    ss_ctx *ctx = r->job.run.ctx;
    const insolation_settings *set = &r->set;
    sweep_job *job = &r->job;
    r->out = (insolation_out){
        .width = job->dem.grid.width,
        .weather = r->have_weather,
        .years = r->have_weather && set->years == YEARS_MEAN ? r->years.n : 1,
        .block_bands = r->have_weather ? WEATHER_BANDS + 2 * (set->ins.pv != 0) : 5};
    size_t rows = (size_t)(job->source ? job->band_rows : job->dem.grid.height);
    r->out.row = malloc(sizeof(float) * (size_t)job->dem.grid.width * rows);
    r->out.tally = calloc(3 * (size_t)r->blocks, sizeof *r->out.tally);
    if (!r->out.row || !r->out.tally)
        return command_out_of_memory(&job->run);
    ss_status st = job_open_output(job, r->blocks * r->out.block_bands, &set->common, &r->out.w);
    if (st == SS_OK && set->steps_path) {
        st = run_check_output(&job->run, set->steps_path);
        if (st == SS_OK)
            st = ss_writer_open(ctx, set->steps_path, &job->dem, r->steps.n, set->common.format,
                                set->common.creation_options.items, &r->out.steps_w);
        for (int k = 0; st == SS_OK && k < r->steps.n; ++k)
            ss_writer_describe(r->out.steps_w, k + 1, r->steps.labels[k], "Wh/m2");
    }
    return st;
}

/* The steps of one of the library's runs: the run's from k0 on. */
typedef struct {
    steps_state *steps;
    int k0;
} steps_part;

static ss_status sun_of_part_rows(ss_ctx *ctx, int k, int row0, int n_rows, ss_sun_step *step,
                                  void *user)
{
    steps_part *part = user;
    return sun_of_step_rows(ctx, part->k0 + k, row0, n_rows, step, part->steps);
}

/* The registry's run over all the steps, or with --years each over each
 * year's steps in turn into its block of bands. */
static ss_status run(insolation_run *r)
{
    const insolation_settings *set = &r->set;
    const ss_product_info *product = ss_product_named("insolation");
    ss_status st = SS_OK;
    for (int b = 0; st == SS_OK && b < r->blocks; ++b) {
        steps_part part = {&r->steps, r->blocks > 1 ? r->years.first[b] : 0};
        if (set->trees.trees.canopy)
            r->trees.lib.leaf_off = r->trees.leaf_off + part.k0;
        ss_product_sun sun = {.n_steps = r->blocks > 1 ? r->years.count[b] : r->steps.n,
                              .sun_rows = sun_of_part_rows,
                              .sun_user = &part,
                              .real_sky = r->have_weather,
                              .shadow_mode = r->job.plan.shadow_mode,
                              .trees = set->trees.trees.canopy ? &r->trees.lib : NULL};
        r->out.block = b;
        r->out.step0 = part.k0;
        run_progress_part(&r->job.run, b, r->blocks);
        ss_source src = job_source(&r->job, &r->bands);
        share_reducer reducer;
        ss_share share = share_of(&reducer, &r->job.run, job_bands(&r->job));
        st = share_end(&reducer, product->run(r->job.run.ctx, &src, &r->job.opt, &set->ins, &sun,
                                              set->steps_path ? 2u : 0u, &share, write_rows,
                                              &r->out));
    }
    run_progress_part(&r->job.run, 0, 1);
    return st;
}

static double steps_hours(const insolation_run *r)
{
    double hours = 0;
    for (int k = 0; k < r->steps.n; ++k)
        hours += r->steps.hours[k];
    return hours;
}

/* Names each block's bands by what its sums stand for: one calendar year
 * of --years each (with the hours its records span where they do not span
 * it), the mean year of several, else the year where the steps cover one
 * (8700 to 8800 hours) or the period. */
static void name_bands(insolation_run *r)
{
    const weather_years *y = &r->years;
    int pv = r->set.ins.pv, each = r->set.years == YEARS_EACH && !y->typical;
    char span[96], months[64] = "";
    for (int b = 0; b < r->blocks; ++b) {
        if (!r->have_weather) {
            span[0] = '\0';
        } else if (each && y->whole[b]) {
            snprintf(span, sizeof span, "%d", y->year[b]);
            snprintf(months, sizeof months, " %d", y->year[b]);
        } else if (each) {
            snprintf(span, sizeof span, "%d (%.0f of %.0f h)", y->year[b], y->hours[b],
                     y->year_hours[b]);
            snprintf(months, sizeof months, " %d", y->year[b]);
        } else if (r->set.years == YEARS_MEAN && y->n > 1) {
            snprintf(span, sizeof span, "mean year of %d-%d", y->first_year, y->last_year);
            snprintf(months, sizeof months, ", mean of %d-%d", y->first_year, y->last_year);
        } else {
            double hours = steps_hours(r);
            snprintf(span, sizeof span, "%s", hours >= 8700 && hours <= 8800 ? "year" : "period");
        }
        describe_bands(r->out.w, b * r->out.block_bands, r->have_weather, pv, span, months);
    }
}

/* The weather's years and what the run made of them, for the summary and
 * the metadata. */
static void describe_years(const insolation_run *r, char *buf, size_t size)
{
    const weather_years *y = &r->years;
    int n;
    if (y->typical)
        n = snprintf(buf, size, "1, a typical year of months from %d to %d, never split",
                     y->first_year, y->last_year);
    else if (y->n == 1)
        n = snprintf(buf, size, "1 (%d)", y->year[0]);
    else
        n = snprintf(buf, size, "%d calendar years, %d to %d: %s", y->n, y->first_year,
                     y->last_year,
                     r->set.years == YEARS_MEAN   ? "their mean year (the sums divided by them)"
                     : r->set.years == YEARS_EACH ? "each year's bands in turn"
                                                  : "summed (--years mean gives the mean "
                                                    "year, --years each every year's bands)");
    for (int j = 0; !y->typical && j < y->n && n > 0 && (size_t)n < size; ++j)
        if (!y->whole[j])
            n += snprintf(buf + n, size - (size_t)n, "; %d's records span %.0f of its %.0f h",
                          y->year[j], y->hours[j], y->year_hours[j]);
}

/* The run described in its outputs' metadata, into meta as well. */
static void describe_run(insolation_run *r, char *meta, size_t size)
{
    const insolation_settings *set = &r->set;
    ss_raster_writer *w = r->out.w;
    sweep_job *job = &r->job;
    run_common_metadata(&job->run, w, &job->opt, &job->frame);
    job_plan_metadata(job, w);
    const char *shadows = ss_shadow_mode_name(job->plan.shadow_mode);
    if (r->have_weather)
        snprintf(meta, size,
                 "%d weather records (%.0f h)%s%s; surface %s; sky diffuse %s; albedo %g "
                 "where the file gives none; shadows %s; solar constant %g W/m2; %s",
                 r->steps.n, steps_hours(r), r->text ? " inside " : "", r->text ? r->text : "",
                 set->ins.surface, ss_sky_model_name(r->io.sky_model), set->ins.albedo, shadows,
                 set->ins.solar_constant, r->weather_note);
    else
        snprintf(meta, size,
                 "%s, %d steps of %s evaluated at their middles; surface %s; Linke %s; "
                 "albedo %g; shadows %s; solar constant %g W/m2",
                 r->text, r->steps.n, set->ins.step, set->ins.surface, set->ins.linke,
                 set->ins.albedo, shadows, set->ins.solar_constant);
    ss_writer_metadata(w, "INSOLATION", meta);
    ss_writer_metadata(
        w, "MODEL",
        r->have_weather
            ? "real sky from weather records: beam = DNI x cos(incidence) where lit; sky "
              "diffuse by the chosen model with the terrain (isotropic part x the cell's "
              "tilted sky-view factor, circumsolar part shaded like the beam, Perez's "
              "horizon band x the share the cell sees); reflected = albedo x GHI x (1 - sky "
              "view); sun hours where lit with DNI >= 120 W/m2 (doc/insolation.md)"
            : "ESRA clear sky (r.sun); sky diffuse by Muneer with the cell's radiative "
              "sky-view factor; reflected = albedo x global horizontal x (1 - sky view)");
    if (set->ins.pv) {
        char pv[600];
        snprintf(pv, sizeof pv,
                 "DC yield per kWp of modules in each cell's surface (pvlib pvwatts_dc, pdc0 = "
                 "1): plane-of-array global, no reflection or spectral losses; cell "
                 "temperature by %s from the records' air temperature and wind (%g C, %g m/s "
                 "where they give none); gamma_pdc %g /K; system losses %g %%; AC yield "
                 "after pvlib.inverter.pvwatts (eta_inv_nom %g, DC/AC ratio %g)",
                 set->ins.temperature_model ? "sapm_cell (open rack glass/glass)"
                                            : "faiman (u0 25, u1 6.84)",
                 set->ins.temp_air_c, set->ins.wind_speed_m_s, set->ins.gamma_pdc,
                 set->ins.losses_percent, set->ins.inverter_efficiency_percent / 100.0,
                 set->ins.dc_ac_ratio);
        ss_writer_metadata(w, "PV", pv);
    }
    if (r->have_weather) {
        char years[600];
        describe_years(r, years, sizeof years);
        ss_writer_metadata(w, "YEARS", years);
    }
    if (set->trees.trees.canopy)
        insolation_trees_metadata(w, &set->trees, &r->trees, &r->job.opt);
    name_bands(r);
}

/* Commits rank 0's output, then the steps' file; aborts what is left. */
static ss_status commit(insolation_run *r, const char *meta)
{
    ss_status st = SS_OK;
    if (r->out.w) {
        st = run_commit(&r->job.run, r->out.w);
        r->out.w = NULL;
    }
    if (st == SS_OK && r->out.steps_w) {
        run_common_metadata(&r->job.run, r->out.steps_w, &r->job.opt, &r->job.frame);
        ss_writer_metadata(r->out.steps_w, "INSOLATION", meta);
        st = run_commit(&r->job.run, r->out.steps_w);
        r->out.steps_w = NULL;
    }
    ss_writer_abort(r->out.w);
    ss_writer_abort(r->out.steps_w);
    r->out.w = r->out.steps_w = NULL;
    return st;
}

/* The summary's line of the global (and the PV yields) of block b: the
 * year's with --years each, else the run's (of the mean year with --years
 * mean). */
static void print_block_sums(const insolation_run *r, int b)
{
    const insolation_settings *set = &r->set;
    const run_tally *tally = &r->out.tally[3 * b];
    double lo, mean, hi, scale = (r->have_weather ? 1000.0 : 1.0) * r->out.years;
    char year[16] = "";
    if (r->blocks > 1)
        snprintf(year, sizeof year, " %d", r->years.year[b]);
    run_tally_result(&tally[0], NAN, &lo, &mean, &hi);
    printf("global %s min %.1f mean %.1f max %.1f %s -> %s\n", year, lo / scale, mean / scale,
           hi / scale, r->have_weather ? "kWh/m2" : "Wh/m2", r->job.output);
    if (!set->ins.pv)
        return;
    int band = b * r->out.block_bands + WEATHER_BANDS;
    ss_counters c = ss_ctx_counters(r->job.run.ctx);
    run_tally_result(&tally[1], NAN, &lo, &mean, &hi);
    printf("pv     %s min %.1f mean %.1f max %.1f kWh/kWp (band %d); %llu records without "
           "air temperature or wind took %g C, %g m/s\n",
           year, lo / r->out.years, mean / r->out.years, hi / r->out.years, band + 1,
           (unsigned long long)c.records_without_temperature, set->ins.temp_air_c,
           set->ins.wind_speed_m_s);
    run_tally_result(&tally[2], NAN, &lo, &mean, &hi);
    printf("pv ac  %s min %.1f mean %.1f max %.1f kWh/kWp (band %d) after an inverter of "
           "%g %% at a DC/AC ratio of %g\n",
           year, lo / r->out.years, mean / r->out.years, hi / r->out.years, band + 2,
           set->ins.inverter_efficiency_percent, set->ins.dc_ac_ratio);
}

static void print_summary(insolation_run *r)
{
    const insolation_settings *set = &r->set;
    sweep_job *job = &r->job;
    ss_counters c = ss_ctx_counters(job->run.ctx);
    run_print_dem(&job->run, &job->dem, &job->frame);
    if (r->have_weather) {
        unsigned long long dropped = c.records_missing + c.records_light_at_night +
                                     c.records_dni_above_extraterrestrial;
        printf("weather %s\n        %llu records missing, %llu split from GHI alone "
               "(Erbs), %llu with DNI from GHI and DHI (closure), %llu with beam on the "
               "horizontal above the global (used as given), %llu with light while the sun "
               "is down (not used), %llu with DNI above the extraterrestrial (not used)\n",
               r->weather_note, (unsigned long long)c.records_missing,
               (unsigned long long)c.records_split,
               (unsigned long long)c.records_dni_from_closure,
               (unsigned long long)c.records_beam_above_global,
               (unsigned long long)c.records_light_at_night,
               (unsigned long long)c.records_dni_above_extraterrestrial);
        printf("        records used %llu (daylight), filled %llu (by the models), dropped "
               "%llu (missing, light at night, DNI above the extraterrestrial); %zu absent "
               "from the file's spacing\n",
               (unsigned long long)c.time_steps,
               (unsigned long long)(c.records_split + c.records_dni_from_closure), dropped,
               r->weather.gaps);
        char years[600];
        describe_years(r, years, sizeof years);
        printf("years   %s\n", years);
    }
    command_print_job_sweep(job, &r->bands);
    printf("steps   %d: %llu in daylight, %llu at night skipped, %llu shadow sweeps skipped "
           "(sun above every horizon)",
           r->steps.n, (unsigned long long)c.time_steps,
           (unsigned long long)c.night_steps_skipped, (unsigned long long)c.shadow_sweeps_skipped);
    if (r->have_weather)
        printf(", %llu more (records with neither beam nor circumsolar light)",
               (unsigned long long)c.shadow_sweeps_unshaded);
    printf("\n");
    if (c.shadow_steps)
        printf("shadows %llu of the shadow walks' %llu samples (%.1f %%) not walked: past the "
               "last cell of their line whose proven horizon bound the sun may not clear\n",
               (unsigned long long)c.shadow_steps_skipped, (unsigned long long)c.shadow_steps,
               100.0 * (double)c.shadow_steps_skipped / (double)c.shadow_steps);
    if (c.box_march_steps)
        printf("shadows %llu steps of box shadows by each cell's own ray: %llu of %llu cell-steps "
               "(%.1f %%) marched, the rest settled by proven bounds\n",
               (unsigned long long)c.box_march_steps, (unsigned long long)c.box_march_marched,
               (unsigned long long)c.box_march_cells,
               100.0 * (double)c.box_march_marched / (double)c.box_march_cells);
    if (c.crown_march_steps)
        printf("trees   %llu suns' crowns by each cell's own ray: %llu of %llu cell-steps "
               "(%.1f %%) marched, the rest settled by a proven bound\n",
               (unsigned long long)c.crown_march_steps, (unsigned long long)c.crown_march_marched,
               (unsigned long long)c.crown_march_cells,
               100.0 * (double)c.crown_march_marched / (double)c.crown_march_cells);
    uint64_t host_cells = c.cell_steps - c.cell_steps_on_device;
    if (c.cell_steps_on_device)
        printf("cells   %llu cell-steps on the device (the sun's terms per cell; the horizons "
               "never left it)\n",
               (unsigned long long)c.cell_steps_on_device);
    if (host_cells)
        printf("cells   %llu cell-steps%s, %llu (%.1f %%) with the sun's terms computed per cell "
               "(outside the step's tables, or more than 0.5 rad from the centre's sun)\n",
               (unsigned long long)host_cells, c.cell_steps_on_device ? " on the host" : "",
               (unsigned long long)c.cell_steps_exact_sun,
               100.0 * (double)c.cell_steps_exact_sun / (double)host_cells);
    if (c.sun_bins)
        printf("sky     cumulative: %llu bins of suns (%d directions x %g deg of elevation x "
               "month) in place of a sweep per record\n",
               (unsigned long long)c.sun_bins, job->opt.directions, set->ins.elevation_step_deg);
    if (share_size() > 1)
        printf("share   %d MPI processes, time steps dealt round-robin (the counts above are "
               "this one's), sums added at rank 0\n",
               share_size());
    if (set->trees.trees.canopy)
        insolation_trees_print(&set->trees, &r->trees, &r->job.opt, r->steps.n, r->shadows_forced,
                               c.sun_bins != 0);
    for (int b = 0; b < r->blocks; ++b)
        print_block_sums(r, b);
}

static void close_run(insolation_run *r)
{
    ss_writer_abort(r->out.w);
    ss_writer_abort(r->out.steps_w);
    if (r->steps.have_field)
        ss_sun_field_free(&r->steps.field);
    steps_free(&r->steps);
    years_free(&r->years);
    ss_weather_free(&r->weather);
    free(r->out.row);
    free(r->out.tally);
    free(r->text);
    insolation_trees_free(&r->trees);
    job_close(&r->job);
}

int cmd_insolation(int argc, char **argv)
{
    insolation_run *r = calloc(1, sizeof *r);
    if (!r) {
        fprintf(stderr, "skysweep insolation: out of memory\n");
        return SS_ERR_MEMORY;
    }
    insolation_settings *set = &r->set;
    common_settings_init(&set->common);
    opt_spec insolation_options[32];
    opt_from_params("insolation", offsetof(insolation_settings, ins), insolation_options, 32);
    opt_spec tree_opts[TREE_OPTIONS_MAX], season_opts[INSOLATION_TREE_OPTIONS_MAX];
    insolation_tree_options(offsetof(insolation_settings, trees), tree_opts, season_opts);
    const opt_spec *tables[] = {insolation_options,
                                file_options,
                                tree_opts,
                                season_opts,
                                crown_light_options(offsetof(insolation_settings, trees) +
                                                    offsetof(insolation_tree_settings, light)),
                                sun_options(),
                                common_options(),
                                NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse(
        "insolation", tables, set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 2,
        "skysweep insolation --time START/END|START/DURATION [--step PT30M] [options] DEM... "
        "OUTPUT\n       skysweep insolation --weather FILE [--sky-model M] [options] DEM... OUTPUT",
        ss_product_named("insolation")->description,
        &set->common.device);
    /* Options another makes meaningless are refused, not ignored, where
     * their value is not the default (front ends pass every default). */
    if (rc < 0 && (isfinite(set->common.sun.sun_azimuth_deg) ||
                   isfinite(set->common.sun.sun_elevation_deg)))
        rc = run_usage_error("insolation", "insolation follows the sun over --time or the "
                                           "weather's records: --sun-azimuth and "
                                           "--sun-elevation are for shadow and hillshade");
    if (rc < 0 && set->weather &&
        (strcmp(set->ins.step, opt_find(tables, "step")->default_text) != 0 ||
         strcmp(set->ins.linke, opt_find(tables, "linke")->default_text) != 0))
        rc = run_usage_error("insolation", "with --weather each record is a step and its "
                                           "irradiance is measured: --step and --linke are for "
                                           "the clear sky");
    if (rc < 0 && !set->weather && set->years != YEARS_TOTAL)
        rc = run_usage_error("insolation", "--years is for --weather: a clear-sky run sums "
                                           "its own --time range");
    /* Under mpirun every process evaluates every N-th step; a band per step
     * would have to travel whole to rank 0. */
    if (rc < 0 && share_size() > 1 && set->steps_path)
        rc = share_rank() == 0 ? run_usage_error("insolation", "--steps is not shared between "
                                                               "MPI processes: run it alone")
                               : 2;
    /* Bands hold a horizon's sums and the cells' insolation terms and sums
     * (more than the radiative SVF's band before them). */
    int directions = set->common.sweep.directions > SS_INSOLATION_STEPS_PER_RUN
                         ? set->common.sweep.directions
                         : SS_INSOLATION_STEPS_PER_RUN;
    /* Stored horizons are counted wherever the planner may choose them. */
    int want = (set->weather ? SS_INSOLATION_MONTHLY : 0) | (set->ins.pv ? SS_INSOLATION_PV : 0) |
               (set->steps_path ? SS_INSOLATION_STEPS : 0);
    ss_shadow_mode shadow = ss_insolation_params_shadow(&set->ins);
    if (rc < 0)
        rc = insolation_trees_usage(tables, set, &set->trees);
    /* Beer-Lambert takes the beam and the sky through crowns of leaf-on
     * steps: --transmissivity would reach nothing. */
    if (rc < 0)
        rc = crown_light_alone("insolation", tables, set, &set->trees.light,
                               set->trees.trees.canopy != NULL);
    if (rc < 0 && set->trees.light.beer_lambert && shadow == SS_SHADOW_CUMULATIVE)
        rc = run_usage_error("insolation", "--crown-light beer-lambert takes exact or "
                                           "interpolated shadows: the cumulative sky keeps one "
                                           "bit a cell per sun bin for its crowns, no path");
    /* Trees: auto takes exact shadows. The planner's error tables have no
     * trees, and the cumulative sky's error with crowns is measured on one
     * small scene only (doc/cumulative_sky.md, "Trees"), so it is given on
     * request (--shadow cumulative), not chosen. */
    r->shadows_forced = set->trees.trees.canopy && shadow == SS_SHADOW_AUTO;
    if (r->shadows_forced)
        shadow = SS_SHADOW_EXACT;
    /* Auto may choose interpolated shadows for a weather file (with --pv
     * too) without --steps (doc/planner.md). */
    int stores = shadow == SS_SHADOW_INTERPOLATED || shadow == SS_SHADOW_CUMULATIVE ||
                 (shadow == SS_SHADOW_AUTO && set->weather && !set->steps_path);
    /* Exact shadows by each cell's own ray hold the heights whole; those
     * walked, their bounds' blocks. */
    int exact = shadow != SS_SHADOW_INTERPOLATED && shadow != SS_SHADOW_CUMULATIVE;
    double march_bytes = exact ? run_march_cell_bytes(&set->common) : 0.0;
    /* The sky view by each cell's own ray holds them too, before the steps,
     * and so do Perez's band and the stored horizons (horizon_walk.c). */
    double sky_bytes = run_box_sky_cell_bytes(&set->common);
    double bounds_bytes = exact && march_bytes == 0.0 ? ss_insolation_grid_cell_bytes() : 0.0;
    double trees_bytes =
        !set->trees.trees.canopy ? 0.0
        : shadow == SS_SHADOW_CUMULATIVE
            ? INSOLATION_TREES_CELL_BYTES +
                  insolation_cumulative_crown_bytes(directions, set->ins.elevation_step_deg)
        : set->trees.light.beer_lambert
            ? INSOLATION_TREES_CELL_BYTES + INSOLATION_BEER_LAMBERT_CELL_BYTES
            : INSOLATION_TREES_CELL_BYTES;
    /* Exact shadows by each cell's own ray walk no lines, nor do stored
     * shadows: with the sky view's horizons by each cell's own ray too and
     * no trees (whose sky view walks lines) no hull is handed on; else only
     * the sky view's (its directions, 32 for box lines where the planner
     * chooses, each of its box lines). */
    int no_lines = sky_bytes > 0 && (march_bytes > 0 || !exact) && !set->trees.trees.canopy;
    int sky_directions = set->common.sweep.directions ? set->common.sweep.directions : 32;
    band_cost cost = {.cell_bytes = ss_horizon_band_cell_bytes(0) +
                                    ss_insolation_band_cell_bytes(want, stores ? directions : 0),
                      .column_bytes = ss_horizon_column_bytes(),
                      .directions = directions,
                      .grid_cell_bytes =
                          (march_bytes > sky_bytes ? march_bytes : sky_bytes) + bounds_bytes +
                          trees_bytes,
                      .hull_lines = no_lines ? 1
                                    : march_bytes > 0 && !stores
                                        ? sky_directions *
                                              ss_sweep_params_sky_box_lines(&set->common.sweep)
                                        : 0};
    if (rc < 0)
        rc = job_open_banded(&r->job, "insolation", &set->common, pos, n_pos, cost);
    if (rc != 0 || !r->job.run.ctx) { /* --help, or the job failed and is closed */
        free(r);
        return rc;
    }
    ss_status st = prepare(r);
    if (st == SS_OK) {
        if (r->shadows_forced && set->common.plan_only && !r->job.run.quiet)
            printf("trees   shadows exact: with --canopy the planner does not choose "
                   "interpolated or cumulative shadows\n");
        ss_insolation_params planned = set->ins;
        if (r->shadows_forced)
            planned.shadow = 1; /* "exact" of auto|exact|interpolated|cumulative */
        rc = job_plan(&r->job, &set->common, ss_product_named("insolation"), &planned,
                      r->steps.n, r->steps.mid_s);
        if (rc >= 0) { /* --plan, or a plan that failed */
            close_run(r);
            free(r);
            return rc;
        }
        r->steps.sun_spread_deg = r->job.frame.diagonal_m /
                                  (2.0 * run_earth_radius(&set->common, &r->job.frame)) * 180 /
                                  M_PI;
    }
    if (st == SS_OK && set->trees.trees.canopy)
        st = insolation_trees_open(&r->job, &set->trees, r->steps.mid_s, r->steps.n, &r->trees);
    if (st == SS_OK)
        st = open_outputs(r);
    if (st == SS_OK)
        st = run(r);
    char meta[1400] = "";
    if (st == SS_OK && r->out.w)
        describe_run(r, meta, sizeof meta);
    if (st == SS_OK)
        st = commit(r, meta);
    rc = job_finish(&r->job, st);
    if (st == SS_OK && !r->job.run.quiet)
        print_summary(r);
    close_run(r);
    free(r);
    return rc;
}
