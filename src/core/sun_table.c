/* A step's sun terms tabulated over its cells (sun_table.h). */
#include "config.h"

#include <math.h>

#include "sun_table.h"

/* Node spacings, chosen so that linear interpolation errs by under 1e-6
 * relative (the error is spacing^2 / 8 times the second derivative;
 * tests/test_sun_table measures it): 3e-5 rad in elevation (the air mass
 * of a low sun, whose error the transmittance amplifies twofold, needs
 * that); 1e-3 rad in azimuth, whose table holds a sine and a cosine alone
 * (1.25e-7 at most, about a float's rounding), so that the window spans
 * 29 degrees either side of the centre's sun: a sun near the zenith
 * spreads over tens of degrees of azimuth across a DEM (Hawaii in June,
 * where 3e-5 rad left 7.7 % of a month's cell-steps to be computed per
 * cell); and 1/2000 of the air mass at the centre's sun (the
 * transmittance's exponent changes by at most about 0.1 T_LK per unit of
 * air mass: 0.67 at a Linke turbidity of 6.5, so 1e-8 relative).
 *
 * The lattices are the step's, not the band's. When each band tabulated
 * its own cells' range, a cell lit at grazing incidence (cos i within 1e-7
 * of 0) could flip between Muneer's lit and shaded diffuse from a band to
 * the whole grid (48.9 Wh/m^2 at one cell of tests/test_memory.sh's DEM,
 * with azimuth nodes 3e-5 / cos h0 rad apart); on one lattice it cannot. */
#define ELEVATION_SPACING_RAD 3e-5f
#define AZIMUTH_SPACING_RAD 1e-3f
#define AIR_MASS_SPACING 5e-4f
/* The windows, in intervals, centred on the centre's sun for the angles:
 * elevations within 3.5 degrees of it (cells up to about 390 km from the
 * DEM's centre), azimuths within 29 degrees. A cell's offset from the
 * window's start (x - origin) rounds to a float, so a wider azimuth window
 * would lose precision (2.4e-7 rad at 117 degrees, against 6e-8). For the
 * air mass, from 0.6 to 2.6 times the centre's at sea level (the cells'
 * air pressure down to 0.6 of sea level's, at 4000 m, and lower suns than
 * the centre's), up to where Rayleigh's thickness changes form. A band
 * fills the nodes its cells need, so wide windows cost only memory. */
#define ELEVATION_WINDOW SS_SUN_TABLE_NODES
#define AZIMUTH_WINDOW 1024
#define AIR_MASS_WINDOW_BELOW 800

void ss_sun_table_fill(ss_sun_table *t, float origin, float spacing, int window, float lo,
                       float hi, int terms, ss_sun_table_fn fn, const void *user)
{
    t->terms = terms;
    t->origin = 0.0f;
    t->scale = 0.0f;
    t->first = 0;
    t->last = -1;
    /* Without a table its first nodes are still defined: the lanes read
     * them and then drop what they read (insolation_lanes.h). */
    for (int k = 0; k < 2 * terms; ++k)
        t->node[k] = 0.0f;
    /* An infinite end of the range (an air mass of no finite bound) is
     * clipped to the window; a NaN one, or an empty range, makes none. */
    if (!(isfinite(origin) && hi >= lo && window <= SS_SUN_TABLE_NODES))
        return;
    t->origin = origin;
    t->scale = 1.0f / spacing;
    /* The band's range on the lattice, as ss_sun_table_position places a
     * value, and one node past its top so that every value in it lies below
     * the last node. */
    float p_lo = (lo - origin) * t->scale, p_hi = (hi - origin) * t->scale;
    double first = fmax(floor(p_lo), 0.0), top = fmin(floor(p_hi) + 1.0, window);
    if (!(top > first))
        return;
    t->first = (int)first;
    t->last = (int)(top - first);
    for (int i = 0; i <= t->last; ++i)
        fn((float)(origin + (first + i) / t->scale), user, t->node + (size_t)i * terms);
}

static void elevation_terms(float h0, const void *user, float *v)
{
    const ss_step_sun *s = user;
    v[0] = sinf(h0);
    v[1] = cosf(h0);
    v[2] = ss_esra_air_mass_sea_level(h0);
    v[3] = ss_esra_diffuse_fraction(s->linke, v[0]);
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

/* The step's centre and, for a weather record, no tables; returns whether
 * the clear sky's tables are to be made. */
static int step_centre(ss_step_sun *s, float h0_step_deg, float az_step_deg, float linke,
                       int clear)
{
    s->linke = linke;
    s->clear = clear;
    s->centre = ss_sun_centre_of(h0_step_deg, az_step_deg);
    if (!clear) {
        ss_sun_table_fill(&s->elevation, NAN, 1.0f, 0, NAN, NAN, 4, elevation_terms, s);
        ss_sun_table_fill(&s->azimuth, NAN, 1.0f, 0, NAN, NAN, 2, azimuth_terms, s);
        ss_sun_table_fill(&s->air_mass, NAN, 1.0f, 0, NAN, NAN, 1, transmittance, s);
    }
    return clear;
}

/* A clear sky's tables over the cells' ranges (radians; the elevations
 * above the horizontal alone), per_cell_h and per_cell_a saying whether
 * the cells have suns of their own in elevation and in azimuth. */
static void clear_tables(ss_step_sun *s, int per_cell_h, int per_cell_a, float h_lo, float h_hi,
                         float a_lo, float a_hi, float pressure_lo, float pressure_hi)
{
    /* Cells' suns: SS_SUN_TABLE_NODES intervals centred on the centre's.
     * One sun for every cell: a lattice that starts on it, whose first node
     * holds its exact terms. */
    float h_step = s->centre.h, a_step = s->centre.a;
    float h_origin =
        per_cell_h ? (float)(h_step - ELEVATION_WINDOW / 2 * (double)ELEVATION_SPACING_RAD)
                   : h_step;
    float a_origin =
        per_cell_a ? (float)(a_step - AZIMUTH_WINDOW / 2 * (double)AZIMUTH_SPACING_RAD) : a_step;
    ss_sun_table_fill(&s->elevation, h_origin, ELEVATION_SPACING_RAD,
                      per_cell_h ? ELEVATION_WINDOW : 1, h_lo, h_hi, 4, elevation_terms, s);
    ss_sun_table_fill(&s->azimuth, a_origin, AZIMUTH_SPACING_RAD, per_cell_a ? AZIMUTH_WINDOW : 1,
                      a_lo, a_hi, 2, azimuth_terms, s);
    float m_ref = ss_esra_air_mass_sea_level(h_step > 0.0f ? h_step : 0.0f);
    if (s->elevation.last < 0 || !(m_ref > 0.0f)) {
        ss_sun_table_fill(&s->air_mass, NAN, 1.0f, 0, NAN, NAN, 1, transmittance, s);
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
    /* The window on the lattice of multiples of the spacing. The
     * transmittance steps where the Rayleigh thickness changes form, so the
     * window ends at the last node below that air mass, and the air masses
     * beyond are evaluated exactly. */
    float spacing = AIR_MASS_SPACING * m_ref;
    double k_origin = floor(m_ref / (double)spacing) - AIR_MASS_WINDOW_BELOW;
    double k_split = floor(SS_ESRA_RAYLEIGH_SPLIT_M / (double)spacing);
    /* (one node short of it, whatever the origin's rounding) */
    int window = (int)fmin(SS_SUN_TABLE_NODES, k_split - k_origin - 1.0);
    ss_sun_table_fill(&s->air_mass, (float)(k_origin * spacing), spacing, window, m_lo, m_hi, 1,
                      transmittance, s);
}

void ss_step_sun_fill(ss_step_sun *s, const float *h0_deg, const float *az_deg, size_t n,
                      float h0_step_deg, float az_step_deg, float linke, int clear,
                      float pressure_lo, float pressure_hi)
{
    if (!step_centre(s, h0_step_deg, az_step_deg, linke, clear))
        return;
    float h_lo, h_hi, a_lo, a_hi;
    range_rad(h0_deg, n, h0_step_deg, 1, &h_lo, &h_hi);
    range_rad(az_deg, n, az_step_deg, 0, &a_lo, &a_hi);
    clear_tables(s, h0_deg != NULL, az_deg != NULL, h_lo, h_hi, a_lo, a_hi, pressure_lo,
                 pressure_hi);
}

void ss_step_sun_fill_range(ss_step_sun *s, float h_lo, float h_hi, float a_lo, float a_hi,
                            float h0_step_deg, float az_step_deg, float linke, int clear,
                            float pressure_lo, float pressure_hi)
{
    if (step_centre(s, h0_step_deg, az_step_deg, linke, clear))
        clear_tables(s, 1, 1, h_lo, h_hi, a_lo, a_hi, pressure_lo, pressure_hi);
}
