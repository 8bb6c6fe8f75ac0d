/* A step's irradiance over runs of cells in SIMD lanes (src/core/
 * insolation_lanes.h) against the cell-by-cell functions it replaces
 * (ss_step_sun_at, then ss_cell_step_of or ss_cell_step_weather), bit for
 * bit, in every copy this CPU can run (the one for any CPU, and AVX2's):
 * - clear sky and weather records (isotropic, Hay-Davies, Perez);
 * - a sun per cell tabulated (clear sky) or near the centre's (weather), one
 *   sun for every cell, and suns outside the tables or too far from the
 *   centre's (which the lanes leave to the caller, and only those);
 * - horizons swept, stored as int16 between two directions, and none;
 * - the values are added into the band's sums, with and without a month's;
 * - nodata cells and suns below the horizontal add nothing, and runs of
 *   every length up to SS_LANE_CELLS. */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "insolation_internal.h"
#include "insolation_lanes.h"
#include "tap.h"

#define CELLS 700

typedef void (*lane_fn)(const ss_lane_step *, const ss_lane_suns *, const float *,
                        const ss_cell_terms *, size_t, int, ss_lane_adds *);

static uint32_t rng_state = 777u;
static float uniform(float lo, float hi)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return lo + (hi - lo) * (float)(rng_state >> 8) / (float)(1u << 24);
}

static float own_z[CELLS], h0_deg[CELLS], az_deg[CELLS], app_deg[CELLS], swept[CELLS];
/* The band's sums the lanes add into: beam, diffuse, reflected, global,
 * sun hours, the month's global. */
static float sums[6][CELLS];
static int16_t stored0[CELLS], stored1[CELLS];
static ss_cell_terms terms[CELLS];
static ss_step_sun tables;

/* What steps_direction did cell by cell before the lanes; per_cell: the
 * cells' own suns (h0_deg, az_deg, app_deg), else the step's. */
static ss_cell_step by_cell(const ss_lane_step *l, int per_cell, size_t c, int *adds)
{
    const float rad = (float)(M_PI / 180.0);
    float h0 = (per_cell ? h0_deg[c] : l->h0_step_deg) * rad;
    float az = (per_cell ? az_deg[c] : l->az_step_deg) * rad;
    float app = per_cell ? app_deg[c] : l->app_step_deg;
    ss_cell_step none = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    *adds = isfinite(own_z[c]) && (l->real_sky || h0 > 0.0f);
    if (!*adds)
        return none;
    float horizon = l->swept     ? l->swept[c]
                    : l->stored0 ? ((1.0f - l->stored_t) * l->stored0[c] +
                                    l->stored_t * l->stored1[c]) /
                                       SS_HORIZON_SCALE
                                 : -90.0f;
    ss_cell_sun at = ss_step_sun_at(l->tables, &terms[c], h0, az);
    return l->real_sky ? ss_cell_step_weather(&terms[c], &at, app, horizon, &l->rec, l->sky, l->dt)
                       : ss_cell_step_of(&terms[c], &at, app, horizon, l->g0, l->albedo, l->dt);
}

static int same_bits(float a, float b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* Runs of lengths 1, 2, ... over the cells through fn, into sums that start
 * at 0; counts the cells whose sums or global differ from by_cell's values
 * (added to 0 as the lanes add them), those left exact (which must add
 * nothing), and those the lanes left exact that the tables hold. */
static void compare(lane_fn fn, const char *copy, const ss_lane_step *l, const char *what,
                    int per_cell)
{
    int want_exact = per_cell; /* the outliers */
    int differ = 0, exact = 0, wrongly_exact = 0, adds = 0;
    memset(sums, 0, sizeof sums);
    size_t c0 = 0;
    for (int len = 1; c0 < CELLS; len = len % SS_LANE_CELLS + 1) {
        int n = CELLS - c0 < (size_t)len ? (int)(CELLS - c0) : len;
        ss_lane_adds out;
        ss_lane_suns suns = {NULL, NULL, NULL};
        if (per_cell)
            suns = (ss_lane_suns){h0_deg + c0, az_deg + c0, app_deg + c0};
        fn(l, &suns, own_z, terms, c0, n, &out);
        for (int j = 0; j < n; ++j) {
            size_t c = c0 + (size_t)j;
            int want_adds;
            ss_cell_step want = by_cell(l, per_cell, c, &want_adds);
            adds += want_adds;
            int lanes_add = out.what[j] == SS_LANE_ADD;
            float v[6] = {want.beam, want.diffuse, want.reflected, want.total, want.sun_hours,
                          l->month ? want.total : 0.0f};
            int same = out.what[j] == SS_LANE_EXACT ? want_adds : lanes_add == want_adds;
            for (int k = 0; k < 6; ++k)
                same &= same_bits(sums[k][c], lanes_add ? 0.0f + v[k] : 0.0f);
            same &= same_bits(out.global[j], lanes_add ? want.total : 0.0f);
            differ += !same;
            if (out.what[j] == SS_LANE_EXACT) {
                /* ss_step_sun_at's lookups (a clear sky's), or a weather
                 * record's sun near the centre's: held means no need. */
                exact++;
                float e[4], a[2], kb;
                const float rad = (float)(M_PI / 180.0);
                float h = (per_cell ? h0_deg[c] : l->h0_step_deg) * rad;
                float z = (per_cell ? az_deg[c] : l->az_step_deg) * rad;
                wrongly_exact += l->real_sky
                                     ? ss_sun_near(&tables.centre, h, z)
                                     : ss_sun_table_at(&tables.elevation, h, e) &&
                                           ss_sun_table_at(&tables.azimuth, z, a) &&
                                           ss_sun_table_at(&tables.air_mass,
                                                           terms[c].pressure_factor * e[2], &kb);
            }
        }
        c0 += (size_t)n;
    }
    tap_ok(differ == 0 && wrongly_exact == 0 && adds > CELLS / 4 && (exact > 0) == want_exact,
           "%s copy, %s: %d of %d cells differ from the cell-by-cell functions (%d add light, "
           "%d left exact, %d of them held)",
           copy, what, differ, CELLS, adds, exact, wrongly_exact);
}

/* Cells around a sun at (h_deg, az_step_deg), spread over spread_deg; nodata
 * every 37th cell; a few suns far outside the spread, in elevation and in
 * azimuth (exact: 40 degrees is beyond both the tables' windows and
 * SS_SUN_NEAR_RAD). */
static void make_cells(float h_deg, float az_step_deg, float spread_deg, int outliers)
{
    for (int c = 0; c < CELLS; ++c) {
        own_z[c] = c % 37 == 5 ? NAN : uniform(0, 3000);
        h0_deg[c] = h_deg + uniform(-0.5f, 0.5f) * spread_deg;
        az_deg[c] = az_step_deg + uniform(-0.5f, 0.5f) * spread_deg;
        if (outliers && c % 53 == 7)
            h0_deg[c] += 40.0f;
        if (outliers && c % 53 == 20)
            az_deg[c] += 40.0f;
        app_deg[c] = h0_deg[c] + 0.02f;
        swept[c] = uniform(-10, 30);
        stored0[c] = (int16_t)uniform(-1000, 3000);
        stored1[c] = (int16_t)uniform(-1000, 3000);
        float flat = c % 11 == 0 ? 0.0f : 1.0f;
        terms[c] = ss_cell_terms_of(flat * uniform(-1, 1), flat * uniform(-1, 1),
                                    uniform(0.4f, 1), own_z[c]);
        terms[c].band_seen = uniform(0, 1);
    }
}

static void fill_tables(const ss_lane_step *l, int clear, int per_cell)
{
    float p_lo = INFINITY, p_hi = -INFINITY;
    for (int c = 0; c < CELLS; ++c)
        if (isfinite(own_z[c])) {
            p_lo = fminf(p_lo, terms[c].pressure_factor);
            p_hi = fmaxf(p_hi, terms[c].pressure_factor);
        }
    /* Tables over the cells without the outliers: those fall outside. */
    static float h_in[CELLS], a_in[CELLS];
    int n = 0;
    for (int c = 0; c < CELLS; ++c)
        if (c % 53 != 7) {
            h_in[n] = h0_deg[c];
            a_in[n++] = az_deg[c];
        }
    ss_step_sun_fill(&tables, per_cell ? h_in : NULL, per_cell ? a_in : NULL, (size_t)n,
                     l->h0_step_deg, l->az_step_deg, 3.0f, clear, p_lo, p_hi);
}

static void check_copy(lane_fn fn, const char *copy)
{
    const char *shadows[] = {"swept horizons", "stored horizons", "no horizons"};
    const char *skies[] = {"clear sky", "weather, isotropic sky", "weather, Hay-Davies sky",
                           "weather, Perez sky, DNI below 120 W/m2"};
    for (int sky = 0; sky < 4; ++sky)
        for (int shadow = 0; shadow < 3; ++shadow)
            for (int per_cell = 0; per_cell < 2; ++per_cell) {
                float h = sky == 0 ? 25.0f : 0.05f; /* weather: some suns below the horizontal */
                /* A weather record's suns need no table: spread them over
                 * 20 deg, where ss_sincos_near's series matter. */
                make_cells(h, 140.0f, per_cell ? (sky == 0 ? 0.2f : 20.0f) : 0.0f, per_cell);
                ss_lane_step l = {.tables = &tables,
                                  .h0_step_deg = h,
                                  .az_step_deg = 140.0f,
                                  .app_step_deg = h + 0.02f,
                                  .swept = shadow == 0 ? swept : NULL,
                                  .stored0 = shadow == 1 ? stored0 : NULL,
                                  .stored1 = shadow == 1 ? stored1 : NULL,
                                  .stored_t = 0.3f,
                                  .real_sky = sky > 0,
                                  .g0 = 1361.0f,
                                  .albedo = 0.2f,
                                  .dt = 0.5f,
                                  .rec = {600.0f, sky == 3 ? 80.0f : 700.0f, 150.0f, 1361.0f, 0.25f},
                                  .beam = sums[0],
                                  .diffuse = sums[1],
                                  .reflected = sums[2],
                                  .global = sums[3],
                                  .sun_hours = sums[4],
                                  .month = shadow != 2 ? sums[5] : NULL};
                if (sky > 0)
                    l.sky = ss_sky_parts_of(sky - 1, l.rec.dhi, l.rec.dni, l.rec.dni_extra,
                                            (float)((90.0 - h) * M_PI / 180.0));
                fill_tables(&l, sky == 0, per_cell);
                char what[160];
                snprintf(what, sizeof what, "%s, %s, %s", skies[sky], shadows[shadow],
                         per_cell ? "a sun per cell" : "one sun");
                compare(fn, copy, &l, what, per_cell); /* the outliers run exact */
            }
}

int main(void)
{
    check_copy(ss_lane_cells_any, "any CPU's");
    check_copy(ss_lane_cells, "run-time chosen");
#if SS_LANES_V3
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma"))
        check_copy(ss_lane_cells_v3, "AVX2");
    else
        tap_skip("the AVX2 copy", "this CPU has no AVX2");
    if (ss_lanes_have_v4())
        check_copy(ss_lane_cells_v4, "AVX-512");
    else
        tap_skip("the AVX-512 copy", "this CPU has no AVX-512 (F, VL, BW, DQ)");
#endif
    return tap_done();
}
