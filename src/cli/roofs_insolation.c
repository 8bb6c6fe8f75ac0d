/* skysweep roofs' insolation run and its skies: the command line passed on
 * to `skysweep insolation --weather F --pv` (every option that is not
 * roofs' own), the weather's records as the steps of the planes with no
 * horizon, and without --weather the records of a clear sky. */
#include "config.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "roofs.h"
#include "skysweep_sun.h"
#include "temporaries.h"
#include "temporary_name.h"

/* Whether spec is one of roofs' own options. */
static int is_own(const opt_spec *own, const opt_spec *spec)
{
    for (; own->name; ++own)
        if (own == spec)
            return 1;
    return 0;
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
static int insolation_args(const opt_spec *const *tables, const opt_spec *own, int argc,
                           char **argv,
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
        if (!spec || !is_own(own, spec)) {
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
    if (clear_sky) { /* the clear sky's records roofs wrote (roofs_write_clear_sky) */
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

/* Runs insolation into a hidden neighbour raster (its path) of OUTPUT, or
 * of `kept` (--cell-raster), which write_outputs renames it to: the
 * windows read it back and close_run removes what is left. With --plan,
 * insolation prints its plan and nothing is kept. Returns the exit code
 * (0: done). */
int roofs_run_insolation(sweep_job *job, const opt_spec *const *tables, const opt_spec *own,
                         int argc, char **argv, const char *clear_sky, const char *kept,
                         char *raster, size_t size)
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
    int n = insolation_args(tables, own, argc, argv, clear_sky, job->inputs, job->n_inputs, raster, args,
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


ss_status roofs_sky_step_at(ss_ctx *ctx, int index, ss_sun_step *step, void *user)
{
    (void)ctx;
    *step = ((const sky_steps *)user)->steps[index];
    return SS_OK;
}

ss_status roofs_sky_steps(sweep_job *job, const roofs_settings *set, const ss_weather *w,
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
ss_status roofs_write_clear_sky(sweep_job *job, const roofs_settings *set, char *path,
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
