/* The parameter table (skysweep_params.h): each product's parameters, once,
 * and what they become in the library's calls. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "box_lines_table.h"
#include "ctx_internal.h"
#include "skysweep_params.h"
#include "skysweep_sun.h"

#define END {NULL, SS_PARAM_FLAG, 0, NULL, NULL, 0, 0, NULL, NULL}

#define SWEEP(field) offsetof(ss_sweep_params, field)
static const ss_param sweep_params[] = {
    {"directions", SS_PARAM_INT, SWEEP(directions), "N", NULL, 1, 1000000, NULL,
     "number of azimuth directions, evenly spaced (default: chosen by the planner from "
     "--svf-tolerance)"},
    {"offset", SS_PARAM_DOUBLE, SWEEP(offset_deg), "DEG", "0", -360, 360, NULL,
     "azimuth of the first direction, degrees clockwise from north"},
    {"north", SS_PARAM_CHOICE, SWEEP(north), NULL, "auto", 0, 0, "auto|true|grid",
     "azimuths from true north (meridian convergence at the DEM's centre taken out) or from "
     "the grid's north; auto: true north where they differ by more than "
     "--horizon-tolerance"},
    {"curvature", SS_PARAM_CHOICE, SWEEP(curvature), NULL, "auto", 0, 0, "auto|on|off",
     "earth curvature with terrestrial refraction; auto: on where it moves horizons by more "
     "than the tolerance"},
    {"refraction", SS_PARAM_DOUBLE, SWEEP(refraction_k), "K", "0.13", 0, 0.99, NULL,
     "terrestrial refraction coefficient k (R_eff = R / (1 - k))"},
    {"earth-radius", SS_PARAM_DOUBLE, SWEEP(earth_radius_m), "METRES", NULL, 1e3, 1e9, NULL,
     "earth radius for curvature (default: the ellipsoid's mean radius at the DEM's centre)"},
    {"horizon-tolerance", SS_PARAM_DOUBLE, SWEEP(horizon_tolerance_deg), "DEG", "0.05", 1e-9,
     90, NULL,
     "horizon (and shadow, azimuth) error the run may allow; the planner follows it"},
    {"svf-tolerance", SS_PARAM_DOUBLE, SWEEP(svf_tolerance), "SVF", "0.01", 1e-9, 1, NULL,
     "sky-view factor error the run may allow"},
    {"sun-tolerance", SS_PARAM_DOUBLE, SWEEP(sun_tolerance_deg), "DEG", "0.001", 1e-9, 90, NULL,
     "error in the sun's direction per cell the run may allow"},
    {"lines", SS_PARAM_CHOICE, SWEEP(lines), NULL, "auto", 0, 0,
     "auto|interpolated|digital|box",
     "interpolated: samples on exact lines, heights interpolated across them; digital: lines "
     "through cell centres; box: cells as flat-topped columns, for city DSMs with vertical "
     "walls; auto: box where neighbouring cells step like walls, else interpolated "
     "(doc/model.md)"},
    {"box-lines", SS_PARAM_INT, SWEEP(box_lines), "N", NULL, 1, SS_BOX_LINES_MAX, NULL,
     "box lines per cell across, a power of two: a cell's line runs at most 1/(2N) cell beside "
     "its centre; time grows with N (default: for the sky view the fewest whose measured SVF "
     "error meets --svf-tolerance, doc/box_lines.md; else 32)"},
    {"box-shadows", SS_PARAM_CHOICE, SWEEP(box_shadows), NULL, "march", 0, 0, "march|lines",
     "box lines' cast shadows and crowns: march: each cell's own ray, exact, settled by "
     "proven bounds where it can be, on the host whatever the device (in bands it holds the "
     "heights whole, 4 bytes a cell); lines: the --box-lines walks (doc/box_lines.md)"},
    {"box-sky", SS_PARAM_CHOICE, SWEEP(box_sky), NULL, "march", 0, 0, "march|lines",
     "box lines' sky view and horizons (SVF, openness, horizon rasters, the sky terms of "
     "hillshade and insolation, Perez's band, stored horizons): march: "
     "each cell's own ray, the box model exactly, on the host whatever the device (in bands it "
     "holds the heights whole, 4 bytes a cell); lines: the --box-lines walks "
     "(doc/box_lines.md)"},
    END};

#define SUN(field) offsetof(ss_sun_params, field)
static const ss_param sun_params[] = {
    {"time", SS_PARAM_TEXT, SUN(time), "ISO8601", NULL, 0, 0, NULL,
     "when: an instant with a zone, e.g. 2026-06-21T10:00Z (the sun from SPA at the DEM)"},
    {"sun-azimuth", SS_PARAM_DOUBLE, SUN(sun_azimuth_deg), "DEG", NULL, -360, 360, NULL,
     "or the sun given directly: azimuth clockwise from north ..."},
    {"sun-elevation", SS_PARAM_DOUBLE, SUN(sun_elevation_deg), "DEG", NULL, -90, 90, NULL,
     "... and apparent elevation above the horizontal"},
    {"sun-per-cell", SS_PARAM_CHOICE, SUN(sun_per_cell), NULL, "auto", 0, 0, "auto|on|off",
     "the sun's position per cell (rotated into each cell's frame) or one for the DEM; auto: "
     "per cell when they differ by more than --sun-tolerance"},
    {"delta-t", SS_PARAM_DOUBLE, SUN(delta_t_s), "SECONDS", NULL, -8000, 8000, NULL,
     "TT - UT1 (default: the Espenak-Meeus model)"},
    {"pressure", SS_PARAM_DOUBLE, SUN(pressure_hpa), "HPA", "1013.25", 0, 5000, NULL,
     "air pressure for refraction"},
    {"temperature", SS_PARAM_DOUBLE, SUN(temperature_c), "C", "12", -273, 100, NULL,
     "air temperature for refraction"},
    END};

static const ss_param svf_params[] = {
    {"definition", SS_PARAM_CHOICE, offsetof(ss_svf_params, definition), NULL, "geometric", 0, 0,
     "geometric|radiative|horizontal",
     "geometric: 1 - mean sin h (Zaksek/RVT); radiative: cosine-weighted sky seen by the "
     "sloping cell (Dozier & Frew); horizontal: cosine-weighted, horizontal surface"},
    {"radius", SS_PARAM_DOUBLE, offsetof(ss_svf_params, radius_m), "METRES", "0", 0, 1e7, NULL,
     "look for the horizon only this far, as RVT and SAGA do (geometric or horizontal; exact, "
     "about 3x the unlimited sweep's cost whatever the radius); 0: unlimited, the exact sweep "
     "horizon"},
    END};

static const ss_param openness_params[] = {
    {"kind", SS_PARAM_CHOICE, offsetof(ss_openness_params, kind), NULL, "positive", 0, 0,
     "positive|negative",
     "positive: 90 deg minus the mean horizon elevation (valleys low, ridges high); negative: "
     "the same for the inverted surface (ridges low, valleys high)"},
    {"radius", SS_PARAM_DOUBLE, offsetof(ss_openness_params, radius_m), "METRES", "0", 0, 1e7,
     NULL,
     "look for the horizon only this far (the classical radius-limited openness; exact, about "
     "3x the unlimited sweep's cost whatever the radius); 0: unlimited, the exact sweep horizon"},
    END};

#define SHADE(field) offsetof(ss_hillshade_params, field)
static const ss_param hillshade_params[] = {
    {"az", SS_PARAM_DOUBLE, SHADE(azimuth_deg), "DEG", "315", -360, 360, NULL,
     "light azimuth, degrees clockwise from the top of the raster (gdaldem's -az)"},
    {"alt", SS_PARAM_DOUBLE, SHADE(altitude_deg), "DEG", "45", 0, 90, NULL,
     "light altitude above the horizontal (gdaldem's -alt)"},
    {"z", SS_PARAM_DOUBLE, SHADE(z_factor), "FACTOR", "1", 1e-6, 1e6, NULL,
     "vertical exaggeration (gdaldem's -z; ground sizes come from the CRS, so gdaldem's -s "
     "is not needed)"},
    {"alg", SS_PARAM_CHOICE, SHADE(alg), NULL, "Horn", 0, 0, "Horn|ZevenbergenThorne",
     "slope algorithm (gdaldem's -alg)"},
    {"multidirectional", SS_PARAM_FLAG, SHADE(multidirectional), NULL, NULL, 0, 0, NULL,
     "gdaldem's multidirectional shading (lights from 225, 270, 315, 360)"},
    {"cast-shadows", SS_PARAM_FLAG, SHADE(cast_shadows), NULL, NULL, 0, 0, NULL,
     "darken cells in the light's cast shadows (exact sweep along the light)"},
    {"sky-view", SS_PARAM_DOUBLE, SHADE(sky_view), "WEIGHT", "0", 0, 1, NULL,
     "blend in sky-view shading: (1 - W) hillshade + W (1 + 254 SVF), geometric SVF over "
     "--directions"},
    {"blend", SS_PARAM_CHOICE, SHADE(blend), NULL, "none", 0, 0, "none|vat",
     "vat: RVT's relief blend for archaeology and cartography (hillshade 315/35, slope, "
     "positive openness, SVF; doc/relief.md) instead of the plain hillshade"},
    {"blend-radius", SS_PARAM_DOUBLE, SHADE(blend_radius_cells), "CELLS", "10", 0, 1e6, NULL,
     "how far the blend's SVF and openness look for the horizon, in cells (RVT's default "
     "10); 0: unlimited"},
    END};

#define INSOL(field) offsetof(ss_insolation_params, field)
static const ss_param insolation_params[] = {
    {"step", SS_PARAM_TEXT, INSOL(step), "DURATION", "PT30M", 0, 0, NULL,
     "time step (ISO 8601 duration); each step is evaluated at its middle"},
    {"linke", SS_PARAM_TEXT, INSOL(linke), "T[,T...]", "3", 0, 0, NULL,
     "Linke turbidity (air mass 2): one value, or 12 for January..December"},
    {"albedo", SS_PARAM_DOUBLE, INSOL(albedo), "A", "0.2", 0, 1, NULL, "ground albedo"},
    {"shadow", SS_PARAM_CHOICE, INSOL(shadow), NULL, "auto", 0, 0,
     "auto|exact|interpolated|cumulative",
     "exact: a sweep at each step's sun azimuth; interpolated: horizons stored at --directions "
     "and interpolated; cumulative (--weather): the suns binned by direction and "
     "--elevation-step, each bin lit at its direction's horizon; auto: for 720 weather records "
     "or more without --steps, the cheapest mode whose measured error meets "
     "--insolation-tolerance, else exact (doc/planner.md)"},
    {"insolation-tolerance", SS_PARAM_DOUBLE, INSOL(tolerance_percent), "PERCENT", "0.5", 0, 100,
     NULL,
     "with --weather and --shadow auto: the error (p95, %) a cell's annual and monthly sums and "
     "PV yield may take; interpolated shadows or the cumulative sky are chosen where their "
     "measured error is within it (doc/shadow_modes.md), 0: exact shadows"},
    {"elevation-step", SS_PARAM_DOUBLE, INSOL(elevation_step_deg), "DEG", "1", 0.01, 90, NULL,
     "with --shadow cumulative: height of a sun bin"},
    {"solar-constant", SS_PARAM_DOUBLE, INSOL(solar_constant), "W/M2", "1367", 1000, 2000, NULL,
     "extraterrestrial irradiance at 1 AU (r.sun's default)"},
    {"sky-model", SS_PARAM_CHOICE, INSOL(sky_model), NULL, "perez", 0, 0,
     "perez|haydavies|isotropic",
     "with --weather: sky diffuse on the tilted cell, with the terrain (doc/insolation.md)"},
    {"surface", SS_PARAM_TEXT, INSOL(surface), "cell|horizontal|TILT,AZIMUTH", "cell", 0, 0, NULL,
     "the surface irradiated in each cell: its own slope (roofs, terrain), a horizontal one, or "
     "a module tilted TILT degrees facing AZIMUTH (clockwise from north); shadows and horizons "
     "stay the cell's"},
    {"pv", SS_PARAM_FLAG, INSOL(pv), NULL, NULL, 0, 0, NULL,
     "with --weather: add the PV yield (kWh/kWp) of modules lying in each cell's surface, "
     "PVWatts-style as pvlib"},
    {"gamma-pdc", SS_PARAM_DOUBLE, INSOL(gamma_pdc), "1/K", "-0.0047", -0.05, 0.05, NULL,
     "with --pv: the modules' power temperature coefficient (PVWatts' standard module)"},
    {"temperature-model", SS_PARAM_CHOICE, INSOL(temperature_model), NULL, "faiman", 0, 0,
     "faiman|sapm",
     "with --pv: cell temperature (pvlib.temperature.faiman, or sapm_cell open rack "
     "glass/glass)"},
    {"losses", SS_PARAM_DOUBLE, INSOL(losses_percent), "PERCENT", "11.42", 0, 99, NULL,
     "with --pv: system losses; pvlib's pvwatts_losses without its 3 % for shading, which the "
     "terrain gives exactly"},
    {"temp-air", SS_PARAM_DOUBLE, INSOL(temp_air_c), "C", "20", -90, 70, NULL,
     "with --pv: air temperature where a record gives none"},
    {"wind-speed", SS_PARAM_DOUBLE, INSOL(wind_speed_m_s), "M/S", "0", 0, 99, NULL,
     "with --pv: wind speed where a record gives none"},
    {"inverter-efficiency", SS_PARAM_DOUBLE, INSOL(inverter_efficiency_percent), "PERCENT", "96",
     1, 100, NULL,
     "with --pv: the inverter's nominal efficiency (pvlib.inverter.pvwatts' eta_inv_nom) for the "
     "AC yield"},
    {"dc-ac-ratio", SS_PARAM_DOUBLE, INSOL(dc_ac_ratio), "RATIO", "1.2", 0.1, 10, NULL,
     "with --pv: the modules' DC nameplate over the inverter's AC rating (PVWatts' 1.2); above "
     "it the inverter clips"},
    END};

static const ss_param_table tables[] = {
    {"sweep", "what every sweeping product takes: directions, the effects, the line model",
     sweep_params},
    {"sun", "the sun of one instant, or given directly", sun_params},
    {"svf", "sky-view factor", svf_params},
    {"openness", "topographic openness", openness_params},
    {"hillshade", "shaded relief", hillshade_params},
    {"insolation", "clear-sky or real-sky irradiation over time steps, and PV yield",
     insolation_params},
};

const ss_param_table *ss_param_table_named(const char *name)
{
    for (size_t i = 0; name && i < sizeof tables / sizeof tables[0]; ++i)
        if (strcmp(tables[i].name, name) == 0)
            return &tables[i];
    return NULL;
}

const char *ss_param_choice(const char *table, const char *param, int index, char *buf,
                            size_t size)
{
    const ss_param_table *t = ss_param_table_named(table);
    if (size)
        buf[0] = '\0';
    for (const ss_param *p = t ? t->params : NULL; p && p->name; ++p) {
        if (strcmp(p->name, param) != 0 || !p->choices)
            continue;
        const char *word = p->choices;
        for (int i = 0; i < index && word; ++i)
            word = strchr(word, '|') ? strchr(word, '|') + 1 : NULL;
        if (word && index >= 0 && size)
            snprintf(buf, size, "%.*s", (int)strcspn(word, "|"), word);
    }
    return buf;
}

void ss_sun_params_init(ss_sun_params *p)
{
    p->sun_azimuth_deg = p->sun_elevation_deg = p->delta_t_s = NAN;
}

ss_status ss_sun_params_check(ss_ctx *ctx, const ss_sun_params *p, double *unix_s)
{
    ss_call_begin(ctx);
    *unix_s = NAN;
    int given = isfinite(p->sun_azimuth_deg) || isfinite(p->sun_elevation_deg);
    if (given && p->time)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "give the sun either as --time or as --sun-azimuth and --sun-elevation, "
                       "not both");
    if (given && !(isfinite(p->sun_azimuth_deg) && isfinite(p->sun_elevation_deg)))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "--sun-azimuth and --sun-elevation go together");
    if (!given && !p->time)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "no sun: give --time, or --sun-azimuth and --sun-elevation");
    return given ? SS_OK : ss_parse_instant(ctx, p->time, unix_s);
}

void ss_sun_params_spa(const ss_sun_params *p, ss_spa_params *spa)
{
    ss_spa_params_default(spa);
    spa->delta_t_s = p->delta_t_s;
    spa->pressure_hpa = p->pressure_hpa;
    spa->temperature_c = p->temperature_c;
}

/* "auto|on|off" as the planner's switch. */
static ss_switch switch_of(int choice)
{
    return choice == SS_CHOICE_AUTO ? SS_AUTO : choice == SS_CHOICE_ON ? SS_ON : SS_OFF;
}

ss_line_model ss_sweep_params_lines(const ss_sweep_params *p)
{
    return (ss_line_model)(p->lines - 1); /* the choices' words start with auto */
}

void ss_sweep_params_request(const ss_sweep_params *p, const ss_sun_params *sun,
                             ss_plan_request *req)
{
    req->horizon_tolerance_deg = p->horizon_tolerance_deg;
    req->svf_tolerance = p->svf_tolerance;
    req->sun_tolerance_deg = p->sun_tolerance_deg;
    req->curvature = switch_of(p->curvature);
    req->true_north = p->north == SS_NORTH_AUTO ? SS_AUTO : p->north == SS_NORTH_TRUE ? SS_ON : SS_OFF;
    req->sun_per_cell = sun ? switch_of(sun->sun_per_cell) : SS_OFF;
    req->refraction_k = p->refraction_k;
    req->directions = p->directions;
    req->lines = ss_sweep_params_lines(p);
    req->box_lines = p->box_lines;
    req->box_shadows = (ss_box_shadows)p->box_shadows;
    req->box_sky = (ss_box_sky)p->box_sky;
}

void ss_sweep_params_options(const ss_sweep_params *p, const ss_place *place,
                             ss_sweep_options *opt)
{
    ss_sweep_options_default(opt);
    opt->directions = p->directions ? p->directions : 32;
    opt->offset_deg = p->offset_deg;
    if (p->curvature == SS_CHOICE_ON) {
        opt->earth_radius_m = p->earth_radius_m > 0   ? p->earth_radius_m
                              : place                ? place->earth_radius_m
                                                     : SS_EARTH_RADIUS_MEAN_M;
        opt->refraction_k = p->refraction_k;
    }
    ss_line_model asked = ss_sweep_params_lines(p);
    opt->lines = asked == SS_LINES_AUTO ? SS_LINES_INTERPOLATED : asked;
    opt->box_lines = p->box_lines ? p->box_lines : SS_BOX_LINES_DEFAULT;
    opt->box_shadows = (ss_box_shadows)p->box_shadows;
    opt->box_sky = (ss_box_sky)p->box_sky;
    opt->grid_north_deg = place && p->north != SS_NORTH_GRID ? place->grid_north_deg : 0.0;
}

int ss_sweep_params_box_lines_most(const ss_sweep_params *p)
{
    if (p->box_lines)
        return p->box_lines;
    int sky_view = ss_box_lines_for_tolerance(p->svf_tolerance, NULL);
    return sky_view > SS_BOX_LINES_DEFAULT ? sky_view : SS_BOX_LINES_DEFAULT;
}

int ss_sweep_params_sky_box_lines(const ss_sweep_params *p)
{
    if (p->box_lines)
        return p->box_lines;
    int sky_view = ss_box_lines_for_tolerance(p->svf_tolerance, NULL);
    return sky_view < SS_BOX_LINES_DEFAULT ? sky_view : SS_BOX_LINES_DEFAULT;
}

ss_sky_term ss_svf_params_term(const ss_svf_params *p)
{
    /* In the choices' order. */
    static const ss_sky_term terms[] = {SS_SKY_SVF_GEOMETRIC, SS_SKY_SVF_RADIATIVE,
                                        SS_SKY_SVF_HORIZONTAL};
    return terms[p->definition >= 0 && p->definition < 3 ? p->definition : 0];
}

ss_sky_term ss_openness_params_term(const ss_openness_params *p)
{
    return p->kind ? SS_SKY_OPENNESS_NEGATIVE : SS_SKY_OPENNESS_POSITIVE;
}

void ss_hillshade_params_options(const ss_hillshade_params *p, double cell_size_m,
                                 ss_hillshade_options *out)
{
    *out = (ss_hillshade_options){.azimuth_deg = p->azimuth_deg,
                                  .altitude_deg = p->altitude_deg,
                                  .z_factor = p->z_factor,
                                  .zevenbergen_thorne =
                                      p->alg == SS_HILLSHADE_ALG_ZEVENBERGEN_THORNE,
                                  .multidirectional = p->multidirectional,
                                  .cast_shadows = p->cast_shadows,
                                  .sky_view = p->sky_view,
                                  .vat = p->blend == SS_HILLSHADE_BLEND_VAT,
                                  .radius_m = p->blend_radius_cells * cell_size_m};
}

ss_plan_kind ss_hillshade_params_plan_kind(const ss_hillshade_params *p)
{
    return p->cast_shadows                                         ? SS_PLAN_SHADOW
           : p->sky_view > 0 || p->blend == SS_HILLSHADE_BLEND_VAT ? SS_PLAN_SKY_VIEW
                                                                   : SS_PLAN_NO_SWEEP;
}

ss_shadow_mode ss_insolation_params_shadow(const ss_insolation_params *p)
{
    /* In the choices' order. */
    static const ss_shadow_mode modes[] = {SS_SHADOW_AUTO, SS_SHADOW_EXACT,
                                           SS_SHADOW_INTERPOLATED, SS_SHADOW_CUMULATIVE};
    return modes[p->shadow >= 0 && p->shadow < 4 ? p->shadow : 0];
}

/* --surface: cell, horizontal, or TILT,AZIMUTH in degrees. */
static ss_status parse_surface(ss_ctx *ctx, const char *text, ss_surface *out)
{
    memset(out, 0, sizeof *out);
    if (!text || strcmp(text, "cell") == 0)
        return SS_OK;
    if (strcmp(text, "horizontal") == 0) {
        out->kind = SS_SURFACE_HORIZONTAL;
        return SS_OK;
    }
    char *end;
    out->kind = SS_SURFACE_FIXED;
    out->tilt_deg = strtod(text, &end);
    const char *az = *end == ',' && end != text ? end + 1 : NULL;
    if (az)
        out->azimuth_deg = strtod(az, &end);
    if (!az || end == az || *end || !(out->tilt_deg >= 0 && out->tilt_deg <= 90) ||
        !(out->azimuth_deg >= -360 && out->azimuth_deg <= 360))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "--surface expects cell, horizontal or TILT,AZIMUTH (tilt 0 to 90, "
                       "azimuth clockwise from north), not '%s'",
                       text);
    return SS_OK;
}

ss_status ss_insolation_params_options(ss_ctx *ctx, const ss_insolation_params *p,
                                       ss_shadow_mode shadow, ss_insolation_options *out)
{
    ss_call_begin(ctx);
    /* In the choices' order. */
    static const ss_sky_model models[] = {SS_SKY_MODEL_PEREZ, SS_SKY_MODEL_HAYDAVIES,
                                          SS_SKY_MODEL_ISOTROPIC};
    *out = (ss_insolation_options){
        .albedo = p->albedo,
        .shadow_mode = shadow,
        .sky_model = models[p->sky_model >= 0 && p->sky_model < 3 ? p->sky_model : 0],
        .pv = {.on = p->pv,
               .gamma_pdc = p->gamma_pdc,
               .temp_model = p->temperature_model ? SS_PV_TEMP_SAPM : SS_PV_TEMP_FAIMAN,
               .losses = p->losses_percent / 100.0,
               .temp_air_c = p->temp_air_c,
               .wind_speed_m_s = p->wind_speed_m_s,
               .inverter_efficiency = p->inverter_efficiency_percent / 100.0,
               .dc_ac_ratio = p->dc_ac_ratio},
        .elevation_step_deg = p->elevation_step_deg};
    return parse_surface(ctx, p->surface, &out->surface);
}

ss_status ss_insolation_params_linke(ss_ctx *ctx, const ss_insolation_params *p,
                                     double linke[12])
{
    ss_call_begin(ctx);
    const char *text = p->linke ? p->linke : "3";
    int n = 0;
    const char *at = text;
    while (*at && n < 13) {
        char *end;
        double v = strtod(at, &end);
        if (end == at || !(v >= 0.5 && v <= 10))
            return ss_fail(ctx, SS_ERR_ARGUMENT,
                           "--linke expects turbidities from 0.5 to 10, not '%s'", text);
        if (n < 12)
            linke[n] = v;
        n++;
        at = *end == ',' ? end + 1 : end;
        if (*end && *end != ',')
            return ss_fail(ctx, SS_ERR_ARGUMENT, "--linke: cannot read '%s'", text);
    }
    if (n != 1 && n != 12)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "--linke expects one value or twelve (one per month), not %d", n);
    for (int i = n; i < 12; ++i)
        linke[i] = linke[0];
    return SS_OK;
}

const char *ss_sky_model_name(ss_sky_model model)
{
    switch (model) {
    case SS_SKY_MODEL_PEREZ: return "Perez et al. 1990";
    case SS_SKY_MODEL_HAYDAVIES: return "Hay & Davies 1980";
    case SS_SKY_MODEL_ISOTROPIC: return "isotropic";
    }
    return "unknown";
}

const char *ss_shadow_mode_name(ss_shadow_mode mode)
{
    switch (mode) {
    case SS_SHADOW_EXACT: return "exact";
    case SS_SHADOW_INTERPOLATED: return "interpolated";
    case SS_SHADOW_CUMULATIVE: return "cumulative";
    case SS_SHADOW_AUTO: return "auto";
    }
    return "unknown";
}
