/* A step's sun terms tabulated over its cells (sun_table.h). */
#include "config.h"

#include <math.h>

#include "sun_table.h"

/* Node spacings, chosen so that linear interpolation errs by under 1e-6
 * relative (the error is spacing^2 / 8 times the second derivative;
 * tests/test_sun_table measures it): 3e-5 rad in elevation and azimuth
 * (the air mass of a low sun, whose error the transmittance amplifies
 * twofold, needs that), and 1/2000 of the air mass itself (the
 * transmittance's exponent changes by at most about 0.1 T_LK per unit of
 * air mass: 0.67 at a Linke turbidity of 6.5, so 1e-8 relative).
 *
 * The azimuth's table could be far coarser for a high sun (its sine and
 * cosine enter the terms times cos h0), which would tabulate the spread of
 * a sun near the zenith (Hawaii in June: 7.7 % of a month's cell-steps are
 * computed per cell). It is not: each band tabulates its own cells' suns,
 * and a cell lit at grazing incidence (cos i within 1e-7 of 0) then flips
 * between Muneer's lit and shaded diffuse from a band to the whole grid
 * (48.9 Wh/m^2 at one cell of tests/test_memory.sh's DEM). Tables whose
 * nodes do not depend on the band would allow it; they are not built. */
#define ANGLE_SPACING_RAD 3e-5f
#define AIR_MASS_SPACING 5e-4f

void ss_sun_table_fill(ss_sun_table *t, float lo, float hi, float spacing, int terms,
                       ss_sun_table_fn fn, const void *user)
{
    t->terms = terms;
    t->lo = 0.0f;
    t->scale = 0.0f;
    t->last = -1;
    /* Without a table its first nodes are still defined: the lanes read
     * them and then drop what they read (insolation_lanes.h). */
    for (int k = 0; k < 2 * terms; ++k)
        t->node[k] = 0.0f;
    if (!(isfinite(lo) && isfinite(hi) && hi >= lo))
        return;
    t->lo = lo;
    double intervals = ceil((double)(hi - lo) / spacing);
    if (intervals > SS_SUN_TABLE_NODES)
        return;
    t->last = (int)intervals;
    if (t->last > 0)
        t->scale = (float)(t->last / ((double)hi - lo));
    for (int i = 0; i <= t->last; ++i) {
        float x = t->last > 0 ? (float)(lo + (double)i * (hi - (double)lo) / t->last) : lo;
        fn(x, user, t->node + (size_t)i * terms);
    }
}

static void elevation_terms(float h0, const void *user, float *v)
{
    const ss_step_sun *s = user;
    v[0] = sinf(h0);
    v[1] = cosf(h0);
    v[2] = s->clear ? ss_esra_air_mass_sea_level(h0) : 0.0f;
    v[3] = s->clear ? ss_esra_diffuse_fraction(s->linke, v[0]) : 0.0f;
}

static void azimuth_terms(float az, const void *user, float *v)
{
    (void)user;
    v[0] = sinf(az);
    v[1] = cosf(az);
}

static void transmittance(float m, const void *user, float *v)
{
    v[0] = ss_esra_beam_transmittance(((const ss_step_sun *)user)->linke, m);
}

/* The range in radians of the angles the cells will look up, converted as
 * they will be (degrees to radians in float): deg[c] over n cells, or
 * step_deg for all where deg is NULL; only those above 0 where
 * above_only (a clear sky's suns below the horizontal add nothing). */
static void range_rad(const float *deg, size_t n, float step_deg, int above_only, float *lo,
                      float *hi)
{
    const float rad = (float)(M_PI / 180.0);
    float r_lo = INFINITY, r_hi = -INFINITY;
    if (!deg) {
        float x = step_deg * rad;
        if (!above_only || x > 0.0f)
            r_lo = r_hi = x;
    }
    /* Selects, not branches, so that each thread's share runs in vector lanes. */
#pragma omp parallel for simd schedule(static) reduction(min : r_lo) reduction(max : r_hi)
    for (size_t c = 0; c < (deg ? n : 0); ++c) {
        float x = deg[c] * rad;
        int in = !above_only || x > 0.0f;
        float x_lo = in ? x : INFINITY, x_hi = in ? x : -INFINITY;
        r_lo = x_lo < r_lo ? x_lo : r_lo;
        r_hi = x_hi > r_hi ? x_hi : r_hi;
    }
    *lo = r_lo;
    *hi = r_hi;
}

void ss_step_sun_fill(ss_step_sun *s, const float *h0_deg, const float *az_deg, size_t n,
                      float h0_step_deg, float az_step_deg, float linke, int clear,
                      float pressure_lo, float pressure_hi)
{
    s->linke = linke;
    s->clear = clear;
    float h_lo, h_hi, a_lo, a_hi;
    range_rad(h0_deg, n, h0_step_deg, clear, &h_lo, &h_hi);
    range_rad(az_deg, n, az_step_deg, 0, &a_lo, &a_hi);
    ss_sun_table_fill(&s->elevation, h_lo, h_hi, ANGLE_SPACING_RAD, 4, elevation_terms, s);
    ss_sun_table_fill(&s->azimuth, a_lo, a_hi, ANGLE_SPACING_RAD, 2, azimuth_terms, s);
    if (!clear || s->elevation.last < 0) {
        ss_sun_table_fill(&s->air_mass, NAN, NAN, AIR_MASS_SPACING, 1, transmittance, s);
        return;
    }
    /* The air mass falls as the sun rises: its range over the table's nodes,
     * times the cells' pressure factors. */
    float m_lo = INFINITY, m_hi = -INFINITY;
    for (int i = 0; i <= s->elevation.last; ++i) {
        float m = s->elevation.node[(size_t)i * 4 + 2];
        m_lo = fminf(m_lo, m);
        m_hi = fmaxf(m_hi, m);
    }
    m_lo *= pressure_lo;
    m_hi *= pressure_hi;
    /* The transmittance steps where the Rayleigh thickness changes form:
     * a table spanning that air mass ends there, and the air masses beyond
     * are evaluated exactly. */
    if (m_lo <= SS_ESRA_RAYLEIGH_SPLIT_M && m_hi > SS_ESRA_RAYLEIGH_SPLIT_M)
        m_hi = SS_ESRA_RAYLEIGH_SPLIT_M;
    ss_sun_table_fill(&s->air_mass, m_lo, m_hi, AIR_MASS_SPACING * m_hi, 1, transmittance, s);
}
