/* Clear-sky irradiance per cell and time step (shared by kernels and C):
 * the ESRA model as GRASS r.sun implements it (Rigollier et al. 2000;
 * Hofierka & Suri 2002; formulas restated in reference/physics.md sec. 4.3),
 * with the terrain's own sky view in place of r.sun's open-plane sky factor
 * (doc/insolation.md). Angles in radians, heights in metres, irradiance in
 * W/m^2. */
#ifndef SS_INSOLATION_H
#define SS_INSOLATION_H

#include "ss_compat.h"

/* r.sun's refraction correction of the solar altitude for the air mass. */
SS_FN float ss_esra_refracted_altitude(float h0)
{
    return h0 + 0.061359f * (0.1594f + 1.123f * h0 + 0.065656f * h0 * h0) /
                    (1.0f + 28.9344f * h0 + 277.3971f * h0 * h0);
}

/* Relative optical air mass (Kasten & Young 1989) at sea level for the true
 * altitude h0 > 0; multiply by exp(-z / 8434.5) for a site at height z. */
SS_FN float ss_esra_air_mass_sea_level(float h0)
{
    float h = ss_esra_refracted_altitude(h0);
    return 1.0f / (SS_SIN(h) + 0.50572f * SS_POW(h * SS_DEG_PER_RAD_F + 6.07995f, -1.6364f));
}

/* Rayleigh optical thickness at air mass m (Kasten 1996), in two pieces
 * that meet, not quite continuously, at SS_ESRA_RAYLEIGH_SPLIT_M. */
#define SS_ESRA_RAYLEIGH_SPLIT_M 20.0f
SS_FN float ss_esra_rayleigh(float m)
{
    if (m > SS_ESRA_RAYLEIGH_SPLIT_M)
        return 1.0f / (10.4f + 0.718f * m);
    return 1.0f / (6.6296f + m * (1.7513f + m * (-0.1202f + m * (0.0065f - 0.00013f * m))));
}

/* Beam transmittance exp(-0.8662 T_LK m delta_R): beam normal irradiance
 * over the extraterrestrial one, for Linke turbidity T_LK. */
SS_FN float ss_esra_beam_transmittance(float linke, float m)
{
    return SS_EXP(-0.8662f * linke * m * ss_esra_rayleigh(m));
}

/* Diffuse irradiance on a horizontal surface over the extraterrestrial
 * normal irradiance: Tn(T_LK) Fd(h0). */
SS_FN float ss_esra_diffuse_fraction(float linke, float sin_h0)
{
    float tn = -0.015843f + linke * (0.030543f + 0.0003797f * linke);
    float a1 = 0.26463f + linke * (-0.061581f + 0.0031408f * linke);
    if (a1 * tn < 0.0022f)
        a1 = 0.0022f / tn;
    float a2 = 2.04020f + linke * (0.018945f - 0.011161f * linke);
    float a3 = -1.3025f + linke * (0.039231f + 0.0085079f * linke);
    return tn * (a1 + sin_h0 * (a2 + a3 * sin_h0));
}

/* Muneer's slope function F(S) = sin S - S cos S - pi sin^2(S / 2). */
SS_FN float ss_muneer_slope_term(float slope)
{
    float s2 = SS_SIN(0.5f * slope);
    return SS_SIN(slope) - slope * SS_COS(slope) - SS_PI_F * s2 * s2;
}

/* Sky-diffuse on the cell over the horizontal diffuse (Muneer 1990, as
 * r.sun): sky_view replaces r.sun's (1 + cos S)/2 (on an open plane they
 * agree), f_slope = ss_muneer_slope_term, kb the beam transmittance. A
 * sunlit cell adds the circumsolar part along the beam: cos_i / sin h0, or
 * on a slope near the horizon (h0 < 0.1) r.sun's form with sin S cos(A_N)
 * = side_sun, the cell's tilt toward the sun's azimuth. A level cell keeps
 * cos_i / sin h0 = 1 throughout, so on an open level cell this is exactly 1,
 * as r.sun's plane case. */
SS_FN float ss_muneer_diffuse_factor(float sky_view, float f_slope, float kb, int sunlit,
                                     int level, float cos_i, float sin_h0, float h0,
                                     float side_sun)
{
    if (!sunlit)
        return sky_view + 0.252271f * f_slope;
    float iso = (sky_view + (0.00263f - kb * (0.712f + 0.6883f * kb)) * f_slope) * (1.0f - kb);
    float circumsolar = h0 >= 0.1f || level ? kb * cos_i / sin_h0
                                            : kb * side_sun / (0.1f - 0.008f * h0);
    return iso + circumsolar;
}

#endif
