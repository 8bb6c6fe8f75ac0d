/* A step's irradiance over a run of cells, in SIMD lanes (insolation_lanes.c).
 *
 * Per cell and step the work is the same few dozen float operations:
 * the sun's terms read from the step's tables (sun_table.h), the shadow
 * test and beam, diffuse and reflected light (insolation_cell.h). Run cell
 * by cell, its branches and table reads cost more than its arithmetic;
 * here every cell of a run computes all of it without a branch, so the
 * compiler runs eight cells side by side in AVX2's or AVX-512's vector
 * lanes where the CPU has them (chosen at run time). Each cell's values are those of the cell-by-cell
 * functions to the bit: the same operations in the same order, only
 * selected instead of branched to. A cell whose sun falls outside a table
 * (a weather record's: too far from the centre's) is left to the caller,
 * who computes it exactly (ss_step_sun_at). */
#ifndef SS_INSOLATION_LANES_H
#define SS_INSOLATION_LANES_H

#include <stddef.h>
#include <stdint.h>

#include "insolation_cell.h"
#include "insolation_internal.h"
#include "sun_table.h"

#define SS_LANE_CELLS 256 /* cells a run holds at most */

/* What a run's cell is: nothing to add, lanes' values to add, or a sun
 * outside the step's tables or too far from the centre's (computed
 * exactly by the caller). */
#define SS_LANE_SKIP 0
#define SS_LANE_ADD 1
#define SS_LANE_EXACT 2

/* One step as the lanes take it: its sun (true and apparent elevation and
 * grid azimuth, degrees) for every cell where a run has none of its own
 * (ss_lane_suns); the cells' horizons in the sun's azimuth (degrees: swept, or stored as
 * int16 hundredths in the two directions around the sun, blended by
 * stored_t), or none; the clear sky's or a weather record's light; and the
 * band's sums the cells' values are added into (month NULL: none). */
typedef struct {
    const ss_step_sun *tables;
    float h0_step_deg, az_step_deg, app_step_deg;
    const float *swept;                /* per cell, or NULL */
    const int16_t *stored0, *stored1;  /* per cell, or NULL */
    float stored_t;
    int real_sky;
    float g0, albedo, dt;              /* clear sky */
    ss_sky_record rec;                 /* weather */
    ss_sky_parts sky;
    float *beam, *diffuse, *reflected, *global, *sun_hours, *month; /* per cell */
} ss_lane_step;

/* Cell c's horizon in the sun's azimuth (degrees) as the step gives it:
 * swept, blended between the two stored directions, or none (-90). */
static inline float ss_lane_horizon(const ss_lane_step *s, size_t c)
{
    if (s->swept)
        return s->swept[c];
    if (s->stored0)
        return ss_stored_horizon_between(s->stored0[c], s->stored1[c], s->stored_t);
    return -90.0f;
}

/* What became of the run's cells: their global (Wh/m^2; 0 where a cell
 * adds nothing or is left to the caller), for the outputs that take it. */
typedef struct {
    float global[SS_LANE_CELLS];
    unsigned char what[SS_LANE_CELLS]; /* SS_LANE_* */
} ss_lane_adds;

/* A run's suns, each cell's (degrees, from the run's first cell: the
 * step's per-cell arrays, or what a lattice gave the run), or NULL where
 * the step's serves every cell. */
typedef struct {
    const float *h0_deg, *az_deg, *app_deg;
} ss_lane_suns;

/* Cells [c0, c0 + n) of the band (n <= SS_LANE_CELLS), whose heights and
 * terms are own_z and terms (indexed from 0) and whose suns are suns:
 * adds each SS_LANE_ADD cell's values into the step's sums (x + 0 is x for
 * every sum, which is never -0, so the others are added 0), and leaves the
 * SS_LANE_EXACT ones to the caller. */
void ss_lane_cells(const ss_lane_step *s, const ss_lane_suns *suns, const float *own_z,
                   const ss_cell_terms *terms, size_t c0, int n, ss_lane_adds *out);

/* The copy for any CPU, which ss_lane_cells runs where neither AVX-512's
 * nor AVX2's can. */
void ss_lane_cells_any(const ss_lane_step *s, const ss_lane_suns *suns, const float *own_z,
                       const ss_cell_terms *terms, size_t c0, int n, ss_lane_adds *out);

/* The AVX2 and AVX-512 copies, built by GCC on x86-64
 * (insolation_lanes_v3.c and insolation_lanes_v4.c, which repeat the
 * condition). */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SS_LANES_V3 1
void ss_lane_cells_v3(const ss_lane_step *s, const ss_lane_suns *suns, const float *own_z,
                      const ss_cell_terms *terms, size_t c0, int n, ss_lane_adds *out);
void ss_lane_cells_v4(const ss_lane_step *s, const ss_lane_suns *suns, const float *own_z,
                      const ss_cell_terms *terms, size_t c0, int n, ss_lane_adds *out);
/* Whether this CPU runs the AVX-512 copy. */
static inline int ss_lanes_have_v4(void)
{
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
}
#else
#define SS_LANES_V3 0
#endif

#endif
