/* Real-sky irradiance on a tilted cell in terrain, from a weather record's
 * global and diffuse horizontal and direct normal irradiance (shared by
 * kernels and C; doc/insolation.md, "Real sky"). The sky-diffuse models are
 * pvlib's (irradiance.isotropic, haydavies, perez with the 1990 all-sites
 * coefficients) with the terrain put in:
 * - the isotropic part is seen through the cell's tilted sky-view factor
 *   (Dozier & Frew 1990) instead of (1 + cos tilt) / 2;
 * - the circumsolar part is shaded exactly like the beam;
 * - Perez's horizon band counts for the share of it the cell sees;
 * - the ground reflects albedo x GHI from the terrain the cell sees,
 *   1 - sky view instead of (1 - cos tilt) / 2.
 * On an open plane each term is pvlib's. Angles in radians, W/m^2. */
#ifndef SS_SKY_DIFFUSE_H
#define SS_SKY_DIFFUSE_H

#include "ss_compat.h"

#define SS_SKY_ISOTROPIC 0
#define SS_SKY_HAYDAVIES 1
#define SS_SKY_PEREZ 2

/* Relative optical air mass (Kasten & Young 1989, pvlib's default) at the
 * true zenith angle z < pi/2; not corrected for pressure, as Perez's
 * model takes it. */
SS_FN float ss_kasten_young_air_mass(float z)
{
    float zd = z * SS_DEG_PER_RAD_F;
    return 1.0f / (SS_COS(z) + 0.50572f * SS_POW(96.07995f - zd, -1.6364f));
}

/* Perez et al. (1990) brightness coefficients F1 (circumsolar) and F2
 * (horizon band), all-sites composite set, from the sky's clearness bin
 * (epsilon), brightness (delta) and the zenith angle z, as pvlib. */
SS_FN void ss_perez_coefficients(float dhi, float dni, float dni_extra, float z, float air_mass,
                                 float *f1, float *f2)
{
    /* F11 F12 F13 F21 F22 F23 per clearness bin (Perez et al. 1990,
     * table 6; pvlib's 'allsitescomposite1990'). */
    const float c[8][6] = {{-0.0080f, 0.5880f, -0.0620f, -0.0600f, 0.0720f, -0.0220f},
                           {0.1300f, 0.6830f, -0.1510f, -0.0190f, 0.0660f, -0.0290f},
                           {0.3300f, 0.4870f, -0.2210f, 0.0550f, -0.0640f, -0.0260f},
                           {0.5680f, 0.1870f, -0.2950f, 0.1090f, -0.1520f, -0.0140f},
                           {0.8730f, -0.3920f, -0.3620f, 0.2260f, -0.4620f, 0.0010f},
                           {1.1320f, -1.2370f, -0.4120f, 0.2880f, -0.8230f, 0.0560f},
                           {1.0600f, -1.6000f, -0.3590f, 0.2640f, -1.1270f, 0.1310f},
                           {0.6780f, -0.3270f, -0.2500f, 0.1560f, -1.3770f, 0.2510f}};
    const float upper[7] = {1.065f, 1.23f, 1.5f, 1.95f, 2.8f, 4.5f, 6.2f};
    float kz3 = 1.041f * z * z * z;
    float eps = ((dhi + dni) / dhi + kz3) / (1.0f + kz3);
    int bin = 0;
    while (bin < 7 && eps >= upper[bin])
        ++bin;
    float delta = dhi * air_mass / dni_extra;
    *f1 = SS_FMAX(c[bin][0] + c[bin][1] * delta + c[bin][2] * z, 0.0f);
    *f2 = c[bin][3] + c[bin][4] * delta + c[bin][5] * z;
}

/* A record's sky diffuse split by the per-cell factor each part takes
 * (W/m^2): the isotropic part the cell's tilted sky view, the circumsolar
 * part cos(incidence) where the cell is lit, the horizon band sin(tilt)
 * times the band's share the cell sees. They depend on the record and the
 * sun alone, so a step computes them once for every cell. */
typedef struct {
    float isotropic, circumsolar, horizon;
} ss_sky_parts;

/* The parts by `model` (SS_SKY_*) for the record's dhi and dni, the
 * extraterrestrial normal irradiance and the sun's true zenith angle z; a
 * sun at or below the horizontal leaves the diffuse light isotropic. */
SS_FN ss_sky_parts ss_sky_parts_of(int model, float dhi, float dni, float dni_extra, float z)
{
    ss_sky_parts p = {0.0f, 0.0f, 0.0f};
    if (!(dhi > 0.0f))
        return p;
    p.isotropic = dhi;
    if (z >= 0.5f * SS_PI_F)
        return p;
    if (model == SS_SKY_HAYDAVIES) {
        float ai = SS_FMIN(SS_FMAX(dni / dni_extra, 0.0f), 1.0f);
        p.isotropic = dhi * (1.0f - ai);
        p.circumsolar = dhi * ai / SS_FMAX(SS_COS(z), 0.01745f);
    } else if (model == SS_SKY_PEREZ) {
        float f1, f2;
        ss_perez_coefficients(dhi, dni, dni_extra, z, ss_kasten_young_air_mass(z), &f1, &f2);
        p.isotropic = dhi * (1.0f - f1);
        p.circumsolar = dhi * f1 / SS_FMAX(SS_COS(z), 0.087155743f); /* cos 85 deg */
        p.horizon = dhi * f2;
    }
    return p;
}

/* Sky-diffuse irradiance on a cell (W/m^2) from a record's parts: cos_i,
 * the cosine of incidence on the cell (any sign); lit, whether the sun is
 * above its terrain horizon and in front of its surface; sky_view, its
 * tilted radiative SVF; sin_tilt, the sine of its slope; band_seen, the
 * share of the horizon band in front of it that its terrain leaves open.
 * As pvlib, a negative sum (Perez's F2 < 0) counts as none. */
SS_FN float ss_sky_diffuse_on(ss_sky_parts p, float cos_i, int lit, float sky_view,
                              float sin_tilt, float band_seen)
{
    /* Clipped by comparison, not fmax, which is the same here (NaN too
     * gives 0) and which compilers can run in vector lanes. */
    float seen = lit && cos_i > 0.0f ? cos_i : 0.0f;
    float sum = p.isotropic * sky_view + p.circumsolar * seen + p.horizon * sin_tilt * band_seen;
    return sum > 0.0f ? sum : 0.0f;
}

#endif
