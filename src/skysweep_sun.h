/* skysweep: the sun's position for a place and an instant, the NREL Solar
 * Position Algorithm (Reda & Andreas 2004, Solar Energy 76:577, with the 2007
 * corrigendum; reference/physics.md sec. 1.1) and, as a cheaper option, the
 * PSA algorithm with its 2020 coefficients (Blanco et al. 2020; physics.md
 * sec. 1.2). Conventions (doc/sun.md):
 *   - times are UTC as Unix seconds (leap seconds not counted, as POSIX);
 *     calendar dates before 1582-10-15 are Julian-calendar dates, as in SPA;
 *   - angles are degrees; latitude north and longitude east positive,
 *     geodetic (WGS84 or any ellipsoid close to it);
 *   - azimuth is clockwise from true north in [0, 360);
 *   - "elevation" is the topocentric elevation without refraction,
 *     "apparent" adds refraction (SPA step 13), zenith = 90 - apparent. */
#ifndef SKYSWEEP_SUN_H
#define SKYSWEEP_SUN_H

#include "skysweep.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    SS_SUN_SPA = 0, /* NREL SPA: +-0.0003 deg, years -2000..6000 */
    SS_SUN_PSA = 1  /* PSA, 2020 coefficients: ~0.01 deg near 2020-2050 (doc/sun.md) */
} ss_sun_algorithm;

typedef struct {
    ss_sun_algorithm algorithm;
    double delta_t_s;         /* TT - UT1, seconds; NAN: ss_delta_t_model for the month */
    double delta_ut1_s;       /* UT1 - UTC, seconds, in (-1, 1) */
    double pressure_hpa;      /* local pressure for refraction, 0..5000 */
    double temperature_c;     /* local temperature for refraction, > -273 */
    double atmos_refract_deg; /* refraction at sunrise and sunset, |.| <= 5 */
    double elevation_m;       /* observer height above the ellipsoid, for parallax */
} ss_spa_params;

/* Delta T from the model, no Delta UT1, 1013.25 hPa, 12 C, refraction at the
 * horizon 0.5667 deg (SPA's value), observer at 0 m, algorithm SPA. */
void ss_spa_params_default(ss_spa_params *p);

typedef struct {
    double julian_day;             /* of UT1 */
    double delta_t_s;              /* the Delta T used (given or modelled) */
    double zenith_deg;             /* topocentric, refracted: 90 - apparent_elevation_deg */
    double azimuth_deg;            /* topocentric, clockwise from north, [0, 360) */
    double elevation_deg;          /* topocentric, without refraction (SPA e0) */
    double apparent_elevation_deg; /* with refraction (SPA e) */
    double right_ascension_deg;    /* geocentric apparent alpha, [0, 360) */
    double declination_deg;        /* geocentric apparent delta */
    double hour_angle_deg;         /* geocentric local hour angle H, westward, [0, 360) */
    double sidereal_time_deg;      /* Greenwich apparent sidereal time nu, [0, 360) */
    double equation_of_time_min;   /* apparent minus mean solar time, minutes */
    double earth_sun_distance_au;  /* R */
    /* Geocentric apparent direction to the sun, unit vector in Earth-fixed
     * axes: x toward latitude 0 longitude 0, y toward latitude 0 longitude
     * 90 E, z toward the north pole (right-handed, as ECEF/ITRS with polar
     * motion neglected). It is (cos d cos G, -cos d sin G, sin d) with d the
     * declination and G = nu - alpha the Greenwich hour angle. Dotting it
     * with a cell's geodetic east, north and up vectors gives the sun's
     * direction there without parallax (at most 8.8 arcsec = 0.0024 deg);
     * for the topocentric direction subtract the cell's ECEF position from
     * earth_sun_distance_au * 149597870700 m times this vector. */
    double sun_ecef[3];
    /* SPA intermediate values, for checking against the paper (NAN for PSA). */
    double heliocentric_longitude_deg; /* L */
    double heliocentric_latitude_deg;  /* B */
    double nutation_longitude_deg;     /* delta psi */
    double nutation_obliquity_deg;     /* delta epsilon */
    double obliquity_deg;              /* true obliquity of the ecliptic, epsilon */
} ss_spa_result;

/* Sun position at unix_s for an observer at lat_deg, lon_deg. Refuses
 * inputs outside SPA's limits (years -2000..6000, |lat| <= 90, |lon| <= 180,
 * pressure 0..5000 hPa, temperature > -273 C, |Delta T| <= 8000 s, ...). */
ss_status ss_spa(ss_ctx *ctx, double unix_s, double lat_deg, double lon_deg, const ss_spa_params *p,
                 ss_spa_result *out);

/* Julian day of a Unix time (both count days linearly; the calendar rules
 * live in the date conversions of iso_time.h). */
double ss_julian_day(double unix_s);

/* Delta T = TT - UT1 in seconds from the Espenak-Meeus polynomials (NASA
 * eclipse site, as pvlib's calculate_deltat), decimal_year = year +
 * (month - 0.5) / 12 for the middle of a month. Beyond about 2150 and
 * before -500 it is the long-term parabola, good to minutes at best. */
double ss_delta_t_model(double decimal_year);

/* SPA's refraction (step 13, Saemundsson's formula scaled by pressure and
 * temperature) for a true elevation e0_deg; 0 when the sun's upper limb is
 * below the horizon (e0 < -(0.26667 + atmos_refract_deg)). */
double ss_spa_refraction_deg(double e0_deg, double pressure_hpa, double temperature_c,
                             double atmos_refract_deg);

/* Standard-atmosphere pressure at an altitude (pvlib alt2pres,
 * physics.md sec. 4.2), in hPa; 0 from 44331.514 m up, where it ends. */
double ss_pressure_from_altitude_hpa(double altitude_m);

typedef enum {
    SS_SUN_RISES_AND_SETS = 0,
    SS_SUN_POLAR_DAY = 1,  /* the sun stays above the rise/set altitude all day */
    SS_SUN_POLAR_NIGHT = 2 /* the sun stays below it all day */
} ss_sun_day_kind;

typedef struct {
    ss_sun_day_kind kind;
    double transit_unix_s; /* the upper transit inside [day_start, day_start + 86400) */
    double sunrise_unix_s; /* the rise before that transit; NAN unless RISES_AND_SETS */
    double sunset_unix_s;  /* the set after it; NAN unless RISES_AND_SETS */
} ss_sun_day;

/* Sunrise, transit and sunset by SPA's appendix A.2 (Meeus ch. 15), with the
 * rise/set correction repeated until it converges: the sun's centre at
 * -(0.26667 + atmos_refract_deg) geocentric altitude, no dip for the
 * observer's height. The day is [day_start_unix_s, +86400 s): pass 0h
 * UTC of a date to match SPA's tables, or local midnight for a local date.
 * Rise and set may fall outside that day (they belong to its transit).
 * Always SPA; p->algorithm, pressure and temperature are not used. */
ss_status ss_sun_rise_set(ss_ctx *ctx, double day_start_unix_s, double lat_deg, double lon_deg,
                          const ss_spa_params *p, ss_sun_day *out);

/* Angle between the sun and the normal of a plane of slope_deg facing
 * aspect_deg (the azimuth its downhill direction points to, clockwise from
 * north): cos i = cos Z cos S + sin Z sin S cos(azimuth - aspect), as SPA
 * step 16 with aspect = SPA's azm_rotation + 180. Above 90: the sun is
 * behind the plane. Float twin for kernels: ss_cos_incidence (ss_sun.h). */
double ss_sun_incidence_deg(double zenith_deg, double azimuth_deg, double slope_deg,
                            double aspect_deg);

#ifdef __cplusplus
}
#endif
#endif
