/* OpenCL entry points of the one sweep driver: one work-item per line of
 * one round of every direction of a batch, over one band of rows
 * (ss_band.h), then per-cell work on the band's buffers. The work itself is
 * in ss_passes.h, which the C twin runs too. Buffers per batch slot (a
 * direction of the batch) lie one band's held cells apart. */
#include "ss_insolation_cells.h"
#include "ss_passes.h"

/* The direction slot and round index of work-item gid, and its line
 * (-1: none, its direction has fewer lines in this round). */
inline int batch_line(const ss_band_run *run, __global const ss_band_dir *dirs, int round,
                      ss_band_dir *d)
{
    int gid = get_global_id(0), slot = gid / run->lines, i = gid - slot * run->lines;
    if (slot >= run->slots)
        return -1; /* the work-items that round the range up to whole groups */
    *d = dirs[slot];
    return i < ss_round_lines(&d->ls, round) ? ss_round_line(&d->ls, round, i) : -1;
}

inline size_t held_cells(const ss_band_run *run)
{
    return (size_t)run->held_rows * (size_t)run->width;
}

/* Where a batch slot's stack grid starts. */
inline size_t stack_at(const ss_band_run *run, int slot)
{
    return (size_t)slot * held_cells(run) * (size_t)run->stack_per_cell;
}

/* Summed terms: each slot adds into its own sums, added to the band's in
 * direction order afterwards (band_reduce). */
__kernel void band_sum(__global const ss_band_dir *dirs, ss_band_run run, int round,
                       __global const float *z, __global const float *grad,
                       __global int *stacks, __global float *sums,
                       __global const ss_hull_point *hull_in, __global const int *in_off,
                       __global const int *in_cnt, __global int *state, __global int *counters)
{
    ss_band_dir d;
    int line = batch_line(&run, dirs, round, &d);
    if (line < 0)
        return;
    ss_band_hulls hulls = {hull_in, in_off, in_cnt, state, counters};
    size_t at = (size_t)d.slot * held_cells(&run);
    ss_band_sum_line(&d, &run, line, z, grad, stacks + stack_at(&run, d.slot), sums + at, hulls);
}

__kernel void band_horizon(__global const ss_band_dir *dirs, ss_band_run run, int round,
                           __global const float *z, __global int *stacks, __global float *outs,
                           __global const ss_hull_point *hull_in, __global const int *in_off,
                           __global const int *in_cnt, __global int *state,
                           __global int *counters, __global const unsigned char *lit_levels)
{
    ss_band_dir d;
    int line = batch_line(&run, dirs, round, &d);
    if (line < 0)
        return;
    ss_band_hulls hulls = {hull_in, in_off, in_cnt, state, counters};
    ss_band_horizon_line(&d, &run, line, z, stacks + stack_at(&run, d.slot), outs, hulls,
                         lit_levels);
}

/* Each line of a round hands its hull on (ss_band_hand_on), after the
 * round's walks and before the next round's. */
__kernel void band_hand_on(__global const ss_band_dir *dirs, ss_band_run run, int round,
                           __global const float *z, __global const int *stacks,
                           __global const ss_hull_point *hull_in, __global const int *in_off,
                           __global const int *state, __global ss_hull_point *hull_out,
                           __global int *out_off, __global int *out_cnt,
                           __global int *counters)
{
    ss_band_dir d;
    int line = batch_line(&run, dirs, round, &d);
    if (line >= 0)
        ss_band_hand_on(&d, line, z, stacks + stack_at(&run, d.slot), hull_in,
                        in_off, state, hull_out, out_off, out_cnt, counters);
}

__kernel void band_radius(__global const ss_band_dir *dirs, ss_band_run run, int round,
                          __global const float *z, __global int *stacks, __global float *sums)
{
    ss_band_dir d;
    int line = batch_line(&run, dirs, round, &d);
    if (line < 0)
        return;
    ss_band_radius_line(&d, &run, line, z, stacks + stack_at(&run, d.slot),
                        sums + (size_t)d.slot * held_cells(&run));
}

__kernel void band_bare(__global const ss_band_dir *dirs, ss_band_run run, int round,
                        __global const float *z, __global float *out)
{
    ss_band_dir d;
    int line = batch_line(&run, dirs, round, &d);
    if (line < 0)
        return;
    ss_walker w;
    int n = ss_walker_begin(&w, &d.ls, line);
    ss_bare_steps(&w, &d.ls, 0, n, z, out);
}

/* The band's sums += each slot's, one after the other in direction order,
 * so that the sums do not depend on how the directions were batched: one
 * work-item per held cell. */
__kernel void band_reduce(ss_band_run run, int n_slots, __global const float *parts,
                          __global float *sums)
{
    size_t cell = get_global_id(0), cells = held_cells(&run);
    if (cell >= cells)
        return;
    float s = sums[cell];
    for (int k = 0; k < n_slots; ++k)
        s += parts[(size_t)k * cells + cell];
    sums[cell] = s;
}

/* Rows of sums carried between bands, planes x width per direction: into
 * the landing row (into = 1), or out of the fed row. A horizon walk's slot
 * keeps its direction's rows (dirs[slot].carry); summed walks keep one.
 * One work-item per slot, plane and column. */
__kernel void band_carry(ss_band_run run, int pass, int n_slots, int planes, int into,
                         int per_direction, __global const ss_band_dir *dirs,
                         __global float *outs, __global float *carry)
{
    int gid = get_global_id(0), w = run.width;
    if (gid >= n_slots * planes * w)
        return;
    int col = gid % w, p = (gid / w) % planes, slot = gid / (w * planes);
    int row = into ? ss_band_landing_row(&run, pass) : ss_band_fed_row(&run, pass);
    if (row < 0)
        return;
    int kept_at = per_direction ? dirs[slot].carry : 0;
    __global float *plane = outs + (size_t)(slot * planes + p) * held_cells(&run);
    __global float *kept = carry + ((size_t)kept_at * planes + p) * w;
    if (into)
        plane[(size_t)row * w + col] = kept[col];
    else
        kept[col] = plane[(size_t)row * w + col];
}

/* Each slot's horizon angles over its own rows: the weighted mean, or
 * none_deg (ss_pass_horizon_finish). One work-item per slot and cell. */
__kernel void band_finish(ss_band_run run, int n_slots, __global float *outs)
{
    size_t gid = get_global_id(0);
    size_t own = (size_t)(run.row1 - run.row0) * run.width;
    if (gid >= (size_t)n_slots * own)
        return;
    int slot = (int)(gid / own);
    size_t first = (size_t)(run.row0 - run.lo) * run.width;
    int cell = (int)(first + gid - (size_t)slot * own);
    ss_pass_horizon_finish(cell, run.none_deg, ss_band_plane(outs, &run, slot, 0),
                           ss_band_plane(outs, &run, slot, 1));
}

/* One insolation step over the band's own cells (ss_cells_step_at): the
 * horizons of batch slot `slot` where the step walked, the cells' terms
 * (ss_cell_terms, own cells), the lattice's columns then rows and its
 * three node arrays then the air (pressure, temperature, refraction at
 * sunset), the band's planes, the stored horizons of interpolated shadows
 * (own cells, a plane per stored direction) and the step's own global
 * (own cells). One work-item per own cell. */
__kernel void insolation_cells(ss_band_run run, ss_cells_step step, int slot,
                               __global const float *z, __global float *outs,
                               __global const ss_cell_terms *terms,
                               __global const int *lattice_at,
                               __global const ss_real *lattice_nodes, __global float *planes,
                               __global const short *stored, __global float *step_out)
{
    int c = get_global_id(0);
    if (c >= step.cells)
        return;
    int nodes = step.lattice_cols * step.lattice_rows;
    ss_lattice_view l = {step.lattice_cols,
                         step.lattice_rows,
                         lattice_at,
                         lattice_at + step.lattice_cols,
                         lattice_nodes,
                         lattice_nodes + nodes,
                         lattice_nodes + 2 * nodes,
                         lattice_nodes[3 * nodes],
                         lattice_nodes[3 * nodes + 1],
                         lattice_nodes[3 * nodes + 2]};
    size_t first = (size_t)(run.row0 - run.lo) * run.width;
    __global const float *walked =
        step.horizon == SS_CELLS_WALKED ? ss_band_plane(outs, &run, slot, 0) + first : outs;
    float horizon = ss_cells_horizon(&step, c, walked, stored);
    ss_cell_terms t = terms[c];
    ss_cells_step_at(&step, &l, c, z[first + c], horizon, &t, planes, step_out);
}
