/* What one work-item does: walk one line of one direction through a band
 * (ss_band.h) and hand each sample's horizon to a walk's term, which adds
 * it into the receiving cells with their weights. Shared by
 * kernels/sweep.cl (one work-item per line and direction of a batch) and
 * the C twin (src/core/backend_ref.c), so both run the same code. A term
 * is a few lines here; the walk and the hull are never written again.
 *
 * Interpolated lines feed two cells per sample, and adjacent lines feed the
 * same cells, so lines run in two rounds (even, then odd intercepts); lines
 * of one round never touch the same cell. */
#ifndef SS_PASSES_H
#define SS_PASSES_H

#include "ss_band.h"
#include "ss_terms.h"

/* One direction's term of an SVF definition for a receiving cell. The
 * radiative term needs the cell's surface gradient: dz/de, dz/dn per cell
 * of the band's buffers in grad (ss_gradient_grid); the others read none. */
SS_FN float ss_svf_term_for(int definition, const ss_line_set *ls, int major, int minor,
                            float d, float dz, float sin_az, float cos_az,
                            SS_GLOBAL const float *grad)
{
    if (definition == SS_SVF_GEOMETRIC)
        return ss_svf_geometric_term(d, dz);
    if (definition == SS_SVF_HORIZONTAL)
        return ss_svf_horizontal_term(d, dz);
    if (definition == SS_TERM_ELEVATION)
        return d > 0.0f ? ss_horizon_deg(d, dz) : 0.0f;
    if (minor < 0 || minor >= ls->minor_len)
        return 0.0f; /* no such cell: it receives nothing */
    int cell = ss_line_cell(ls, major, minor);
    return ss_svf_tilted_term(d, dz, sin_az, cos_az, grad[2 * cell], grad[2 * cell + 1]);
}

/* Adds one direction's SVF term to acc for the cells that steps [s_lo,
 * s_hi) of the walker's line feed. */
SS_FN void ss_svf_steps(ss_walker *w, const ss_line_set *ls, int s_lo, int s_hi, int definition,
                        float curv_k, float sin_az, float cos_az, SS_GLOBAL const float *z,
                        SS_GLOBAL const float *grad, SS_GLOBAL int *stack,
                        SS_GLOBAL float *acc, int flags)
{
    for (int i = s_lo; i < s_hi; ++i) {
        ss_sample_horizon h = ss_walker_step(w, ls, z, stack, curv_k, i, flags);
        if (!h.valid)
            continue;
        /* Only the radiative term depends on the receiving cell (its slope). */
        float term0 = ss_svf_term_for(definition, ls, h.major, h.minor0, h.d, h.dz, sin_az,
                                      cos_az, grad);
        float term1 = definition == SS_SVF_TILTED
                          ? ss_svf_term_for(definition, ls, h.major, h.minor0 + 1, h.d, h.dz,
                                            sin_az, cos_az, grad)
                          : term0;
        if (h.cell0 >= 0)
            acc[h.cell0] += h.w0 * term0;
        if (h.cell1 >= 0)
            acc[h.cell1] += h.w1 * term1;
    }
}

/* Gives a cell the distance d (> 0) of a sample with terrain ahead and, if
 * want_cast, the height of that sample's casting point. Each cell is fed
 * by at most two samples (digital lines: one), on lines of different
 * rounds, and takes the caster of the nearer one that has terrain ahead:
 * the nearer sample writes unconditionally, the farther only into a cell
 * whose distance is still 0 (the grid starts at 0), so either order of the
 * rounds gives the same result. Of a sample's two cells, cell0 is the
 * nearer when w1 <= 0.5 (a tie goes to cell0, so the neighbouring line,
 * whose cell1 it is, is the farther). */
SS_FN void ss_horizon_caster(const ss_sample_horizon *h, SS_GLOBAL float *dist_m,
                             SS_GLOBAL float *cast_z, int want_cast)
{
    int near0 = h->w1 <= 0.5f;
    if (h->cell0 >= 0 && (near0 || dist_m[h->cell0] == 0.0f)) {
        dist_m[h->cell0] = h->d;
        if (want_cast)
            cast_z[h->cell0] = h->zc;
    }
    if (h->cell1 >= 0 && (!near0 || dist_m[h->cell1] == 0.0f)) {
        dist_m[h->cell1] = h->d;
        if (want_cast)
            cast_z[h->cell1] = h->zc;
    }
}

/* Adds, for the samples that have terrain ahead, the weighted horizon
 * angle (degrees) into angle_deg and the weight into weight; samples with
 * nothing ahead add nothing, so that a cell beside the grid's edge or a
 * hole, fed by one sample with terrain ahead and one without, is not
 * dragged toward -90 by the empty one (ss_pass_horizon_finish divides).
 * With SS_HORIZON_WANT_DIST in want, gives each cell the distance
 * (metres) of its nearer sample with terrain ahead, 0 where none has, and
 * with SS_HORIZON_WANT_CAST too the height of that sample's casting point
 * (relative to the grid origin). All grids start at 0; cells without a
 * height, or without a caster, are set to nodata afterwards by the host.
 * Steps [s_lo, s_hi) of the walker's line (a band's share of it). */
SS_FN void ss_horizon_steps(ss_walker *w, const ss_line_set *ls, int s_lo, int s_hi,
                            float curv_k, SS_GLOBAL const float *z, SS_GLOBAL int *stack,
                            SS_GLOBAL float *angle_deg, SS_GLOBAL float *weight,
                            SS_GLOBAL float *dist_m, SS_GLOBAL float *cast_z, int want, int flags)
{
    for (int i = s_lo; i < s_hi; ++i) {
        ss_sample_horizon h = ss_walker_step(w, ls, z, stack, curv_k, i, flags);
        if (!h.valid || !(h.d > 0.0f))
            continue;
        float angle = ss_horizon_deg(h.d, h.dz);
        if (h.cell0 >= 0) {
            angle_deg[h.cell0] += h.w0 * angle;
            weight[h.cell0] += h.w0;
        }
        if (h.cell1 >= 0) {
            angle_deg[h.cell1] += h.w1 * angle;
            weight[h.cell1] += h.w1;
        }
        if (want & SS_HORIZON_WANT_DIST)
            ss_horizon_caster(&h, dist_m, cast_z, want & SS_HORIZON_WANT_CAST);
    }
}

/* Turns a cell's sums into its horizon: the weighted mean over the samples
 * that have terrain ahead, or none_deg (-90 for horizon products; shadows
 * take the horizontal, 0) where none has. Weights are exact (16 fractional
 * bits) and sum to exactly 1 where both samples have terrain ahead, so
 * there the division changes nothing. */
SS_FN void ss_pass_horizon_finish(int cell, float none_deg, SS_GLOBAL float *angle_deg,
                                  SS_GLOBAL const float *weight)
{
    float w = weight[cell];
    angle_deg[cell] = w > 0.0f ? angle_deg[cell] / w : none_deg;
}

/* Adds, for the cells that steps [s_lo, s_hi) of the line feed, a term
 * (SS_TERM_ELEVATION, SS_SVF_GEOMETRIC or SS_SVF_HORIZONTAL) of the horizon
 * within radius_m only: the highest terrain ahead no farther than
 * radius_m, nothing where none lies within it. The classical
 * radius-limited horizon of openness (Yokoyama et al. 2002) and of RVT's
 * sky-view factor: a plain scan back along the line, O(samples x radius);
 * no hull, so a band needs the rows within radius_m held, not a hull. */
SS_FN void ss_radius_steps(const ss_walker *w, const ss_line_set *ls, int s_lo, int s_hi,
                           int definition, float radius_m, float curv_k,
                           SS_GLOBAL const float *z, SS_GLOBAL float *acc, int flags)
{
    for (int s = s_lo; s < s_hi; ++s) {
        float zv, offv;
        ss_line_sample qv = ss_walker_sample(ls, w, s);
        ss_sample_horizon h = ss_sample_cells(ls, qv, z, &zv, &offv);
        if (!h.valid)
            continue;
        ss_hull_point v = ss_hull_point_at(w, s, qv, zv, offv);
        float best_d = 0.0f, best_dz = -1.0f;
        for (int t = s - 1; t >= 0; --t) {
            float zt, offt;
            ss_line_sample qt = ss_walker_sample(ls, w, t);
            ss_sample_horizon ht = ss_sample_cells(ls, qt, z, &zt, &offt);
            ss_hull_point p = ss_hull_point_at(w, t, qt, zt, offt);
            float d = ss_hull_dist(ls, v, p, flags);
            if (d > radius_m)
                break;
            if (!ht.occludes)
                continue;
            float dz = ss_hull_height_above(v, p, flags) - curv_k * d * d;
            if (best_d == 0.0f || dz * best_d > best_dz * d) {
                best_d = d;
                best_dz = dz;
            }
        }
        /* Radius terms are never radiative: no gradient is read. */
        float term = ss_svf_term_for(definition, ls, 0, 0, best_d, best_dz, 0.0f, 0.0f, z);
        if (h.cell0 >= 0)
            acc[h.cell0] += h.w0 * term;
        if (h.cell1 >= 0)
            acc[h.cell1] += h.w1 * term;
    }
}

/* The bare pass: the same samples read and their cells written, no hull.
 * The yardstick of the sweep's cost (DESIGN.md, speed) and, with z = 1, a
 * count of the weight each cell receives. */
SS_FN void ss_bare_steps(const ss_walker *w, const ss_line_set *ls, int s_lo, int s_hi,
                         SS_GLOBAL const float *z, SS_GLOBAL float *out)
{
    for (int s = s_lo; s < s_hi; ++s) {
        float base, offset;
        ss_sample_horizon h = ss_sample_cells(ls, ss_walker_sample(ls, w, s), z, &base, &offset);
        if (!h.valid)
            continue;
        float v = base + offset;
        if (h.cell0 >= 0)
            out[h.cell0] += h.w0 * v;
        if (h.cell1 >= 0)
            out[h.cell1] += h.w1 * v;
    }
}

/* ---- one work-item: a line of a direction in a band --------------------- */

/* A summed term (SS_SVF_* or SS_TERM_ELEVATION) of a line's band steps
 * into acc, walked by a copy of the walk compiled for the line's flags
 * (SS_WALK_DIGITAL, SS_WALK_CURVED), so that each does only what it needs. */
SS_FN void ss_band_sum_line(const ss_band_dir *d, const ss_band_run *run, int line,
                            SS_GLOBAL const float *z, SS_GLOBAL const float *grad,
                            SS_GLOBAL int *stack, SS_GLOBAL float *acc, ss_band_hulls hulls)
{
    ss_walker w;
    int s_lo, s_hi, count;
    if (!ss_band_line_begin(&w, d, run, line, hulls, &s_lo, &s_hi, &count))
        return;
    const ss_line_set *ls = &d->ls;
    float k = run->curv_k, sa = d->sin_az, ca = d->cos_az;
    switch (ss_walk_flags(ls, k)) {
    case 0:
        ss_svf_steps(&w, ls, s_lo, s_hi, run->term, k, sa, ca, z, grad, stack, acc, 0);
        break;
    case SS_WALK_DIGITAL:
        ss_svf_steps(&w, ls, s_lo, s_hi, run->term, k, sa, ca, z, grad, stack, acc,
                     SS_WALK_DIGITAL);
        break;
    case SS_WALK_CURVED:
        ss_svf_steps(&w, ls, s_lo, s_hi, run->term, k, sa, ca, z, grad, stack, acc,
                     SS_WALK_CURVED);
        break;
    default:
        ss_svf_steps(&w, ls, s_lo, s_hi, run->term, k, sa, ca, z, grad, stack, acc,
                     SS_WALK_DIGITAL | SS_WALK_CURVED);
    }
    ss_band_line_end(&w, d, run, line, s_hi, count, hulls.state, hulls.counters);
}

/* Output plane p of a horizon walk's direction in batch slot `slot`
 * (angle sums, weights, distances, casting heights: ss_horizon_steps). */
SS_FN SS_GLOBAL float *ss_band_plane(SS_GLOBAL float *outs, const ss_band_run *run, int slot,
                                     int p)
{
    return outs + (ss_i64)(slot * run->planes + p) * run->held_rows * run->width;
}

/* A horizon walk of a line's band steps into its direction's planes
 * (written once per direction: one general copy of the walk). */
SS_FN void ss_band_horizon_line(const ss_band_dir *d, const ss_band_run *run, int line,
                                SS_GLOBAL const float *z, SS_GLOBAL int *stack,
                                SS_GLOBAL float *outs, ss_band_hulls hulls)
{
    ss_walker w;
    int s_lo, s_hi, count;
    if (!ss_band_line_begin(&w, d, run, line, hulls, &s_lo, &s_hi, &count))
        return;
    /* Planes not asked for are never written: the angle plane stands in. */
    SS_GLOBAL float *angle = ss_band_plane(outs, run, d->slot, 0);
    SS_GLOBAL float *weight = ss_band_plane(outs, run, d->slot, 1);
    SS_GLOBAL float *dist = run->planes > 2 ? ss_band_plane(outs, run, d->slot, 2) : angle;
    SS_GLOBAL float *cast = run->planes > 3 ? ss_band_plane(outs, run, d->slot, 3) : angle;
    ss_horizon_steps(&w, &d->ls, s_lo, s_hi, run->curv_k, z, stack, angle, weight, dist, cast,
                     run->want, ss_walk_flags(&d->ls, run->curv_k));
    ss_band_line_end(&w, d, run, line, s_hi, count, hulls.state, hulls.counters);
}

/* A radius-limited term of a line's band steps into acc: no hull, the
 * band holds every row within the radius. */
SS_FN void ss_band_radius_line(const ss_band_dir *d, const ss_band_run *run, int line,
                               SS_GLOBAL const float *z, SS_GLOBAL float *acc)
{
    ss_walker w;
    int count = ss_walker_begin(&w, &d->ls, line), s_lo = 0, s_hi = count;
    if (!run->whole) {
        int pass = d->pass, h = run->height;
        s_lo = ss_band_first_step_past(&d->ls, &w, count, pass > 0 ? run->row0 : run->row1 - 1,
                                       pass, h);
        s_hi = ss_band_first_step_past(&d->ls, &w, count, pass > 0 ? run->row1 : run->row0 - 1,
                                       pass, h);
    }
    ss_radius_steps(&w, &d->ls, s_lo, s_hi, run->term, run->radius_m, run->curv_k, z, acc,
                    ss_walk_flags(&d->ls, run->curv_k));
}

/* Lines of one round: all lines for digital lines, else every other one
 * (interpolated lines feed two cells per sample and neighbouring lines the
 * same cells, so lines of one round never touch the same cell). */
SS_FN int ss_round_lines(const ss_line_set *ls, int round)
{
    return ls->model == SS_LINE_MODEL_DIGITAL ? (round == 0 ? ls->n_lines : 0)
                                         : (ls->n_lines - round + 1) / 2;
}

SS_FN int ss_round_line(const ss_line_set *ls, int round, int index)
{
    return ls->model == SS_LINE_MODEL_DIGITAL ? index : 2 * index + round;
}

#endif
