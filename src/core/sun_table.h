/* A step's sun terms, tabulated over the range its cells span. Per cell the
 * sun's elevation and azimuth differ from the step's centre by at most the
 * planner's spread (0.11 deg over the 15 km sample), and what insolation
 * takes from them are smooth functions: their sines and cosines,
 * Kasten-Young's air mass, ESRA's diffuse fraction and, of the air mass,
 * the beam transmittance. Evaluated at nodes across the step's range and
 * interpolated linearly, a cell costs no transcendental call. The nodes lie
 * close enough that interpolation errs by under 1e-6 relative
 * (tests/test_sun_table, doc/insolation.md); a value beyond the step's
 * window of nodes is evaluated exactly. The nodes lie on a lattice around
 * the step's centre, the same for every band, so that bands give the
 * whole grid's values to the bit, for every cell that adds light (a clear
 * sky's suns below the horizontal add nothing, and are left out of the
 * range). With one sun for every cell a node lies on it: its terms are the
 * exact ones.
 *
 * A weather record's sky takes the sines and cosines alone, and those need
 * no table: each cell's come from the centre's by the angle-addition
 * formulas, with the sine and cosine of its small difference from the
 * centre's sun as series (ss_sincos_near, kernels/ss_cell_step.h). That costs the lanes a few
 * multiplications where the tables cost gathers, and the step no scan of
 * its cells' range (3.6 s of an hourly weather year on the Kilauea DEM,
 * doc/performance.md). */
#ifndef SS_SUN_TABLE_H
#define SS_SUN_TABLE_H

#include <stddef.h>

#include "insolation_cell.h"

#define SS_SUN_TABLE_NODES 4096 /* the most intervals a table holds */
#define SS_SUN_TABLE_TERMS 4   /* the most functions tabulated together */

/* Functions of one variable, tabulated on a lattice: node k lies at
 * origin + k / scale, and the table holds nodes first to first + last
 * (last -1: no table). The origin and spacing are the step's, never the
 * band's, and where a value lies on the lattice depends on them alone: so
 * the terms of a cell whose value the band's range holds are the same to
 * the bit in any band and in the whole grid. */
typedef struct {
    float origin, scale;
    int first, last, terms;
    float node[(SS_SUN_TABLE_NODES + 1) * SS_SUN_TABLE_TERMS];
} ss_sun_table;

/* The tabulated functions' values at x, into terms[]. */
typedef void (*ss_sun_table_fn)(float x, const void *user, float *terms);

/* Tabulates fn on the lattice of nodes origin + k * spacing, for the
 * nodes k from 0 to window (at most SS_SUN_TABLE_NODES: the step's window)
 * that the values in [lo, hi] (the band's) need; no table where there are
 * none. */
void ss_sun_table_fill(ss_sun_table *t, float origin, float spacing, int window, float lo,
                       float hi, int terms, ss_sun_table_fn fn, const void *user);

/* Where x lies on t's lattice: node (int)p, and the fraction p - (int)p
 * towards the next (exact: p lies within [0, 2^23) where a table holds
 * it). */
static inline float ss_sun_table_position(const ss_sun_table *t, float x)
{
    return (x - t->origin) * t->scale;
}

/* The functions at x, linear between the nodes; 0 where the table does
 * not hold x (the caller evaluates exactly). */
static inline int ss_sun_table_at(const ss_sun_table *t, float x, float *terms)
{
    float p = ss_sun_table_position(t, x);
    if (!(p >= (float)t->first && p < (float)(t->first + t->last)))
        return 0;
    int k = (int)p;
    float f = p - (float)k;
    const float *a = t->node + (size_t)(k - t->first) * t->terms, *b = a + t->terms;
    for (int j = 0; j < t->terms; ++j)
        terms[j] = a[j] + f * (b[j] - a[j]);
    return 1;
}

/* A step's sun over a band's cells: for a clear sky, its tables of the
 * true elevation h0 (sin, cos, sea-level air mass, diffuse fraction), of
 * the grid azimuth (sin, cos) and of the air mass (beam transmittance), for
 * the step's Linke turbidity; for a weather record (clear 0), the centre's
 * sun alone. */
typedef struct {
    ss_sun_table elevation, azimuth, air_mass;
    float linke;
    int clear;
    ss_sun_centre centre; /* the weather record's cells' suns come from it */
} ss_step_sun;

/* The tables for a step whose centre's sun (true elevation and grid
 * azimuth, degrees) is h0_step_deg and az_step_deg, and whose cells' suns
 * are h0_deg[c] and az_deg[c] over n cells, or the centre's for all where
 * those are NULL; the cells' air pressure factors span [pressure_lo,
 * pressure_hi]. The lattices lie around the centre's sun, so every band of
 * a step gets the same values. A clear sky tabulates the sun above the
 * horizontal alone (below it a cell adds nothing, whatever its terms); a
 * weather record's sky makes no table (its cells' h0_deg and az_deg are
 * not read). */
void ss_step_sun_fill(ss_step_sun *s, const float *h0_deg, const float *az_deg, size_t n,
                      float h0_step_deg, float az_step_deg, float linke, int clear,
                      float pressure_lo, float pressure_hi);
/* The same for cells with suns of their own whose range is known without
 * them (radians, as the cells look them up: true elevations [h_lo, h_hi],
 * of those above the horizontal alone, and grid azimuths [a_lo, a_hi]). A
 * wider range than the cells' gives them the same values: it only fills
 * more nodes of the same lattices. */
void ss_step_sun_fill_range(ss_step_sun *s, float h_lo, float h_hi, float a_lo, float a_hi,
                            float h0_step_deg, float az_step_deg, float linke, int clear,
                            float pressure_lo, float pressure_hi);

/* The sun's terms at a cell whose sun is h0 and az (radians): a weather
 * record's sines and cosines from the centre's, a clear sky's terms from
 * the tables; else exactly. */
static inline ss_cell_sun ss_step_sun_at(const ss_step_sun *s, const ss_cell_terms *t, float h0,
                                         float az)
{
    float e[SS_SUN_TABLE_TERMS], a[2] = {0.0f, 0.0f}, kb = 0.0f;
    ss_cell_sun sun;
    if (!s->clear) {
        return ss_sun_near(&s->centre, h0, az) ? ss_sun_near_of(&s->centre, h0, az)
                                               : ss_cell_sun_exact(t, h0, az, s->linke, 0);
    }
    if (!ss_sun_table_at(&s->elevation, h0, e))
        return ss_cell_sun_exact(t, h0, az, s->linke, s->clear);
    /* A sun near the zenith spreads over tens of degrees of azimuth: beyond
     * the table's window its sine and cosine alone are computed per cell. */
    if (!ss_sun_table_at(&s->azimuth, az, a)) {
        a[0] = sinf(az);
        a[1] = cosf(az);
    }
    sun.h0 = h0;
    sun.sin_h0 = e[0];
    sun.cos_h0 = e[1];
    sun.sin_az = a[0];
    sun.cos_az = a[1];
    float m = t->pressure_factor * e[2];
    sun.kb = ss_sun_table_at(&s->air_mass, m, &kb) ? kb : ss_esra_beam_transmittance(s->linke, m);
    sun.diffuse_fraction = e[3];
    return sun;
}

#endif
