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
SS_API void ss_spa_params_default(ss_spa_params *p);

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
SS_API ss_status ss_spa(ss_ctx *ctx, double unix_s, double lat_deg, double lon_deg, const ss_spa_params *p,
                 ss_spa_result *out);

/* Julian day of a Unix time (both count days linearly; the calendar rules
 * live in the date conversions of iso_time.h). */
SS_API double ss_julian_day(double unix_s);

/* Delta T = TT - UT1 in seconds from the Espenak-Meeus polynomials (NASA
 * eclipse site, as pvlib's calculate_deltat), decimal_year = year +
 * (month - 0.5) / 12 for the middle of a month. Beyond about 2150 and
 * before -500 it is the long-term parabola, good to minutes at best. */
SS_API double ss_delta_t_model(double decimal_year);

/* SPA's refraction (step 13, Saemundsson's formula scaled by pressure and
 * temperature) for a true elevation e0_deg; 0 when the sun's upper limb is
 * below the horizon (e0 < -(0.26667 + atmos_refract_deg)). */
SS_API double ss_spa_refraction_deg(double e0_deg, double pressure_hpa, double temperature_c,
                             double atmos_refract_deg);

/* Doubles ss_sun_lattice_cells' tx takes: the place of each column between
 * its lattice columns, the same in every row. */
SS_API size_t ss_sun_lattice_tx_count(const ss_sun_lattice *l);
/* Fills tx (ss_sun_lattice_tx_count doubles) for ss_sun_lattice_cells. */
SS_API void ss_sun_lattice_tx(const ss_sun_lattice *l, double *tx);
/* The suns of cells [col0, col0 + n) of grid row `row`, which the
 * lattice's rows and columns span: grid azimuth, true and apparent
 * elevation (degrees). */
SS_API void ss_sun_lattice_cells(const ss_sun_lattice *l, const double *tx, int row, int col0,
                                 int n, float *grid_azimuth_deg, float *elevation_deg,
                                 float *apparent_deg);

/* Standard-atmosphere pressure at an altitude (pvlib alt2pres,
 * physics.md sec. 4.2), in hPa; 0 from 44331.514 m up, where it ends. */
SS_API double ss_pressure_from_altitude_hpa(double altitude_m);

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
SS_API ss_status ss_sun_rise_set(ss_ctx *ctx, double day_start_unix_s, double lat_deg, double lon_deg,
                          const ss_spa_params *p, ss_sun_day *out);

/* Angle between the sun and the normal of a plane of slope_deg facing
 * aspect_deg (the azimuth its downhill direction points to, clockwise from
 * north): cos i = cos Z cos S + sin Z sin S cos(azimuth - aspect), as SPA
 * step 16 with aspect = SPA's azm_rotation + 180. Above 90: the sun is
 * behind the plane. Float twin for kernels: ss_cos_incidence (ss_sun.h). */
SS_API double ss_sun_incidence_deg(double zenith_deg, double azimuth_deg, double slope_deg,
                            double aspect_deg);

/* The clear-sky insolation step (ss_insolation) of `sun`, ss_spa's result at
 * the grid's centre for the step's instant: duration_h hours, Linke
 * turbidity linke, extraterrestrial normal irradiance solar_constant_w_m2 /
 * R^2 (R: the earth-sun distance in AU), the sun's azimuth in the grid's
 * frame (grid_azimuth_deg) and in the sweep options' (grid_azimuth_deg +
 * options_north_deg, the options' grid_north_deg), and its true and
 * apparent elevations. The rest is zero: no per-cell suns, no spread, no
 * weather record. */
SS_API void ss_sun_step_clear_sky(const ss_spa_result *sun, double grid_azimuth_deg,
                           double options_north_deg, double duration_h, double linke,
                           double solar_constant_w_m2, ss_sun_step *step);

/* ---- instants, durations and time ranges in ISO 8601 -------------------- */
/* Instants are UTC Unix seconds (doubles: microseconds survive to year
 * 6000); calendar dates are Gregorian from 1582-10-15, Julian before, as SPA
 * counts them (doc/sun.md). */

/* A duration as ISO 8601 writes it: years and months stay calendar units so
 * that P1M steps from month to month; weeks, days, hours, minutes and
 * seconds are exact seconds (a day is 86400 s: UTC has no daylight saving). */
typedef struct {
    long long years, months;
    double seconds;
} ss_duration;

/* unix_s + times * d. The calendar part moves the date by whole months and
 * clamps the day to the month's length (2026-01-31 + P1M = 2026-02-28,
 * + P2M = 2026-03-31); for times >= 0 it is applied before the seconds
 * (as RFC 5545 does), for times < 0 after them, so that DURATION/END undoes
 * START/DURATION where no clamping occurs. */
SS_API double ss_time_add(double unix_s, const ss_duration *d, long long times);

/* 2026-06-21T10:00:00Z, ...T10:00Z, ...T10:00:00.25+10:00, -05:30, +0530,
 * +05; a bare date is 00:00 UTC. A date and time without a zone is refused. */
SS_API ss_status ss_parse_instant(ss_ctx *ctx, const char *text, double *unix_s);
/* PnW or PnYnMnDTnHnMnS; only the last unit may carry a fraction, and not
 * years or months (they have no fixed length). */
SS_API ss_status ss_parse_duration(ss_ctx *ctx, const char *text, ss_duration *out);

#define SS_TIME_RANGE_MAX_STEPS 10000000LL

typedef struct {
    double start_unix_s;
    double end_unix_s; /* equals start for a single instant */
    int has_step;
    ss_duration step;
    /* Instants start + k * step (k = 0, 1, ...) before end: the range is
     * half-open, so consecutive ranges tile without repeating an instant.
     * 1 for a single instant; 0 for an interval given without a step. */
    long long count;
} ss_time_range;

/* START, START/END, START/DURATION or DURATION/END, each optionally followed
 * by /STEP. Refuses an empty or reversed interval, a zero step, a step on a
 * single instant and more than SS_TIME_RANGE_MAX_STEPS instants. Steps may
 * hold years and months: instant k is start + k * step (ss_time_add), so
 * monthly steps from the 31st keep returning to the 31st where it exists. */
SS_API ss_status ss_parse_time_range(ss_ctx *ctx, const char *text, ss_time_range *out);
/* Instant k of the range. */
SS_API double ss_time_range_at(const ss_time_range *r, long long k);
/* Step k of a range with a step, as insolation takes it: from instant k to
 * instant k + 1 or the range's end, whichever comes first, evaluated at its
 * middle (*mid_unix_s) and lasting *hours. */
SS_API void ss_time_range_step(const ss_time_range *r, long long k, double *mid_unix_s, double *hours);

/* 2026-06-21T10:00:00Z, with up to 6 decimals of seconds when they are not
 * zero (rounded to the microsecond); "invalid" for NAN, infinities and
 * beyond +-9e12 s (year 285000). Returns the length the text needs, as
 * snprintf does. */
SS_API size_t ss_format_instant(double unix_s, char *buf, size_t size);

/* A UTC calendar date and time in the calendar SPA uses: Gregorian from
 * 1582-10-15, Julian before it, astronomical year numbers (0 = 1 BC). */
typedef struct {
    long long year;
    int month, day, hour, minute;
    double second; /* [0, 60) */
} ss_civil_time;

/* Unix seconds of a UTC calendar date and time; fields are not checked, so
 * day 0 or hour 24 count on as arithmetic would. */
SS_API double ss_unix_from_civil(long long year, int month, int day, int hour, int minute,
                                 double second);
SS_API void ss_civil_from_unix(double unix_s, ss_civil_time *out);
/* Days in a month of the calendar in force (Julian leap rule before 1582);
 * 0 for a month outside 1..12. */
SS_API int ss_days_in_month(long long year, int month);

#ifdef __cplusplus
}
#endif
#endif
