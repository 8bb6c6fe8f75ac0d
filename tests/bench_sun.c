/* PSA (2020 coefficients) against SPA: angular error over sites and years,
 * and the cost of one call of each. Prints the tables quoted in doc/sun.md.
 * Usage: bench_sun [calls-for-timing] */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "skysweep_sun.h"

#define RAD (M_PI / 180.0)

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Angle between two sky directions given as elevation and azimuth, degrees. */
static double separation_deg(double e1, double a1, double e2, double a2)
{
    double u[3] = {cos(RAD * e1) * sin(RAD * a1), cos(RAD * e1) * cos(RAD * a1), sin(RAD * e1)};
    double v[3] = {cos(RAD * e2) * sin(RAD * a2), cos(RAD * e2) * cos(RAD * a2), sin(RAD * e2)};
    double c[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    double dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    return atan2(sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), dot) / RAD;
}

typedef struct {
    double max_sep, sum_sq, max_elev, max_dist, max_eot;
    long n;
} errors;

/* Sites every 20 deg of latitude (-80..80) and 60 deg of longitude, times
 * stepping 2 days 3 h 7 min (so that hours of the day and seasons mix)
 * from year0 to year1; only samples with the sun above the horizon. */
static errors compare(ss_ctx *ctx, int year0, int year1)
{
    errors e = {0};
    ss_spa_params spa, psa;
    ss_spa_params_default(&spa);
    psa = spa;
    psa.algorithm = SS_SUN_PSA;
    double t0 = ss_unix_from_civil(year0, 1, 1, 0, 0, 0),
           t1 = ss_unix_from_civil(year1, 1, 1, 0, 0, 0);
    for (double t = t0; t < t1; t += 51 * 3600 + 7 * 60)
        for (int lat = -80; lat <= 80; lat += 20)
            for (int lon = -180; lon < 180; lon += 60) {
                ss_spa_result a, b;
                if (ss_spa(ctx, t, lat, lon, &spa, &a) || ss_spa(ctx, t, lat, lon, &psa, &b)) {
                    fprintf(stderr, "bench_sun: %s\n", ss_ctx_message(ctx));
                    exit(1);
                }
                if (a.elevation_deg <= 0)
                    continue;
                double s =
                    separation_deg(a.elevation_deg, a.azimuth_deg, b.elevation_deg, b.azimuth_deg);
                e.max_sep = fmax(e.max_sep, s);
                e.sum_sq += s * s;
                e.max_elev = fmax(e.max_elev, fabs(a.elevation_deg - b.elevation_deg));
                e.max_dist =
                    fmax(e.max_dist, fabs(a.earth_sun_distance_au - b.earth_sun_distance_au));
                e.max_eot = fmax(e.max_eot, fabs(a.equation_of_time_min - b.equation_of_time_min));
                e.n++;
            }
    return e;
}

/* Seconds per ss_spa call, over `calls` calls at changing times and sites. */
static double time_per_call(ss_ctx *ctx, ss_sun_algorithm algorithm, long calls, double *sink)
{
    ss_spa_params p;
    ss_spa_params_default(&p);
    p.algorithm = algorithm;
    p.delta_t_s = 69; /* fixed, so the model's calendar conversion is not timed */
    double t = ss_unix_from_civil(2026, 1, 1, 0, 0, 0), start = now_s();
    for (long i = 0; i < calls; ++i) {
        ss_spa_result r;
        ss_spa(ctx, t + 997.0 * i, -60 + (i % 120), -170 + (i % 340), &p, &r);
        *sink += r.zenith_deg;
    }
    return (now_s() - start) / (double)calls;
}

int main(int argc, char **argv)
{
    long calls = argc > 1 ? atol(argv[1]) : 200000;
    ss_ctx *ctx = ss_ctx_new();
    const int periods[][2] = {{2020, 2050}, {2000, 2020}, {2050, 2100}, {1950, 2000}};
    printf("PSA (2020 coefficients) minus SPA, sun above the horizon, no refraction;\n"
           "sites every 20 deg lat (-80..80) x 60 deg lon, times every 51 h 7 min.\n\n");
    printf("| years | samples | max angle (deg) | RMS angle (deg) | max elevation (deg) | "
           "max distance (AU) | max EoT (min) |\n|---|---|---|---|---|---|---|\n");
    for (size_t i = 0; i < sizeof periods / sizeof periods[0]; ++i) {
        errors e = compare(ctx, periods[i][0], periods[i][1]);
        printf("| %d-%d | %ld | %.4f | %.4f | %.4f | %.1e | %.3f |\n", periods[i][0], periods[i][1],
               e.n, e.max_sep, sqrt(e.sum_sq / (double)e.n), e.max_elev, e.max_dist, e.max_eot);
    }
    double sink = 0;
    time_per_call(ctx, SS_SUN_SPA, calls / 10, &sink); /* warm up */
    double spa_s = time_per_call(ctx, SS_SUN_SPA, calls, &sink);
    double psa_s = time_per_call(ctx, SS_SUN_PSA, calls, &sink);
    printf("\n| algorithm | time per ss_spa call (us) | calls/s |\n|---|---|---|\n");
    printf("| SPA | %.3f | %.3g |\n| PSA | %.3f | %.3g |\n", 1e6 * spa_s, 1 / spa_s, 1e6 * psa_s,
           1 / psa_s);
    printf("\nSPA / PSA time ratio %.1f (%ld calls each; checksum %.3f)\n", spa_s / psa_s, calls,
           sink);
    ss_ctx_free(ctx);
    return 0;
}
