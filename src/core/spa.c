/* Sun position by NREL SPA (Reda & Andreas 2004, steps as numbered in
 * reference/physics.md sec. 1.1), implemented from the paper; and by PSA
 * with the 2020 coefficients (physics.md sec. 1.2). */
#include "config.h"

#include <math.h>

#include "ctx_internal.h"
#include "skysweep_sun.h"
#include "spa.h"
#include "ss_sun_lattice.h"

#define RAD (M_PI / 180.0)
/* Unix time of JD 2451545.0 (2000-01-01 12:00), in days. */
#define J2000_UNIX_DAYS 10957.5

static double wrap360(double deg)
{
    double w = fmod(deg, 360.0);
    return w < 0 ? w + 360.0 : w;
}

static double wrap180(double deg)
{
    double w = wrap360(deg + 180.0);
    return w - 180.0;
}

void ss_spa_params_default(ss_spa_params *p)
{
    p->algorithm = SS_SUN_SPA;
    p->delta_t_s = NAN;
    p->delta_ut1_s = 0;
    p->pressure_hpa = 1013.25;
    p->temperature_c = 12;
    p->atmos_refract_deg = 0.5667;
    p->elevation_m = 0;
}

double ss_julian_day(double unix_s)
{
    return unix_s / 86400.0 + 2440587.5;
}

/* c[0] + c[1] t + ... + c[n-1] t^(n-1) */
static double poly(double t, const double *c, int n)
{
    double v = 0;
    while (n-- > 0)
        v = v * t + c[n];
    return v;
}

/* Espenak & Meeus, NASA eclipse web site "Polynomial expressions for Delta
 * T" (as pvlib.spa.calculate_deltat, with NASA's 7.62 for 1860-1900): from
 * year `from` until the next row, Delta T = sum c_k u^k, u = (y - y0) / scale. */
static const struct {
    double from, y0, scale, c[8];
} delta_t_rows[] = {
    {-500, 0, 100, {10583.6, -1014.41, 33.78311, -5.952053, -0.1798452, 0.022174192, 0.0090316521}},
    {500, 1000, 100, {1574.2, -556.01, 71.23472, 0.319781, -0.8503463, -0.005050998, 0.0083572073}},
    {1600, 1600, 1, {120, -0.9808, -0.01532, 1.0 / 7129}},
    {1700, 1700, 1, {8.83, 0.1603, -0.0059285, 0.00013336, -1.0 / 1174000}},
    {1800,
     1800,
     1,
     {13.72, -0.332447, 6.8612e-3, 4.1116e-3, -3.7436e-4, 1.21272e-5, -1.699e-7, 8.75e-10}},
    {1860, 1860, 1, {7.62, 0.5737, -0.251754, 0.01680668, -0.0004473624, 1.0 / 233174}},
    {1900, 1900, 1, {-2.79, 1.494119, -0.0598939, 0.0061966, -0.000197}},
    {1920, 1920, 1, {21.20, 0.84493, -0.076100, 0.0020936}},
    {1941, 1950, 1, {29.07, 0.407, -1.0 / 233, 1.0 / 2547}},
    {1961, 1975, 1, {45.45, 1.067, -1.0 / 260, -1.0 / 718}},
    {1986, 2000, 1, {63.86, 0.3345, -0.060374, 0.0017275, 0.000651814, 0.00002373599}},
    {2005, 2000, 1, {62.92, 0.32217, 0.005589}}};

double ss_delta_t_model(double decimal_year)
{
    /* Rows are chosen by calendar year; the long-term parabola holds before
     * -500 and after 2150. */
    double y = decimal_year, year = floor(y);
    double u = (y - 1820) / 100, parabola = -20 + 32 * u * u;
    if (year < -500 || year >= 2150)
        return parabola;
    if (year >= 2050)
        return parabola - 0.5628 * (2150 - y);
    int i = (int)(sizeof delta_t_rows / sizeof delta_t_rows[0]) - 1;
    while (year < delta_t_rows[i].from)
        i--;
    return poly((y - delta_t_rows[i].y0) / delta_t_rows[i].scale, delta_t_rows[i].c, 8);
}

double ss_spa_refraction_deg(double e0_deg, double pressure_hpa, double temperature_c,
                             double atmos_refract_deg)
{
    return ss_refraction_deg(e0_deg, pressure_hpa, temperature_c, atmos_refract_deg);
}

double ss_pressure_from_altitude_hpa(double altitude_m)
{
    if (altitude_m >= 44331.514)
        return 0; /* the formula's top of the atmosphere */
    return pow((44331.514 - altitude_m) / 11880.516, 1 / 0.1902632);
}

double ss_sun_incidence_deg(double zenith_deg, double azimuth_deg, double slope_deg,
                            double aspect_deg)
{
    double z = RAD * zenith_deg, s = RAD * slope_deg;
    double c = cos(z) * cos(s) + sin(z) * sin(s) * cos(RAD * (azimuth_deg - aspect_deg));
    return acos(c > 1 ? 1 : c < -1 ? -1 : c) / RAD;
}

/* ---- SPA, steps 2-10: what depends on the time alone ---------------------------------- */

typedef struct {
    double l_deg, b_deg, r_au;   /* heliocentric (step 3) */
    double dpsi_deg, deps_deg;   /* nutation (step 5) */
    double eps_deg;              /* true obliquity (step 6) */
    double nu_deg;               /* apparent sidereal time (step 8) */
    double alpha_deg, delta_deg; /* geocentric apparent (step 9) */
    double jme;
} spa_geo;

/* sum_i series_i(JME) JME^i (step 3). */
static double vsop(const ss_spa_series *s, int orders, double jme)
{
    double total = 0, power = 1;
    for (int i = 0; i < orders; ++i, power *= jme) {
        double sum = 0;
        for (int k = 0; k < s[i].count; ++k)
            sum += s[i].terms[k].a * cos(s[i].terms[k].b + s[i].terms[k].c * jme);
        total += sum * power;
    }
    return total / 1e8;
}

/* days_ut, days_tt: UT1 and TT days since JD 2451545.0. */
static void spa_geocentric(double days_ut, double days_tt, spa_geo *g)
{
    double jc = days_ut / 36525, jce = days_tt / 36525, jme = jce / 10;
    g->jme = jme;
    g->l_deg = wrap360(vsop(ss_spa_l_series, SS_SPA_L_ORDERS, jme) / RAD);
    g->b_deg = vsop(ss_spa_b_series, SS_SPA_B_ORDERS, jme) / RAD;
    g->r_au = vsop(ss_spa_r_series, SS_SPA_R_ORDERS, jme);
    double theta = wrap360(g->l_deg + 180), beta = -g->b_deg; /* step 4 */

    /* Step 5: mean elongation of the moon, mean anomalies of sun and moon,
     * moon's argument of latitude and ascending node (degrees). */
    static const double xc[5][4] = {{297.85036, 445267.111480, -0.0019142, 1.0 / 189474},
                                    {357.52772, 35999.050340, -0.0001603, -1.0 / 300000},
                                    {134.96298, 477198.867398, 0.0086972, 1.0 / 56250},
                                    {93.27191, 483202.017538, -0.0036825, 1.0 / 327270},
                                    {125.04452, -1934.136261, 0.0020708, 1.0 / 450000}};
    double x[5];
    for (int k = 0; k < 5; ++k)
        x[k] = poly(jce, xc[k], 4);
    double dpsi = 0, deps = 0;
    for (int i = 0; i < SS_SPA_NUTATION_TERMS; ++i) {
        const ss_spa_nutation_term *t = &ss_spa_nutation[i];
        double arg = 0;
        for (int k = 0; k < 5; ++k)
            arg += t->y[k] * x[k];
        dpsi += (t->a + t->b * jce) * sin(RAD * arg);
        deps += (t->c + t->d * jce) * cos(RAD * arg);
    }
    g->dpsi_deg = dpsi / 36000000;
    g->deps_deg = deps / 36000000;

    static const double eps_c[11] = {84381.448, -4680.93, -1.55, 1999.25, -51.38, -249.67,
                                     -39.05,    7.12,     27.87, 5.79,    2.45};
    double eps0 = poly(jme / 10, eps_c, 11); /* step 6, arcseconds */
    g->eps_deg = eps0 / 3600 + g->deps_deg;

    double lambda = theta + g->dpsi_deg - 20.4898 / (3600 * g->r_au); /* step 7 */

    /* Step 8; 360.98564736629 d split so that 360 * d is reduced exactly. */
    double nu0 = 280.46061837 + 360.0 * (days_ut - floor(days_ut)) + 0.98564736629 * days_ut +
                 jc * jc * (0.000387933 - jc / 38710000);
    g->nu_deg = wrap360(nu0 + g->dpsi_deg * cos(RAD * g->eps_deg));

    double sl = sin(RAD * lambda), eps = RAD * g->eps_deg, b = RAD * beta; /* step 9 */
    g->alpha_deg = wrap360(atan2(sl * cos(eps) - tan(b) * sin(eps), cos(RAD * lambda)) / RAD);
    g->delta_deg = asin(sin(b) * cos(eps) + cos(b) * sin(eps) * sl) / RAD;
}

/* ---- input checks ----------------------------------------------------------------------- */

static ss_status check_inputs(ss_ctx *ctx, double unix_s, double lat_deg, double lon_deg,
                              const ss_spa_params *p)
{
    if (!isfinite(unix_s))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "sun position: the time is not a finite number");
    if (fabs(unix_s) > 1e12) /* beyond years -29700..33700: no calendar needed to refuse */
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun position: time %g s is far outside SPA's years -2000..6000", unix_s);
    ss_civil_time c;
    ss_civil_from_unix(unix_s, &c);
    if (c.year < -2000 || c.year > 6000)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun position: year %lld is outside SPA's range -2000..6000", c.year);
    if (!(fabs(lat_deg) <= 90))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "sun position: latitude %g is outside -90..90",
                       lat_deg);
    if (!(fabs(lon_deg) <= 180))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "sun position: longitude %g is outside -180..180",
                       lon_deg);
    if (p->algorithm != SS_SUN_SPA && p->algorithm != SS_SUN_PSA)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "sun position: unknown algorithm %d",
                       (int)p->algorithm);
    if (!isnan(p->delta_t_s) && !(fabs(p->delta_t_s) <= 8000))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "sun position: Delta T %g s is outside -8000..8000 s",
                       p->delta_t_s);
    if (!(fabs(p->delta_ut1_s) < 1))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun position: Delta UT1 %g s is outside -1..1 s (exclusive)",
                       p->delta_ut1_s);
    if (!(p->pressure_hpa >= 0 && p->pressure_hpa <= 5000))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "sun position: pressure %g hPa is outside 0..5000",
                       p->pressure_hpa);
    if (!(p->temperature_c > -273 && p->temperature_c < 6000))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun position: temperature %g C is not above -273 C (absolute zero)",
                       p->temperature_c);
    if (!(fabs(p->atmos_refract_deg) <= 5))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun position: horizon refraction %g deg is outside -5..5",
                       p->atmos_refract_deg);
    if (!(p->elevation_m >= -6500000 && p->elevation_m < 1e9))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun position: observer elevation %g m is below -6500000 m or not finite",
                       p->elevation_m);
    return SS_OK;
}

static double delta_t_for(const ss_spa_params *p, double unix_s)
{
    if (!isnan(p->delta_t_s))
        return p->delta_t_s;
    ss_civil_time c;
    ss_civil_from_unix(unix_s, &c);
    return ss_delta_t_model((double)c.year + (c.month - 0.5) / 12);
}

/* Geocentric direction in Earth-fixed axes from declination and Greenwich
 * hour angle (spa.h). */
static void ecef_direction(double delta_deg, double gha_deg, double v[3])
{
    double cd = cos(RAD * delta_deg);
    v[0] = cd * cos(RAD * gha_deg);
    v[1] = -cd * sin(RAD * gha_deg);
    v[2] = sin(RAD * delta_deg);
}

/* What both algorithms end with: refraction, zenith, the Earth-fixed vector. */
static void finish(const ss_spa_params *p, double e0_deg, ss_spa_result *out)
{
    out->elevation_deg = e0_deg;
    out->apparent_elevation_deg =
        e0_deg +
        ss_spa_refraction_deg(e0_deg, p->pressure_hpa, p->temperature_c, p->atmos_refract_deg);
    out->zenith_deg = 90 - out->apparent_elevation_deg;
    ecef_direction(out->declination_deg, out->sidereal_time_deg - out->right_ascension_deg,
                   out->sun_ecef);
}

/* ---- SPA steps 10-15 and 17: the observer ------------------------------------------------ */

static void spa_observe(const spa_geo *g, double lat_deg, double lon_deg, const ss_spa_params *p,
                        ss_spa_result *out)
{
    double h = wrap360(g->nu_deg + lon_deg - g->alpha_deg); /* step 10 */
    /* Step 11: parallax for an observer on the ellipsoid (flattening
     * 1 - 0.99664719, equatorial radius 6378140 m). */
    double lat = RAD * lat_deg, hr = RAD * h, dr = RAD * g->delta_deg;
    double xi = RAD * 8.794 / (3600 * g->r_au);
    double uu = atan(0.99664719 * tan(lat));
    double x = cos(uu) + p->elevation_m / 6378140 * cos(lat);
    double y = 0.99664719 * sin(uu) + p->elevation_m / 6378140 * sin(lat);
    double den = cos(dr) - x * sin(xi) * cos(hr);
    double dalpha = atan2(-x * sin(xi) * sin(hr), den);
    double delta_p = atan2((sin(dr) - y * sin(xi)) * cos(dalpha), den);
    double h_p = hr - dalpha;

    double e0 = asin(sin(lat) * sin(delta_p) + cos(lat) * cos(delta_p) * cos(h_p)); /* 12 */
    double gamma = atan2(sin(h_p), cos(h_p) * sin(lat) - tan(delta_p) * cos(lat));  /* 15 */
    out->azimuth_deg = wrap360(gamma / RAD + 180);
    out->hour_angle_deg = h;

    /* Step 17: equation of time from the sun's mean longitude. */
    static const double m_c[6] = {280.4664567, 360007.6982779, 0.03032028,
                                  1.0 / 49931, -1.0 / 15300,   -1.0 / 2000000};
    double m = poly(g->jme, m_c, 6);
    out->equation_of_time_min =
        4 * wrap180(m - 0.0057183 - g->alpha_deg + g->dpsi_deg * cos(RAD * g->eps_deg));
    finish(p, e0 / RAD, out);
}

/* ---- PSA (Blanco et al. 2020 coefficients) ------------------------------------------------ */

static void psa(double days_ut, double lat_deg, double lon_deg, const ss_spa_params *p,
                ss_spa_result *out)
{
    static const double c[15] = {2.267127827,     -9.300339267e-4, 4.895036035,    1.720279602e-2,
                                 6.239468336,     1.720200135e-2,  3.338320972e-2, 3.497596876e-4,
                                 -1.544353226e-4, -8.68972936e-6,  4.090904909e-1, -6.213605399e-9,
                                 4.418094944e-5,  6.697096103,     6.570984737e-2};
    /* Earth's mean radius over the astronomical unit, km/km (PSA 2001). */
    const double parallax = 6371.01 / 149597890.0;
    double n = days_ut, hour = 24 * (days_ut + 0.5 - floor(days_ut + 0.5));
    double omega = c[0] + c[1] * n, l = c[2] + c[3] * n, g = c[4] + c[5] * n;
    double lambda = l + c[6] * sin(g) + c[7] * sin(2 * g) + c[8] + c[9] * sin(omega);
    double eps = c[10] + c[11] * n + c[12] * cos(omega);
    double ra = atan2(cos(eps) * sin(lambda), cos(lambda));
    double delta = asin(sin(eps) * sin(lambda));
    double gmst_h = c[13] + c[14] * n + hour;
    double w = RAD * (15 * gmst_h + lon_deg) - ra; /* hour angle */
    double lat = RAD * lat_deg;
    double cz = cos(lat) * cos(w) * cos(delta) + sin(delta) * sin(lat);
    double z = acos(cz > 1 ? 1 : cz < -1 ? -1 : cz);
    z += parallax * sin(z);
    double az = atan2(-sin(w), tan(delta) * cos(lat) - sin(lat) * cos(w));

    out->azimuth_deg = wrap360(az / RAD);
    out->right_ascension_deg = wrap360(ra / RAD);
    out->declination_deg = delta / RAD;
    out->sidereal_time_deg = wrap360(15 * gmst_h);
    out->hour_angle_deg = wrap360(w / RAD);
    out->obliquity_deg = eps / RAD;
    /* Not part of PSA: the Astronomical Almanac's low-precision distance
     * and the equation of time as mean longitude minus right ascension;
     * their error against SPA is measured in doc/sun.md. */
    out->earth_sun_distance_au = 1.00014 - 0.01671 * cos(g) - 0.00014 * cos(2 * g);
    out->equation_of_time_min = 4 * wrap180((l - ra) / RAD);
    finish(p, 90 - z / RAD, out);
}

ss_status ss_spa(ss_ctx *ctx, double unix_s, double lat_deg, double lon_deg, const ss_spa_params *p,
                 ss_spa_result *out)
{
    ss_call_begin(ctx);
    ss_status st = check_inputs(ctx, unix_s, lat_deg, lon_deg, p);
    if (st != SS_OK)
        return st;
    double days_ut = (unix_s + p->delta_ut1_s) / 86400.0 - J2000_UNIX_DAYS;
    out->julian_day = days_ut + 2451545.0;
    out->delta_t_s = delta_t_for(p, unix_s);
    out->heliocentric_longitude_deg = NAN;
    out->heliocentric_latitude_deg = NAN;
    out->nutation_longitude_deg = NAN;
    out->nutation_obliquity_deg = NAN;
    if (p->algorithm == SS_SUN_PSA) {
        psa(days_ut, lat_deg, lon_deg, p, out);
        return SS_OK;
    }
    spa_geo g;
    spa_geocentric(days_ut, days_ut + out->delta_t_s / 86400.0, &g);
    out->heliocentric_longitude_deg = g.l_deg;
    out->heliocentric_latitude_deg = g.b_deg;
    out->earth_sun_distance_au = g.r_au;
    out->nutation_longitude_deg = g.dpsi_deg;
    out->nutation_obliquity_deg = g.deps_deg;
    out->obliquity_deg = g.eps_deg;
    out->sidereal_time_deg = g.nu_deg;
    out->right_ascension_deg = g.alpha_deg;
    out->declination_deg = g.delta_deg;
    spa_observe(&g, lat_deg, lon_deg, p, out);
    return SS_OK;
}

/* ---- sunrise, transit, sunset (SPA appendix A.2) -------------------------------------------- */

/* Quadratic interpolation through the values at days -1, 0, +1 (SPA eq.
 * A.2.x, Meeus eq. 3.3); differences are taken modulo 360 so that a right
 * ascension passing 0 interpolates smoothly. */
static double interpolate(const double v[3], double n)
{
    double a = wrap180(v[1] - v[0]), b = wrap180(v[2] - v[1]);
    return v[1] + n * (a + b + (b - a) * n) / 2;
}

/* Correction, in days, to an event estimated at day fraction m (SPA eq.
 * A.2.18-20): for the transit the hour angle over 360; for rise and set the
 * altitude's distance from h0 divided by its rate of change. */
static double event_correction(const double alpha[3], const double delta[3], double nu_deg,
                               double lon_deg, double lat, double dt_days, double h0_deg,
                               int transit, double m)
{
    double n = m + dt_days;
    double a = interpolate(alpha, n), d = RAD * interpolate(delta, n);
    double hp = wrap180(nu_deg + 360.985647 * m + lon_deg - a); /* local hour angle */
    if (transit)
        return -hp / 360;
    double h = asin(sin(lat) * sin(d) + cos(lat) * cos(d) * cos(RAD * hp)) / RAD;
    return (h - h0_deg) / (360 * cos(d) * cos(lat) * sin(RAD * hp));
}

ss_status ss_sun_rise_set(ss_ctx *ctx, double day_start_unix_s, double lat_deg, double lon_deg,
                          const ss_spa_params *p, ss_sun_day *out)
{
    ss_call_begin(ctx);
    ss_status st = check_inputs(ctx, day_start_unix_s, lat_deg, lon_deg, p);
    if (st != SS_OK)
        return st;
    double dt_days = delta_t_for(p, day_start_unix_s) / 86400.0;
    double day0 = (day_start_unix_s + p->delta_ut1_s) / 86400.0 - J2000_UNIX_DAYS;
    /* alpha and delta at the same clock reading on the TT scale, days -1, 0, +1. */
    double alpha[3], delta[3], nu = 0;
    for (int i = 0; i < 3; ++i) {
        spa_geo g;
        spa_geocentric(day0, day0 + i - 1, &g);
        alpha[i] = g.alpha_deg;
        delta[i] = g.delta_deg;
        if (i == 1)
            nu = g.nu_deg; /* sidereal time at the day's start (UT1) */
    }
    double h0 = -(SS_SUN_RADIUS_DEG + p->atmos_refract_deg), lat = RAD * lat_deg;
    double m[3]; /* transit, rise, set as fractions of the day */
    m[0] = wrap360(alpha[1] - lon_deg - nu) / 360;
    double cos_h0 =
        (sin(RAD * h0) - sin(lat) * sin(RAD * delta[1])) / (cos(lat) * cos(RAD * delta[1]));
    /* Step 18: no rise or set when |cos H0| > 1; its sign says which. */
    out->kind = cos_h0 < -1  ? SS_SUN_POLAR_DAY
                : cos_h0 > 1 ? SS_SUN_POLAR_NIGHT
                             : SS_SUN_RISES_AND_SETS;
    int events = out->kind == SS_SUN_RISES_AND_SETS ? 3 : 1;
    double hw = events == 3 ? acos(cos_h0) / RAD / 360 : 0;
    m[1] = m[0] - hw;
    m[2] = m[0] + hw;
    /* SPA applies the rise/set correction once; repeating it (Meeus ch. 15)
     * changes mid-latitude times by under a second but is what keeps them
     * right where the sun only grazes the horizon (doc/sun.md). */
    double t[3];
    for (int k = 0; k < events; ++k) {
        t[k] = m[k];
        for (int it = 0; it < (k ? 10 : 1); ++it) {
            double c = event_correction(alpha, delta, nu, lon_deg, lat, dt_days, h0, k == 0, t[k]);
            if (!isfinite(c))
                break;
            t[k] += c;
            if (fabs(c) < 1e-7)
                break;
        }
    }
    out->transit_unix_s = day_start_unix_s + 86400.0 * t[0];
    out->sunrise_unix_s = events == 3 ? day_start_unix_s + 86400.0 * t[1] : NAN;
    out->sunset_unix_s = events == 3 ? day_start_unix_s + 86400.0 * t[2] : NAN;
    return SS_OK;
}
