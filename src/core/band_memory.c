/* What a run in bands holds, so that callers can size bands to a memory
 * budget (the CLI's --memory, doc/scale.md). */
#include "config.h"

#include "ctx_internal.h"
#include "engine.h"
#include "insolation_cell.h"
#include "lit_levels.h"
#include "ss_passes.h"

#define HALO SS_BAND_HALO

size_t ss_band_bytes(int width, int band_rows)
{
    return (size_t)(band_rows + 2 * HALO) * (size_t)width * (2 * sizeof(float) + sizeof(int));
}

double ss_sky_band_cell_bytes(ss_sky_term term)
{
    /* Heights, stack slots and sums; the radiative SVF's gradients. */
    return (double)(ss_band_bytes(1, 1) / (1 + 2 * HALO)) +
           (term == SS_SKY_SVF_RADIATIVE ? 2.0 * sizeof(float) : 0.0);
}

double ss_horizon_band_cell_bytes(int want)
{
    /* Heights, stack slots, weighted angles and weights; distances, which
     * casting heights need too; casting heights. */
    int want_cast = (want & SS_HORIZON_CAST_HEIGHT) != 0;
    int grids = 4 + (want_cast || (want & SS_HORIZON_DISTANCE)) + want_cast;
    return 4.0 * grids;
}

double ss_lines_extra_cell_bytes(ss_line_model lines)
{
    /* Box lines keep up to SS_BOX_EVENTS hull slots per home cell. */
    return lines == SS_LINES_BOX ? (SS_BOX_EVENTS - 1) * sizeof(int) : 0.0;
}

_Static_assert(SS_RADIUS_SLOTS * sizeof(int) == sizeof(ss_hull_point),
               "a radius walk's stack slots of a cell hold one hull point");

double ss_radius_extra_cell_bytes(double radius_m, double cell_x_m, double cell_y_m)
{
    /* Cell sizes not known yet (a geographic grid before its frame): the
     * hulls are counted. */
    int known = isfinite(cell_x_m) && isfinite(cell_y_m);
    int hulls = !(radius_m <= 0) && (!known || ss_radius_takes_hulls((float)radius_m,
                                                                     (float)cell_x_m,
                                                                     (float)cell_y_m));
    return hulls ? (SS_RADIUS_SLOTS - 1) * sizeof(int) : 0.0;
}

double ss_horizon_column_bytes(void)
{
    return 4 * sizeof(float); /* a row each of the four sums carried between bands */
}

double ss_insolation_band_cell_bytes(int want, int stored_directions)
{
    /* Heights (with a halo row) 4, the sky view and the share of Perez's
     * band 8, the cells' terms, the suns per cell (true and apparent
     * elevation, azimuth) 12, and per output plane its sums and the sums
     * earlier visits left 8: five planes, twelve months, PV's DC and AC;
     * a step's global; the stored horizons; exact shadows' bounds, a byte
     * a sector (lit_levels.h), counted whether or not a run makes them. Measured: 121 bytes a cell
     * with the sweep's 16 for a clear sky's exact shadows on a 2048^2 DEM
     * (peak resident, doc/scale.md), against 112 counted here. */
    int planes = 5 + (want & SS_INSOLATION_MONTHLY ? 12 : 0) + (want & SS_INSOLATION_PV ? 2 : 0);
    return 4.0 + 8.0 + (double)sizeof(ss_cell_terms) + 12.0 + 8.0 * planes +
           (want & SS_INSOLATION_STEPS ? 4.0 : 0.0) + 2.0 * stored_directions + SS_LIT_SECTORS;
}

double ss_insolation_grid_cell_bytes(void)
{
    return 3.0 * SS_LIT_SECTORS / (double)(1 << (2 * SS_LIT_BLOCK_SHIFT));
}

/* Without a measured process: 16 MiB stand for the program and 16 for
 * GDAL's cache, which with the run's own 16 make the 48 MiB of fixed
 * buffers these sizes have always counted. */
static ss_memory_need need_without_process(int width, int height, int directions,
                                           double budget_bytes, double band_cell_bytes,
                                           double column_bytes)
{
    ss_memory_need n = {.budget_bytes = budget_bytes,
                        .baseline_bytes = 16.0 * 1048576.0,
                        .width = width,
                        .height = height,
                        .cell_bytes = band_cell_bytes,
                        .column_bytes = column_bytes,
                        .hull_lines = directions > 0 ? directions : 64,
                        .cache_bytes = 16.0 * 1048576.0};
    return n;
}

double ss_whole_sweep_bytes(int width, int height)
{
    ss_memory_need n = need_without_process(width, height, 0, 0.0, 0.0, 0.0);
    return ss_memory_planned(NULL, &n, height);
}

int ss_band_rows_for(int width, int height, int directions, double budget_bytes)
{
    return ss_band_rows_within(width, height, directions, budget_bytes,
                               (double)ss_band_bytes(1, 1) / (1 + 2 * HALO), 0.0);
}

int ss_band_rows_within(int width, int height, int directions, double budget_bytes,
                        double band_cell_bytes, double column_bytes)
{
    ss_memory_need n = need_without_process(width, height, directions, budget_bytes,
                                            band_cell_bytes, column_bytes);
    return ss_memory_plan_rows(NULL, &n, NULL);
}

double ss_band_min_budget(int width, int height, int directions, double band_cell_bytes,
                          double column_bytes)
{
    ss_memory_need n = need_without_process(width, height, directions, 0.0, band_cell_bytes,
                                            column_bytes);
    ss_memory_plan p;
    ss_memory_plan_rows(NULL, &n, &p);
    return p.least_budget;
}
