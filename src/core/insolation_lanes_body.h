/* The body of ss_lane_cells (insolation_lanes.h), compiled once per
 * instruction set: insolation_lanes.c for any x86-64 (or other) CPU,
 * insolation_lanes_v3.c for AVX2 and FMA, insolation_lanes_v4.c for
 * AVX-512; each defines SS_LANE_ENTRY, the
 * name of its copy, and includes this file after its pragmas.
 *
 * Two options let GCC turn the cell functions' branches into selects:
 * floating-point operations may be computed where a branch would have
 * skipped them (no-trapping-math: only the flags of results that are then
 * not selected could differ, and nothing reads the flags), and loads are
 * not sunk into the branches that use them (no-tree-sink), where they
 * would need masks. Neither changes a value, and fused multiply-adds stay
 * off (whatever CFLAGS say), so every copy computes every cell's values to
 * the bit as the cell-by-cell functions do. The pragma
 * precedes the headers so that their inline functions are compiled alike. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-trapping-math", "no-tree-sink", "fp-contract=off")
#endif

#include "config.h"

#include <math.h>

#include "insolation_internal.h"
#include "insolation_lanes.h"

/* ss_sun_table_at without a branch: *terms get its values wherever it
 * returns 1 (the table holds x), and the index stays inside the table
 * wherever it does not (a table has two nodes or none, whose first two are
 * still defined). */
static inline __attribute__((always_inline)) int table_lane(const ss_sun_table *t, float x, float *terms, int n_terms)
{
    float lo = (float)t->first, hi = (float)(t->first + t->last), top = hi - 1.0f > lo ? hi - 1.0f : lo;
    float p = ss_sun_table_position(t, x);
    int ok = (p >= lo) & (p < hi);
    float clamped = p > lo ? p : lo; /* NaN too */
    clamped = clamped < top ? clamped : top;
    int k = (int)clamped;
    float f = p - (float)k;
    int i = k - t->first;
    int a = i * n_terms, b = a + n_terms; /* int offsets from the table: gathers */
#pragma GCC unroll 4
    for (int j = 0; j < n_terms; ++j)
        terms[j] = t->node[a + j] + f * (t->node[b + j] - t->node[a + j]);
    return ok;
}

/* One cell: what it adds, and whether its sun was held (by the tables, or
 * near enough the centre's: ss_step_sun_at). */
static inline __attribute__((always_inline)) int lane_cell(const ss_lane_step *s, const ss_cell_terms *t, float h0, float az,
                            float app, float horizon, int real_sky, ss_cell_step *add)
{
    const ss_step_sun *tb = s->tables;
    if (real_sky) {
        ss_cell_sun sun = ss_sun_near_of(&tb->centre, h0, az);
        *add = ss_cell_step_weather(t, &sun, app, horizon, &s->rec, s->sky, s->dt);
        return ss_sun_near(&tb->centre, h0, az);
    }
    float e[SS_SUN_TABLE_TERMS], a[2], kb = 0.0f;
    int ok = table_lane(&tb->elevation, h0, e, 4) & table_lane(&tb->azimuth, az, a, 2);
    ok &= table_lane(&tb->air_mass, t->pressure_factor * e[2], &kb, 1);
    ss_cell_sun sun = {h0, e[0], e[1], a[0], a[1], kb, e[3]};
    *add = ss_cell_step_of(t, &sun, app, horizon, s->g0, s->albedo, s->dt);
    return ok;
}

/* The run's cells for a clear sky (real_sky 0) or a weather record (1):
 * constant, so each loop is compiled for one. Sums and inputs count from
 * the run's first cell; month is never NULL here. */
static inline __attribute__((always_inline)) void lane_run(const ss_lane_step *s, const float *own_z, const ss_cell_terms *terms,
                            const float *h0_deg, const float *az_deg, const float *app_deg,
                            const float *horizon, int n, int real_sky, float *beam,
                            float *diffuse, float *reflected, float *global, float *sun_hours,
                            float *month, ss_lane_adds *out)
{
    const float rad = (float)(M_PI / 180.0);
#pragma omp simd
    for (int j = 0; j < n; ++j) {
        float h0 = h0_deg[j] * rad, az = az_deg[j] * rad;
        ss_cell_step add;
        int ok = lane_cell(s, &terms[j], h0, az, app_deg[j], horizon[j], real_sky, &add);
        int live = isfinite(own_z[j]) && (real_sky || h0 > 0.0f), use = live && ok;
        float g = use ? add.total : 0.0f;
        beam[j] += use ? add.beam : 0.0f;
        diffuse[j] += use ? add.diffuse : 0.0f;
        reflected[j] += use ? add.reflected : 0.0f;
        global[j] += g;
        sun_hours[j] += use ? add.sun_hours : 0.0f;
        month[j] += g;
        out->global[j] = g;
        out->what[j] = !live ? SS_LANE_SKIP : ok ? SS_LANE_ADD : SS_LANE_EXACT;
    }
}

/* A per-cell array of the run, or the step's value in each place. */
static const float *per_cell(const float *v, int n, float step, float *fill)
{
    if (v)
        return v;
    for (int j = 0; j < n; ++j)
        fill[j] = step;
    return fill;
}

void SS_LANE_ENTRY(const ss_lane_step *s, const ss_lane_suns *suns, const float *own_z,
                   const ss_cell_terms *terms, size_t c0, int n, ss_lane_adds *out)
{
    float h0_fill[SS_LANE_CELLS], az_fill[SS_LANE_CELLS], app_fill[SS_LANE_CELLS];
    float horizon[SS_LANE_CELLS];
    const float *h0 = per_cell(suns->h0_deg, n, s->h0_step_deg, h0_fill);
    const float *az = per_cell(suns->az_deg, n, s->az_step_deg, az_fill);
    const float *app = per_cell(suns->app_deg, n, s->app_step_deg, app_fill);
#pragma omp simd
    for (int j = 0; j < n; ++j)
        horizon[j] = ss_lane_horizon(s, c0 + (size_t)j);
    float no_month[SS_LANE_CELLS] = {0};
    float *month = s->month ? s->month + c0 : no_month;
    if (s->real_sky)
        lane_run(s, own_z + c0, terms + c0, h0, az, app, horizon, n, 1, s->beam + c0,
                 s->diffuse + c0, s->reflected + c0, s->global + c0, s->sun_hours + c0, month,
                 out);
    else
        lane_run(s, own_z + c0, terms + c0, h0, az, app, horizon, n, 0, s->beam + c0,
                 s->diffuse + c0, s->reflected + c0, s->global + c0, s->sun_hours + c0, month,
                 out);
}
