/* A step's sun terms tabulated over its cells (src/core/sun_table.h)
 * against the same terms evaluated exactly per cell:
 * - the sines and cosines within 1e-6, the beam transmittance and the
 *   diffuse fraction within 2e-6 relative, and the step's irradiance at a
 *   cell within 1e-6 of the extraterrestrial, from a sun 0.05 deg above
 *   the horizontal to the zenith, over spreads up to 1.4 deg and heights
 *   up to 4000 m. The exact terms are floats too: a low sun's
 *   transmittance, exp(-4.5) in a turbid sky, moves by 5e-7 between
 *   neighbouring floats of its air mass, which the tables smooth out;
 * - the tables are made where the suns spread over a DEM's usual 0.1 deg;
 * - one sun for every cell gives the exact sines, cosines and diffuse
 *   fraction, bit for bit, and the transmittance over the cells' air
 *   pressures within 2e-6;
 * - a weather record's suns, below the horizontal too, get their sines and
 *   cosines from the centre's (ss_sincos_near), without tables;
 * - a value outside its table (the band's range, or the step's window) is
 *   evaluated exactly;
 * - a band's tables give its cells the whole grid's terms to the bit;
 * - a lattice's per-cell suns, run by run, are the whole row's and the
 *   bilinear interpolation of its nodes. */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "skysweep_sun.h"
#include "sun_table.h"
#include "tap.h"

#define CELLS 4000

static uint32_t rng_state = 12345u;
static float uniform(float lo, float hi)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return lo + (hi - lo) * (float)(rng_state >> 8) / (float)(1u << 24);
}

static double relative(float got, float want)
{
    return fabs((double)got - want) / fmax(fabs((double)want), 1e-3);
}

/* Cells whose suns scatter over spread_deg around (h_deg, az_deg) (over
 * az_spread_deg in azimuth), their
 * heights from 0 to 4000 m, their slopes up to 45 deg: the worst error of
 * the sines and cosines, of the clear sky's terms (relative) and of the
 * step's global at a cell. */
static void check_range(float h_deg, float az_deg, float spread_deg, float az_spread_deg,
                        float linke)
{
    static float h0[CELLS], az[CELLS];
    static ss_cell_terms terms[CELLS];
    static ss_step_sun table;
    const float rad = (float)(M_PI / 180.0);
    float p_lo = INFINITY, p_hi = -INFINITY;
    for (int c = 0; c < CELLS; ++c) {
        h0[c] = h_deg + uniform(-0.5f, 0.5f) * spread_deg;
        az[c] = az_deg + uniform(-0.5f, 0.5f) * az_spread_deg;
        terms[c] = ss_cell_terms_of(uniform(-1, 1), uniform(-1, 1), uniform(0.5f, 1), uniform(0, 4000));
        p_lo = fminf(p_lo, terms[c].pressure_factor);
        p_hi = fmaxf(p_hi, terms[c].pressure_factor);
    }
    ss_step_sun_fill(&table, h0, az, CELLS, h_deg, az_deg, linke, 1, p_lo, p_hi);
    double worst_trig = 0, worst_sky = 0, worst_global = 0;
    int up = 0, angles_held = 0, air_mass_held = 0;
    for (int c = 0; c < CELLS; ++c) {
        float h = h0[c] * rad, a = az[c] * rad, e[SS_SUN_TABLE_TERMS], v[2];
        if (h <= 0.0f)
            continue;
        up++;
        if (ss_sun_table_at(&table.elevation, h, e) && ss_sun_table_at(&table.azimuth, a, v)) {
            angles_held++;
            air_mass_held += ss_sun_table_at(&table.air_mass, terms[c].pressure_factor * e[2], v);
        }
        ss_cell_sun got = ss_step_sun_at(&table, &terms[c], h, a);
        ss_cell_sun want = ss_cell_sun_exact(&terms[c], h, a, linke, 1);
        float trig[][2] = {{got.sin_h0, want.sin_h0}, {got.cos_h0, want.cos_h0},
                           {got.sin_az, want.sin_az}, {got.cos_az, want.cos_az}};
        for (size_t k = 0; k < sizeof trig / sizeof trig[0]; ++k)
            worst_trig = fmax(worst_trig, fabs((double)trig[k][0] - trig[k][1]));
        worst_sky = fmax(worst_sky, fmax(relative(got.kb, want.kb),
                                         relative(got.diffuse_fraction, want.diffuse_fraction)));
        ss_cell_step s_got = ss_cell_step_of(&terms[c], &got, h0[c], -90.0f, 1361.0f, 0.2f, 1.0f);
        ss_cell_step s_want = ss_cell_step_of(&terms[c], &want, h0[c], -90.0f, 1361.0f, 0.2f, 1.0f);
        worst_global = fmax(worst_global, fabs((double)s_got.total - s_want.total) / 1361.0);
    }
    /* The tables hold every cell's sun, and above 3 deg (an air mass below
     * 20: sun_table.c) most air masses. */
    int made = angles_held == up && (h_deg < 3.0f || air_mass_held > up / 2);
    tap_ok(worst_trig <= 1e-6 && worst_sky <= 2e-6 && worst_global <= 1e-6 && made,
           "sun at %.2f deg, spread %.2f deg in elevation and %.2f deg in azimuth, Linke %.1f: "
           "tables of %d/%d/%d intervals (-1: exact) holding %d/%d/%d of %d cell suns, worst "
           "sine %.2e, transmittance or diffuse fraction %.2e relative, global %.2e of the "
           "extraterrestrial",
           h_deg, spread_deg, az_spread_deg, linke, table.elevation.last, table.azimuth.last,
           table.air_mass.last, angles_held, angles_held, air_mass_held, up, worst_trig,
           worst_sky, worst_global);
}

/* One sun for every cell, over heights from 0 to 3000 m: the elevation
 * and azimuth tables have a node on it, their terms exact; the
 * transmittance is tabulated over the air pressures. */
static void check_one_sun(void)
{
    static ss_step_sun table;
    static ss_cell_terms terms[100];
    const float rad = (float)(M_PI / 180.0);
    float h_deg = 23.4f, az_deg = 131.0f, h = h_deg * rad, a = az_deg * rad;
    for (int c = 0; c < 100; ++c)
        terms[c] = ss_cell_terms_of(0.3f, -0.2f, 0.9f, 30.0 * c);
    ss_step_sun_fill(&table, NULL, NULL, 100, h_deg, az_deg, 3.0f, 1, terms[99].pressure_factor,
                     terms[0].pressure_factor);
    int exact = 1;
    double worst_kb = 0;
    for (int c = 0; c < 100; ++c) {
        ss_cell_sun got = ss_step_sun_at(&table, &terms[c], h, a);
        ss_cell_sun want = ss_cell_sun_exact(&terms[c], h, a, 3.0f, 1);
        exact &= got.sin_h0 == want.sin_h0 && got.cos_h0 == want.cos_h0 &&
                 got.sin_az == want.sin_az && got.cos_az == want.cos_az &&
                 got.diffuse_fraction == want.diffuse_fraction;
        worst_kb = fmax(worst_kb, relative(got.kb, want.kb));
    }
    tap_ok(table.elevation.last == 1 && table.azimuth.last == 1 && table.air_mass.last > 0 &&
               exact && worst_kb <= 2e-6,
           "one sun for all cells: the lattice's node at it, exact sines and diffuse fraction; "
           "the transmittance over %d intervals of air mass within %.2e relative",
           table.air_mass.last, worst_kb);
}

/* A weather record's suns straddle the horizontal, 20 deg either side in
 * elevation and 35 in azimuth (a sun near the zenith): their sines and
 * cosines come from the centre's by ss_sincos_near within 2.5e-7 of the
 * exact ones out to SS_SUN_NEAR_RAD (a few float roundings), beyond it the
 * exact ones, and no table is made. */
static void check_weather(void)
{
    static ss_step_sun table;
    const float rad = (float)(M_PI / 180.0);
    ss_cell_terms t = ss_cell_terms_of(0.2f, 0.1f, 0.95f, 500.0);
    ss_step_sun_fill(&table, NULL, NULL, 0, 0.0f, 61.0f, 3.0f, 0, t.pressure_factor,
                     t.pressure_factor);
    double worst = 0;
    int near = 0, far = 0, exact_far = 1;
    for (int c = 0; c < CELLS; ++c) {
        float h = uniform(-20.0f, 20.0f) * rad, a = (61.0f + uniform(-35.0f, 35.0f)) * rad;
        ss_cell_sun got = ss_step_sun_at(&table, &t, h, a);
        ss_cell_sun want = ss_cell_sun_exact(&t, h, a, 3.0f, 0);
        if (ss_sun_near(&table.centre, h, a)) {
            near++;
            float d[] = {got.sin_h0 - want.sin_h0, got.cos_h0 - want.cos_h0,
                         got.sin_az - want.sin_az, got.cos_az - want.cos_az};
            for (int k = 0; k < 4; ++k)
                worst = fmax(worst, fabs((double)d[k]));
        } else {
            far++;
            exact_far &= got.sin_h0 == want.sin_h0 && got.cos_az == want.cos_az;
        }
    }
    tap_ok(table.elevation.last == -1 && table.azimuth.last == -1 && table.air_mass.last == -1 &&
               near > CELLS / 4 && far > 0 && exact_far && worst <= 2.5e-7,
           "a weather record's suns 20 deg either side of the horizontal, 35 deg in azimuth: no "
           "table; %d near the centre's within %.2e of the exact sines and cosines, %d beyond "
           "%.1f rad exact",
           near, worst, far, (double)SS_SUN_NEAR_RAD);
}

static void only_f(float x, const void *user, float *v)
{
    (void)user;
    v[0] = x * x;
}

/* Outside the band's range (one node past its top aside) or the step's
 * window, a table answers nothing and the cell is evaluated exactly. */
static void check_outside(void)
{
    static ss_sun_table t;
    float v = -1.0f;
    /* nodes 0.01 apart from 0.9 to 2.1 */
    ss_sun_table_fill(&t, 0.9f, 0.01f, 120, 1.0f, 2.0f, 1, only_f, NULL);
    int inside = ss_sun_table_at(&t, 1.5f, &v);
    float at_inside = v;
    int top = ss_sun_table_at(&t, 2.005f, &v);
    int below = ss_sun_table_at(&t, 0.995f, &v), above = ss_sun_table_at(&t, 2.011f, &v);
    int nan = ss_sun_table_at(&t, NAN, &v);
    tap_ok(t.last == 101 && inside && fabsf(at_inside - 2.25f) < 1e-4f && top && !below &&
               !above && !nan,
           "a table answers inside its range and one node past it alone (%d intervals; x^2 at "
           "1.5: %g)",
           t.last, at_inside);
    ss_sun_table_fill(&t, 0.9f, 0.01f, 120, 0.0f, 3.0f, 1, only_f, NULL);
    int clipped = t.last == 120 && ss_sun_table_at(&t, 0.905f, &v) &&
                  !ss_sun_table_at(&t, 0.895f, &v) && !ss_sun_table_at(&t, 2.11f, &v);
    ss_sun_table_fill(&t, 0.9f, 0.01f, 120, 1.0f, INFINITY, 1, only_f, NULL);
    clipped &= t.last == 110 && ss_sun_table_at(&t, 2.05f, &v);
    tap_ok(clipped, "a range wider than the step's window is tabulated over the window alone");
    ss_sun_table_fill(&t, 0.0f, 1e-4f, 10000, 0.0f, 1.0f, 1, only_f, NULL);
    tap_ok(t.last == -1 && !ss_sun_table_at(&t, 0.5f, &v),
           "a window of 10000 intervals makes no table");

    static ss_step_sun table;
    static float h0[2] = {10.0f, 30.0f}, az[2] = {100.0f, 101.0f};
    ss_cell_terms terms = ss_cell_terms_of(0.1f, 0.1f, 1.0f, 0.0);
    const float rad = (float)(M_PI / 180.0);
    ss_step_sun_fill(&table, h0, az, 2, 20.0f, 100.5f, 3.0f, 1, 1.0f, 1.0f);
    int exact = 1;
    for (int c = 0; c < 2; ++c) {
        ss_cell_sun got = ss_step_sun_at(&table, &terms, h0[c] * rad, az[c] * rad);
        ss_cell_sun want = ss_cell_sun_exact(&terms, h0[c] * rad, az[c] * rad, 3.0f, 1);
        exact &= got.kb == want.kb && got.sin_h0 == want.sin_h0 && got.cos_az == want.cos_az;
    }
    tap_ok(exact, "suns 10 deg either side of the centre's: beyond the window, the exact terms");
}

/* A band's tables give its cells the whole grid's terms to the bit: the
 * lattice is the step's. The cells' suns spread over 10 deg of elevation
 * and 80 deg of azimuth (beyond both windows) and their heights up to
 * 4000 m (beyond the air mass's), so bands hold cells both inside and
 * outside each table. A clear sky's suns below the horizontal are not
 * tabulated (they add nothing: test_insolation_lanes), so only those above
 * are compared; a weather record's are all. */
static void check_bands(void)
{
    static float h0[CELLS], az[CELLS];
    static ss_cell_terms terms[CELLS];
    static ss_step_sun whole, band;
    const float rad = (float)(M_PI / 180.0);
    const float h_deg[] = {0.3f, 8.0f, 60.0f}, az_deg = 170.0f;
    const int band_cells[] = {333, 700, 1410};
    int same = 1, compared = 0, held[3] = {0}, missed[3] = {0};
    for (int clear = 0; clear < 2; ++clear)
        for (int k = 0; k < 3; ++k) {
            for (int c = 0; c < CELLS; ++c) {
                /* rows of cells: the sun changes along them */
                float along = (float)c / CELLS;
                h0[c] = h_deg[k] + 10.0f * (along - 0.5f) + uniform(-0.01f, 0.01f);
                az[c] = az_deg + 80.0f * (along - 0.5f);
                terms[c] = ss_cell_terms_of(uniform(-1, 1), uniform(-1, 1), uniform(0.5f, 1),
                                            uniform(0, 4000));
            }
            ss_step_sun_fill(&whole, h0, az, CELLS, h_deg[k], az_deg, 4.0f, clear, 0.6f, 1.0f);
            for (int b = 0; b < 3; ++b)
                for (int row0 = 0; row0 < CELLS; row0 += band_cells[b]) {
                    int n = CELLS - row0 < band_cells[b] ? CELLS - row0 : band_cells[b];
                    float p_lo = INFINITY, p_hi = -INFINITY;
                    for (int c = row0; c < row0 + n; ++c) {
                        p_lo = fminf(p_lo, terms[c].pressure_factor);
                        p_hi = fmaxf(p_hi, terms[c].pressure_factor);
                    }
                    ss_step_sun_fill(&band, h0 + row0, az + row0, (size_t)n, h_deg[k], az_deg,
                                     4.0f, clear, p_lo, p_hi);
                    for (int c = row0; c < row0 + n; ++c) {
                        float h = h0[c] * rad, a = az[c] * rad, e[SS_SUN_TABLE_TERMS], v[2];
                        if (clear && !(h > 0.0f))
                            continue;
                        ss_cell_sun w = ss_step_sun_at(&whole, &terms[c], h, a);
                        ss_cell_sun o = ss_step_sun_at(&band, &terms[c], h, a);
                        same &= w.sin_h0 == o.sin_h0 && w.cos_h0 == o.cos_h0 &&
                                w.sin_az == o.sin_az && w.cos_az == o.cos_az && w.kb == o.kb &&
                                w.diffuse_fraction == o.diffuse_fraction;
                        compared++;
                        int in[3] = {ss_sun_table_at(&band.elevation, h, e),
                                     ss_sun_table_at(&band.azimuth, a, v), 0};
                        in[2] = clear && in[0] &&
                                ss_sun_table_at(&band.air_mass, terms[c].pressure_factor * e[2],
                                                v);
                        for (int t = 0; t < 3; ++t) {
                            held[t] += in[t];
                            missed[t] += !in[t] && (t < 2 || (clear && in[0]));
                        }
                    }
                }
        }
    int both = 1;
    for (int t = 0; t < 3; ++t)
        both &= held[t] > 0 && missed[t] > 0;
    tap_ok(same && both,
           "bands of 333, 700 and 1410 cells get the whole grid's terms to the bit (%d cell suns "
           "compared; held/missed by the tables: elevation %d/%d, azimuth %d/%d, air mass %d/%d)",
           compared, held[0], missed[0], held[1], missed[1], held[2], missed[2]);
}

/* Per-cell suns from a lattice (ss_sun_lattice_cells, which insolation
 * calls on runs of cells and the command line's sun field on whole rows):
 * runs of any length and start give a row's cells the whole row's values to
 * the bit, and those are the bilinear interpolation of the nodes, worked
 * out here again in double, with refraction interpolated where the sun is
 * up at a cell's four nodes and computed for the cell where it is not;
 * the lattice's shared columns go to the segment they start. */
static void check_lattice_runs(void)
{
    enum { W = 76, H = 50, NC = 4, NR = 3 };
    static const int cols[NC] = {0, 30, 60, W - 1}, rows[NR] = {0, 20, H - 1};
    double az[NC * NR], e0[NC * NR], refr[NC * NR];
    const double hpa = 1013.25, temp = 12.0, atmos = 0.5667;
    for (int j = 0; j < NR; ++j)
        for (int i = 0; i < NC; ++i) {
            int k = j * NC + i;
            az[k] = 100.0 + 0.013 * i - 0.021 * j;
            e0[k] = -0.3 + 0.2 * i + 0.1 * j; /* down at some nodes: refraction per cell there */
            refr[k] = ss_spa_refraction_deg(e0[k], hpa, temp, atmos);
        }
    ss_sun_lattice l = {NC, NR, cols, rows, az, e0, refr, hpa, temp, atmos};
    double tx[W + NC];
    ss_sun_lattice_tx(&l, tx);
    int same = 1, per_cell = 0, smooth_cells = 0;
    double worst = 0;
    for (int r = 0; r < H; ++r) {
        float whole[3][W], part[3][W];
        ss_sun_lattice_cells(&l, tx, r, 0, W, whole[0], whole[1], whole[2]);
        for (int c0 = 0; c0 < W;) {
            int n = 1 + (int)uniform(0.0f, 40.0f);
            n = n < W - c0 ? n : W - c0;
            ss_sun_lattice_cells(&l, tx, r, c0, n, part[0] + c0, part[1] + c0, part[2] + c0);
            c0 += n;
        }
        for (int v = 0; v < 3; ++v)
            for (int c = 0; c < W; ++c)
                same &= memcmp(&whole[v][c], &part[v][c], sizeof(float)) == 0;
        /* On a few rows, every run: each start (shared columns, the last
         * one) and each length, none too (which writes nothing). */
        for (int c0 = 0; (r == 0 || r == 20 || r == 37 || r == H - 1) && c0 < W; ++c0)
            for (int n = 0; n <= W - c0; ++n) {
                float run[3][W + 1];
                run[0][n] = run[1][n] = run[2][n] = -999.0f;
                ss_sun_lattice_cells(&l, tx, r, c0, n, run[0], run[1], run[2]);
                for (int v = 0; v < 3; ++v) {
                    same &= memcmp(run[v], whole[v] + c0, sizeof(float) * (size_t)n) == 0;
                    same &= run[v][n] == -999.0f;
                }
            }
        int j = r < rows[1] || r == rows[1] ? 0 : 1; /* a row on a node takes the rows below it */
        double ty = (double)(r - rows[j]) / (rows[j + 1] - rows[j]);
        for (int c = 0; c < W; ++c) {
            int i = c >= cols[2] ? 2 : c >= cols[1] ? 1 : 0;
            double t = (double)(c - cols[i]) / (cols[i + 1] - cols[i]);
            int a = j * NC + i, b = a + 1, d = a + NC, e = d + 1;
            double w[4] = {(1 - t) * (1 - ty), t * (1 - ty), (1 - t) * ty, t * ty};
            double want_az = w[0] * az[a] + w[1] * az[b] + w[2] * az[d] + w[3] * az[e];
            double want_e0 = w[0] * e0[a] + w[1] * e0[b] + w[2] * e0[d] + w[3] * e0[e];
            int up = e0[a] > 0 && e0[b] > 0 && e0[d] > 0 && e0[e] > 0;
            double want_refr = up ? w[0] * refr[a] + w[1] * refr[b] + w[2] * refr[d] + w[3] * refr[e]
                                  : ss_spa_refraction_deg(want_e0, hpa, temp, atmos);
            smooth_cells += up;
            per_cell += !up;
            worst = fmax(worst, fabs(whole[0][c] - want_az));
            worst = fmax(worst, fabs(whole[1][c] - want_e0));
            worst = fmax(worst, fabs(whole[2][c] - (want_e0 + want_refr)));
        }
    }
    /* A grid one column wide: its lattice's two columns are one. */
    static const int one_col[2] = {0, 0}, one_rows[2] = {0, 9};
    double az1[4] = {10.0, 10.0, 12.0, 12.0}, e1[4] = {5.0, 5.0, 7.0, 7.0}, r1[4];
    for (int k = 0; k < 4; ++k)
        r1[k] = ss_spa_refraction_deg(e1[k], hpa, temp, atmos);
    ss_sun_lattice l1 = {2, 2, one_col, one_rows, az1, e1, r1, hpa, temp, atmos};
    double tx1[2];
    ss_sun_lattice_tx(&l1, tx1);
    float a1, h1, p1;
    ss_sun_lattice_cells(&l1, tx1, 3, 0, 1, &a1, &h1, &p1);
    double ty1 = 3.0 / 9.0, h_want = (1 - ty1) * 5.0 + ty1 * 7.0;
    int one_ok = fabs(a1 - ((1 - ty1) * 10.0 + ty1 * 12.0)) < 1e-5 && fabs(h1 - h_want) < 1e-5 &&
                 fabs(p1 - (h_want + (1 - ty1) * r1[0] + ty1 * r1[2])) < 1e-5;
    tap_ok(same && one_ok && worst <= 2e-5 && smooth_cells > 0 && per_cell > 0,
           "a lattice's suns: runs of every start and length give the whole row's to the bit, "
           "within %.1e deg of the bilinear nodes (%d cells with refraction interpolated, %d "
           "computed per cell); a one-column grid's too",
           worst, smooth_cells, per_cell);
}

int main(void)
{
    const float elevations[] = {0.05f, 0.5f, 2.0f, 10.0f, 35.0f, 70.0f, 89.0f};
    const float spreads[] = {0.01f, 0.11f, 1.4f};
    for (size_t i = 0; i < sizeof elevations / sizeof elevations[0]; ++i)
        for (size_t j = 0; j < sizeof spreads / sizeof spreads[0]; ++j)
            check_range(elevations[i], 35.0f + 40.0f * (float)i, spreads[j], spreads[j],
                        i % 2 ? 6.5f : 2.0f);
    check_range(45.0f, -0.5f, 1.4f, 1.4f, 3.0f); /* azimuths either side of grid north */

    check_one_sun();
    check_weather();
    check_outside();
    check_bands();
    check_lattice_runs();
    return tap_done();
}
