/* One cell's irradiation for one time step, clear-sky or from a weather
 * record (shared by kernels and C): the host's steps (insolation.c, in SIMD
 * lanes), the cumulative sky (insolation_cumulative.c) and the device's
 * steps (sweep.cl, insolation_cells) all compute this one function. */
#ifndef SS_CELL_STEP_H
#define SS_CELL_STEP_H

#include "ss_compat.h"
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

/* What one step adds to a cell (Wh/m^2, hours of direct sun); total is
 * the global, beam + diffuse + reflected ("global" is an OpenCL word). */
typedef struct {
    float beam, diffuse, reflected, total, sun_hours;
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
SS_FN ss_cell_sun ss_cell_sun_exact(const ss_cell_terms *t, float h0, float az, float linke,
                                    int clear)
{
    ss_cell_sun s = {h0, SS_SIN(h0), SS_COS(h0), SS_SIN(az), SS_COS(az), 0.0f, 0.0f};
    if (clear && h0 > 0.0f) {
        s.kb =
            ss_esra_beam_transmittance(linke, t->pressure_factor * ss_esra_air_mass_sea_level(h0));
        s.diffuse_fraction = ss_esra_diffuse_fraction(linke, s.sin_h0);
    }
    return s;
}

/* A step's sun at the grid's centre (radians, with its sines and
 * cosines), from which a weather record's cells take theirs. */
typedef struct {
    float h, a, sin_h, cos_h, sin_a, cos_a;
} ss_sun_centre;

SS_FN ss_sun_centre ss_sun_centre_of(float h0_deg, float az_deg)
{
    const float rad = 0.017453292519943295f; /* (float)(pi / 180) */
    ss_sun_centre c;
    c.h = h0_deg * rad;
    c.a = az_deg * rad;
    c.sin_h = SS_SIN(c.h);
    c.cos_h = SS_COS(c.h);
    c.sin_a = SS_SIN(c.a);
    c.cos_a = SS_COS(c.a);
    return c;
}

/* How far a cell's sun may lie from the centre's, in elevation and in
 * azimuth, for ss_sincos_near. */
#define SS_SUN_NEAR_RAD 0.5f

/* The sine and cosine of x + d from those of x (sin_x, cos_x), for |d| at
 * most SS_SUN_NEAR_RAD: sin d and cos d by their Taylor series to d^7 and
 * d^8, whose remainders there are under 6e-9 and 3e-10 (d^9 / 9! and
 * d^10 / 10!), then the angle-addition formulas. */
SS_FN void ss_sincos_near(float sin_x, float cos_x, float d, float *sin_xd, float *cos_xd)
{
    float d2 = d * d;
    float sin_d = d * (1.0f - d2 * (1.0f / 6.0f - d2 * (1.0f / 120.0f - d2 * (1.0f / 5040.0f))));
    float cos_d =
        1.0f - d2 * (0.5f - d2 * (1.0f / 24.0f - d2 * (1.0f / 720.0f - d2 * (1.0f / 40320.0f))));
    *sin_xd = sin_x * cos_d + cos_x * sin_d;
    *cos_xd = cos_x * cos_d - sin_x * sin_d;
}

/* Whether a cell's sun, h0 and az (radians), lies near enough the
 * centre's for ss_sun_near_of (else it is computed exactly): without a
 * branch, for SIMD lanes. */
SS_FN int ss_sun_near(const ss_sun_centre *c, float h0, float az)
{
    return (SS_FABS(h0 - c->h) <= SS_SUN_NEAR_RAD) & (SS_FABS(az - c->a) <= SS_SUN_NEAR_RAD);
}

/* A weather record's sun at a cell near the centre's (ss_sun_near): its
 * sines and cosines from the centre's, no clear-sky terms. A weather record
 * needs nothing else of the sun, which spares every cell four sines. */
SS_FN ss_cell_sun ss_sun_near_of(const ss_sun_centre *c, float h0, float az)
{
    ss_cell_sun sun = {h0, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    ss_sincos_near(c->sin_h, c->cos_h, h0 - c->h, &sun.sin_h0, &sun.cos_h0);
    ss_sincos_near(c->sin_a, c->cos_a, az - c->a, &sun.sin_az, &sun.cos_az);
    return sun;
}

/* The clear sky's step at a cell: the sun there (ss_cell_sun, its apparent
 * elevation in degrees); the cell's terrain horizon (degrees) in the sun's
 * azimuth; the step's extraterrestrial irradiance, albedo and duration
 * (hours). A sun below the horizontal adds nothing. */
SS_FN ss_cell_step ss_cell_step_of(const ss_cell_terms *t, const ss_cell_sun *sun,
                                   float apparent_deg, float horizon_deg, float g0, float albedo,
                                   float dt)
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
     * than branched around: the cells run side by side (insolation_lanes.h, and a device's
     * work-items). */
    int up = sun->h0 > 0.0f;
    ss_cell_step s;
    s.beam = up ? beam * dt : 0.0f;
    s.diffuse = up ? diffuse * dt : 0.0f;
    s.reflected = up ? reflected * dt : 0.0f;
    s.total = up ? (beam + diffuse + reflected) * dt : 0.0f;
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
SS_FN ss_cell_step ss_cell_step_weather(const ss_cell_terms *t, const ss_cell_sun *sun,
                                        float apparent_deg, float horizon_deg,
                                        const ss_sky_record *rec, ss_sky_parts sky, float dt)
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
    s.total = (beam + diffuse + reflected) * dt;
    /* Sunshine as the WMO counts it: direct normal of 120 W/m^2 or more. */
    float sunny = dni >= 120.0f ? dt : 0.0f; /* one test of the record, then one per cell */
    s.sun_hours = lit ? sunny : 0.0f;
    return s;
}

/* A weather record's PV system and air, as every cell's yield takes them:
 * the cell temperature model (ss_pv.h), air temperature (C) and wind (m/s),
 * the temperature coefficient (1/K) and system losses, and the inverter's
 * DC input limit per kWp of modules and its nominal efficiency. */
typedef struct {
    int temp_model;
    float temp_air, wind, gamma_pdc, losses, inv_pdc0, eta_inv;
} ss_pv_step;

/* The DC and AC energy per kWp (kWh) of a PV module lying in the cell's
 * surface over a step of dt > 0 hours, from the global the step added to
 * it (Wh/m^2): pvwatts_dc, the system losses, then pvwatts_ac, as pvlib's
 * PVWatts chain. */
SS_FN void ss_cell_pv_yield(const ss_pv_step *p, float global_wh, float dt, float *dc_kwh,
                            float *ac_kwh)
{
    float poa = global_wh / dt;
    float cell = ss_pv_cell_temp(p->temp_model, poa, p->temp_air, p->wind);
    float pdc = SS_FMAX(ss_pvwatts_dc_per_kwp(poa, cell, p->gamma_pdc), 0.0f) * (1.0f - p->losses);
    *dc_kwh = pdc * dt;
    *ac_kwh = ss_pvwatts_ac(pdc, p->inv_pdc0, p->eta_inv) * dt;
}

#endif
