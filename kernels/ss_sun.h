/* Per-cell sun geometry shared by kernels and C (physics.md sec. 0): how
 * directly the sun shines on a sloping cell. The sun's own position comes
 * from SPA on the host (src/core/spa.h). Both forms return the raw cosine;
 * a value <= 0 means the sun is behind the surface (self-shadow), and
 * callers clip it where they need irradiance. */
#ifndef SS_SUN_H
#define SS_SUN_H

#include "ss_compat.h"

/* cos i = cos Z cos S + sin Z sin S cos(phi_s - A): sun at zenith Z and
 * azimuth phi_s, surface of slope S facing azimuth A (radians, azimuths
 * clockwise from north). */
SS_FN float ss_cos_incidence(float zenith_rad, float sun_azimuth_rad, float slope_rad,
                             float aspect_rad)
{
    return SS_COS(zenith_rad) * SS_COS(slope_rad) +
           SS_SIN(zenith_rad) * SS_SIN(slope_rad) * SS_COS(sun_azimuth_rad - aspect_rad);
}

/* The same from the surface gradient (ss_gradient_horn) and the sun as a unit
 * vector in local east, north, up, without trigonometry per cell: the
 * surface normal is (-dz_de, -dz_dn, 1) / sqrt(1 + dz_de^2 + dz_dn^2), and
 * the unit sun vector is (sin Z sin phi_s, sin Z cos phi_s, cos Z); the
 * normal's norm is given (a cell's, kept over many suns). */
SS_FN float ss_cos_incidence_normed(float sun_east, float sun_north, float sun_up, float dz_de,
                                    float dz_dn, float normal_norm)
{
    return (sun_up - dz_de * sun_east - dz_dn * sun_north) / normal_norm;
}

/* The same, the normal's norm computed here. */
SS_FN float ss_cos_incidence_gradient(float sun_east, float sun_north, float sun_up, float dz_de,
                                      float dz_dn)
{
    return ss_cos_incidence_normed(sun_east, sun_north, sun_up, dz_de, dz_dn,
                                   SS_SQRT(1.0f + dz_de * dz_de + dz_dn * dz_dn));
}

#endif
