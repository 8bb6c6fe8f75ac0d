/* One cell's irradiation for one time step, clear-sky or from a weather
 * record, shared by the exact and interpolated steps (insolation.c) and
 * the cumulative sky (insolation_cumulative.c), so that all compute the
 * same function. */
#ifndef SS_INSOLATION_CELL_H
#define SS_INSOLATION_CELL_H

#include <math.h>

#include "ss_insolation.h"
#include "ss_pv.h"
#include "ss_sky_diffuse.h"
#include "ss_sun.h"
#include "ss_terms.h"

/* What a cell keeps for every step: its gradient (Horn), the radiative
 * SVF of the tilted cell, Muneer's F(S), the air pressure factor
 * exp(-z / 8434.5), the sine of its slope, and the share of Perez's horizon
 * band in front of it that the terrain leaves open (1 unless computed). */
typedef struct ss_cell_terms_s {
    float dz_de, dz_dn, sky_view, slope_term, pressure_factor, sin_tilt, band_seen;
    float normal_norm; /* sqrt(1 + dz_de^2 + dz_dn^2) */
} ss_cell_terms;

/* The terms of a cell from its gradient, radiative SVF and height above
 * the datum. */
static inline ss_cell_terms ss_cell_terms_of(float dz_de, float dz_dn, float sky_view,
                                             double height_m)
{
    ss_cell_terms t;
    t.dz_de = dz_de;
    t.dz_dn = dz_dn;
    t.sky_view = sky_view;
    float slope = atanf(sqrtf(dz_de * dz_de + dz_dn * dz_dn));
    t.slope_term = ss_muneer_slope_term(slope);
    t.sin_tilt = sinf(slope);
    t.band_seen = 1.0f;
    t.normal_norm = sqrtf(1.0f + dz_de * dz_de + dz_dn * dz_dn);
    /* Air pressure relative to sea level (ESRA's p/p0). No dry land lies
     * below -1000 m, and far below it the factor overflows: a DEM of
     * bathymetry or fill values gets the -1000 m air. */
    t.pressure_factor = (float)exp(-fmax(height_m, -1000.0) / 8434.5);
    return t;
}

/* What one step adds to a cell (Wh/m^2, hours of direct sun). */
typedef struct {
    float beam, diffuse, reflected, global, sun_hours;
} ss_cell_step;

/* The step's sun at a cell as its terms take it: the true elevation h0
 * (radians), the sines and cosines of h0 and of the grid azimuth, and for
 * the clear sky the beam transmittance kb at the cell's air mass and ESRA's
 * diffuse fraction (0 otherwise). */
typedef struct {
    float h0, sin_h0, cos_h0, sin_az, cos_az, kb, diffuse_fraction;
} ss_cell_sun;

/* The sun's terms at a cell, evaluated exactly (sun_table.h tabulates them
 * over a step's cells). */
static inline ss_cell_sun ss_cell_sun_exact(const ss_cell_terms *t, float h0, float az,
                                            float linke, int clear)
{
    ss_cell_sun s = {h0, sinf(h0), cosf(h0), sinf(az), cosf(az), 0.0f, 0.0f};
    if (clear && h0 > 0.0f) {
        s.kb = ss_esra_beam_transmittance(linke,
                                          t->pressure_factor * ss_esra_air_mass_sea_level(h0));
        s.diffuse_fraction = ss_esra_diffuse_fraction(linke, s.sin_h0);
    }
    return s;
}

/* The clear sky's step at a cell: the sun there (ss_cell_sun, its apparent
 * elevation in degrees); the cell's terrain horizon (degrees) in the sun's
 * azimuth; the step's extraterrestrial irradiance, albedo and duration
 * (hours). A sun below the horizontal adds nothing. */
static inline ss_cell_step ss_cell_step_of(const ss_cell_terms *t, const ss_cell_sun *sun,
                                           float apparent_deg, float horizon_deg, float g0,
                                           float albedo, float dt)
{
    float sin_h0 = sun->sin_h0, kb = sun->kb;
    float se = sun->cos_h0 * sun->sin_az, sn = sun->cos_h0 * sun->cos_az;
    float cos_i = ss_cos_incidence_normed(se, sn, sin_h0, t->dz_de, t->dz_dn, t->normal_norm);
    int lit = apparent_deg > horizon_deg && cos_i > 0.0f;
    float beam_h = g0 * sin_h0 * kb;
    float diff_h = g0 * sun->diffuse_fraction;
    float beam = lit ? g0 * kb * cos_i : 0.0f;
    /* sin S cos(sun azimuth - aspect): the tilt toward the sun. */
    float side = -(t->dz_de * sun->sin_az + t->dz_dn * sun->cos_az) / t->normal_norm;
    int level = t->dz_de == 0.0f && t->dz_dn == 0.0f;
    float diffuse = diff_h * ss_muneer_diffuse_factor(t->sky_view, t->slope_term, kb, lit, level,
                                                      cos_i, sin_h0, sun->h0, side);
    float reflected = albedo * (beam_h + diff_h) * (1.0f - t->sky_view);
    /* Computed for every sun and then dropped below the horizontal, rather
     * than branched around: the cells run side by side (insolation_lanes.h). */
    int up = sun->h0 > 0.0f;
    ss_cell_step s;
    s.beam = up ? beam * dt : 0.0f;
    s.diffuse = up ? diffuse * dt : 0.0f;
    s.reflected = up ? reflected * dt : 0.0f;
    s.global = up ? (beam + diffuse + reflected) * dt : 0.0f;
    s.sun_hours = up && lit ? dt : 0.0f;
    return s;
}

/* A weather record's irradiance for a step (W/m^2): global and diffuse
 * horizontal, direct normal, extraterrestrial normal; the ground's albedo. */
typedef struct ss_sky_record_s {
    float ghi, dni, dhi, dni_extra, albedo;
} ss_sky_record;

/* What one weather record adds to a cell, its sky split into parts
 * (ss_sky_parts_of, once per step); the sun as for ss_cell_step_of (its
 * clear-sky terms unused), which may here be below the horizontal. */
static inline ss_cell_step ss_cell_step_weather(const ss_cell_terms *t, const ss_cell_sun *sun,
                                                float apparent_deg, float horizon_deg,
                                                const ss_sky_record *rec, ss_sky_parts sky,
                                                float dt)
{
    ss_cell_step s = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    float dni = rec->dni > 0.0f ? rec->dni : 0.0f, ghi = rec->ghi > 0.0f ? rec->ghi : 0.0f;
    float se = sun->cos_h0 * sun->sin_az, sn = sun->cos_h0 * sun->cos_az;
    float cos_i = ss_cos_incidence_normed(se, sn, sun->sin_h0, t->dz_de, t->dz_dn, t->normal_norm);
    int lit = sun->h0 > 0.0f && apparent_deg > horizon_deg && cos_i > 0.0f;
    float beam = lit ? dni * cos_i : 0.0f;
    float diffuse = ss_sky_diffuse_on(sky, cos_i, lit, t->sky_view, t->sin_tilt, t->band_seen);
    float reflected = rec->albedo * ghi * (1.0f - t->sky_view);
    s.beam = beam * dt;
    s.diffuse = diffuse * dt;
    s.reflected = reflected * dt;
    s.global = (beam + diffuse + reflected) * dt;
    /* Sunshine as the WMO counts it: direct normal of 120 W/m^2 or more. */
    float sunny = dni >= 120.0f ? dt : 0.0f; /* one test of the record, then one per cell */
    s.sun_hours = lit ? sunny : 0.0f;
    return s;
}

/* What a PV module lying in the cell's surface yields over a step, kWh per
 * kWp, from the step's plane-of-array global (W/m^2) and weather. */
/* DC power per kWp after the system losses, kW (pvwatts_dc, then the
 * losses, as pvlib's PVWatts chain). */
static inline float ss_cell_pv_power(float poa, float temp_air, float wind, int temp_model,
                                     float gamma_pdc, float losses)
{
    float cell = ss_pv_cell_temp(temp_model, poa, temp_air, wind);
    return fmaxf(ss_pvwatts_dc_per_kwp(poa, cell, gamma_pdc), 0.0f) * (1.0f - losses);
}

#endif
