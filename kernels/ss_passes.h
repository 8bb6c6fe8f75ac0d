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
    if (definition != SS_SVF_TILTED)
        return ss_sky_walk_term(definition, d, dz, sin_az, cos_az, 0.0f, 0.0f);
    if (minor < 0 || minor >= ls->minor_len)
        return 0.0f; /* no such cell: it receives nothing */
    int cell = ss_line_cell(ls, major, minor);
    return ss_sky_walk_term(definition, d, dz, sin_az, cos_az, grad[2 * cell], grad[2 * cell + 1]);
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
        if (!h.valid || (h.cell0 < 0 && h.cell1 < 0)) /* box lines: not this line's cell */
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
 * Steps [s_lo, s_hi) of the walker's line (a band's share of it).
 *
 * A shadow walk (lit_level >= 0, ss_band_horizon_line) gives no horizon
 * to cells whose bound level is at most lit_level: the sun clears every
 * horizon they could have, and the horizon they get instead, from one of
 * their samples or none (none_deg, the horizontal, below a sun of level 0
 * or more), stays below their bound too. Their samples still join the
 * hull, for the cells after them. */
SS_FN void ss_horizon_steps(ss_walker *w, const ss_line_set *ls, int s_lo, int s_hi,
                            float curv_k, SS_GLOBAL const float *z, SS_GLOBAL int *stack,
                            SS_GLOBAL float *angle_deg, SS_GLOBAL float *weight,
                            SS_GLOBAL float *dist_m, SS_GLOBAL float *cast_z, int want, int flags,
                            SS_GLOBAL const unsigned char *levels, int lit_level)
{
    for (int i = s_lo; i < s_hi; ++i) {
        ss_sample_horizon h = ss_walker_step(w, ls, z, stack, curv_k, i, flags);
        if (!h.valid || !(h.d > 0.0f) || (h.cell0 < 0 && h.cell1 < 0))
            continue;
        if (lit_level >= 0 && (h.cell0 < 0 || levels[h.cell0] <= lit_level) &&
            (h.cell1 < 0 || levels[h.cell1] <= lit_level))
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

/* ---- horizons within a radius ------------------------------------------- */

/* Windows of up to this many steps are scanned, longer ones use hulls. */
#define SS_RADIUS_SCAN_STEPS 20

/* Radius-limited horizons (SS_TERM_ELEVATION, SS_SVF_GEOMETRIC or
 * SS_SVF_HORIZONTAL within radius_m): the highest terrain ahead no farther
 * than radius_m, nothing where none lies within it. The classical horizon
 * of openness (Yokoyama et al. 2002) and of RVT's sky-view factor.
 *
 * Scanning back over every sample within the radius costs O(samples x
 * radius). Instead each sample's window (the samples within the radius
 * ahead of it) is split in two at a chunk boundary: the window's
 * farther part is a suffix of the previous chunk, its nearer part a prefix
 * of the sample's own chunk, and the horizon is the better of the two
 * parts' tangents (a maximum splits over any partition). Chunks end where
 * the window start passes the chunk's start, so windows never span more
 * than two. A chunk's prefix hull grows as the sweep's does (pops are
 * final: a popped vertex lies under the chord to a nearer one, which every
 * later window of the chunk holds too); the previous chunk's suffix hulls
 * are built backward, for the chunk's samples taken backward, and queried
 * by bisection. Each sample is pushed and popped at most once per hull,
 * so a line costs O(samples x log(hull)), whatever the radius. Short
 * windows are scanned instead (ss_radius_scan): on the Kilauea sample the
 * scan costs less up to about 20 steps (doc/relief.md).
 *
 * Hulls are kept as whole points in the stack grid (the engine gives a
 * radius walk SS_RADIUS_SLOTS int slots a cell, so that a bisection reads
 * a vertex instead of recomputing its sample), at the home cells of the
 * chunk's own samples (ss_sweep.h's scheme): the suffix hull of chunk
 * [a, b] at the homes of a, a + 1, ...; the suffix tangent found for
 * sample q at q's home, until the prefix hull overwrites it after q was
 * walked. Only the held rows within the radius are read, so a band needs
 * those rows held, not a hull handed on. */

/* Stack grid slots (ints) a radius walk with hulls takes per held cell: a
 * hull point. */
#define SS_RADIUS_SLOTS 4
/* The u of the point kept for a sample whose window's farther part holds
 * no vertex (no point's u, a step count, comes near it). */
#define SS_RADIUS_NONE 3.0e38f

/* Whether a walk within radius_m takes the hulls in some direction, and so
 * needs SS_RADIUS_SLOTS stack slots a held cell: a line steps at least the
 * smaller cell size, so shorter radii are scanned in every direction
 * (ss_band_radius_line) and read no stack. */
SS_FN int ss_radius_takes_hulls(float radius_m, float cell_x_m, float cell_y_m)
{
    return radius_m > SS_RADIUS_SCAN_STEPS * SS_FMIN(cell_x_m, cell_y_m);
}

/* The hull point of the sample at step t of the walker's line. */
SS_FN ss_hull_point ss_radius_point(const ss_line_set *ls, const ss_walker *w,
                                    SS_GLOBAL const float *z, int t, ss_sample_horizon *h)
{
    float base, offset;
    ss_line_sample q = ss_walker_sample(ls, w, t);
    *h = ss_sample_cells(ls, q, z, &base, &offset);
    return ss_hull_point_at(w, t, q, base, offset);
}

/* Distance from step t back to step s's sample: positions only. */
SS_FN float ss_radius_dist(const ss_line_set *ls, const ss_walker *w, int s, int t, int flags)
{
    ss_hull_point v = ss_hull_point_at(w, s, ss_walker_sample(ls, w, s), 0.0f, 0.0f);
    ss_hull_point p = ss_hull_point_at(w, t, ss_walker_sample(ls, w, t), 0.0f, 0.0f);
    return ss_hull_dist(ls, v, p, flags);
}

/* The stack grid cell where step t keeps a hull slot: its home. */
SS_FN int ss_radius_home(const ss_line_set *ls, const ss_walker *w, int t)
{
    return ss_walker_sample(ls, w, t).home;
}

/* The hull point kept at the home of step t. */
SS_FN ss_hull_point ss_radius_vertex(const ss_line_set *ls, const ss_walker *w,
                                     SS_GLOBAL const ss_hull_point *pts, int t)
{
    return pts[ss_radius_home(ls, w, t)];
}

/* Whether, seen from v, hull point a rises at least as steeply as b (the
 * sweep's comparison, bent heights over distance). */
SS_FN int ss_radius_not_below(const ss_line_set *ls, ss_hull_point v, ss_hull_point a,
                              ss_hull_point b, float curv_k, int flags)
{
    float da = ss_hull_dist(ls, v, a, flags), db = ss_hull_dist(ls, v, b, flags);
    return ss_hull_rise(ls, v, a, da, curv_k, flags) * db >=
           ss_hull_rise(ls, v, b, db, curv_k, flags) * da;
}

/* The hull vertex that the tangent from v touches, of n > 0 vertices
 * ordered from the nearest (i = 0) to the farthest, vertex i kept at the
 * home of step base + sign * i. Slopes from v rise along a convex hull to
 * the tangent vertex, then fall: bisection finds it, the nearer of equal
 * ones. */
SS_FN ss_hull_point ss_radius_tangent(const ss_line_set *ls, const ss_walker *w,
                                      SS_GLOBAL const ss_hull_point *pts, int base, int sign,
                                      int n, ss_hull_point v, float curv_k, int flags)
{
    int lo = 0, hi = n - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        ss_hull_point p0 = ss_radius_vertex(ls, w, pts, base + sign * mid);
        ss_hull_point p1 = ss_radius_vertex(ls, w, pts, base + sign * (mid + 1));
        if (ss_radius_not_below(ls, v, p0, p1, curv_k, flags))
            hi = mid;
        else
            lo = mid + 1;
    }
    return ss_radius_vertex(ls, w, pts, base + sign * lo);
}

/* A hull of points kept at the homes of steps base, base + 1, ... (slot 0
 * the first pushed), its top vertex also held. */
typedef struct {
    int base, n;
    ss_hull_point top;
} ss_radius_hull;

/* The vertex below the top. */
SS_FN ss_hull_point ss_radius_second(const ss_line_set *ls, const ss_walker *w,
                                     SS_GLOBAL const ss_hull_point *pts,
                                     const ss_radius_hull *hull)
{
    return ss_radius_vertex(ls, w, pts, hull->base + hull->n - 2);
}

SS_FN void ss_radius_push(const ss_line_set *ls, const ss_walker *w, SS_GLOBAL ss_hull_point *pts,
                          ss_radius_hull *hull, ss_hull_point p)
{
    pts[ss_radius_home(ls, w, hull->base + hull->n++)] = p;
    hull->top = p;
}

/* Pushes p, which lies before every vertex, on a hull that grows backward:
 * the vertices on or under the chord from p to the vertex after them (seen
 * from that vertex) are popped first. */
SS_FN void ss_radius_push_before(const ss_line_set *ls, const ss_walker *w,
                                 SS_GLOBAL ss_hull_point *pts, ss_radius_hull *hull,
                                 ss_hull_point p, float curv_k, int flags)
{
    while (hull->n >= 2) {
        ss_hull_point second = ss_radius_second(ls, w, pts, hull);
        if (!ss_radius_not_below(ls, second, p, hull->top, curv_k, flags))
            break;
        hull->top = second;
        hull->n--;
    }
    ss_radius_push(ls, w, pts, hull, p);
}

/* The tangent from v (after every vertex) to a hull that grows forward, in
 * *touch; returns 0 for an empty hull. An occluding v is pushed, the
 * vertices under its chord popped on the way, as the sweep does: the
 * tangent is then the top left. */
SS_FN int ss_radius_tangent_after(const ss_line_set *ls, const ss_walker *w,
                                  SS_GLOBAL ss_hull_point *pts, ss_radius_hull *hull,
                                  ss_hull_point v, int occludes, float curv_k, int flags,
                                  ss_hull_point *touch)
{
    int found = hull->n > 0;
    if (found && !occludes) {
        *touch = ss_radius_tangent(ls, w, pts, hull->base + hull->n - 1, -1, hull->n, v, curv_k,
                                   flags);
    } else if (found) {
        while (hull->n >= 2) {
            ss_hull_point second = ss_radius_second(ls, w, pts, hull);
            if (!ss_radius_not_below(ls, v, second, hull->top, curv_k, flags))
                break;
            hull->top = second;
            hull->n--;
        }
        *touch = hull->top;
    }
    if (occludes)
        ss_radius_push(ls, w, pts, hull, v);
    return found;
}

/* Adds the radius-limited term of steps [s_lo, s_hi) of the walker's line
 * to the cells they feed; steps before s_lo within the radius are read too
 * (in a band: the rows held above it). */
SS_FN void ss_radius_hulls(const ss_walker *w, const ss_line_set *ls, int s_lo, int s_hi,
                           int definition, float radius_m, float curv_k,
                           SS_GLOBAL const float *z, SS_GLOBAL ss_hull_point *pts,
                           SS_GLOBAL float *acc, int flags)
{
    /* The first window's start: the distance back grows with the steps. */
    int a = 0, hi = s_lo;
    while (a < hi) {
        int mid = (a + hi) / 2;
        if (ss_radius_dist(ls, w, s_lo, mid, flags) <= radius_m)
            hi = mid;
        else
            a = mid + 1;
    }
    ss_sample_horizon h, ht;
    /* Chunk [a, s - 1] serves the samples [s, e) as their windows' farther part. */
    for (int s = s_lo; s < s_hi;) {
        int e = s + 1;
        while (e < s_hi && ss_radius_dist(ls, w, e, s, flags) <= radius_m)
            e++;
        /* Backward: the chunk's suffix hull grows to each sample's window;
         * its tangent waits at the sample's home. */
        ss_radius_hull far = {a, 0, {0.0f, 0.0f, 0.0f, 0.0f}};
        int lo = s;
        for (int q = e - 1; q >= s; --q) {
            while (lo > a && ss_radius_dist(ls, w, q, lo - 1, flags) <= radius_m) {
                lo--;
                ss_hull_point p = ss_radius_point(ls, w, z, lo, &ht);
                if (ht.occludes)
                    ss_radius_push_before(ls, w, pts, &far, p, curv_k, flags);
            }
            ss_hull_point v = ss_radius_point(ls, w, z, q, &h);
            ss_hull_point none = {SS_RADIUS_NONE, 0.0f, 0.0f, 0.0f};
            if (h.valid)
                pts[ss_radius_home(ls, w, q)] =
                    far.n > 0 ? ss_radius_tangent(ls, w, pts, a, 1, far.n, v, curv_k, flags)
                              : none;
        }
        /* Forward: the nearer part from the chunk's own prefix hull, which
         * overwrites only homes of samples already walked. */
        ss_radius_hull near = {s, 0, {0.0f, 0.0f, 0.0f, 0.0f}};
        for (int q = s; q < e; ++q) {
            ss_hull_point v = ss_radius_point(ls, w, z, q, &h), pn = {0.0f, 0.0f, 0.0f, 0.0f};
            if (!h.valid)
                continue;
            /* The farther part's tangent, read before the prefix hull may
             * take q's home; then the nearer part's, if it rises higher. */
            ss_hull_point best = ss_radius_vertex(ls, w, pts, q);
            int have_best = best.u != SS_RADIUS_NONE;
            if (ss_radius_tangent_after(ls, w, pts, &near, v, h.occludes, curv_k, flags, &pn) &&
                (!have_best || ss_radius_not_below(ls, v, pn, best, curv_k, flags))) {
                have_best = 1;
                best = pn;
            }
            float best_d = 0.0f, best_dz = -1.0f;
            if (have_best) {
                best_d = ss_hull_dist(ls, v, best, flags);
                best_dz = ss_hull_height_above(v, best, flags) - curv_k * best_d * best_d;
            }
            /* Radius terms are never radiative: no gradient is read. */
            float term = ss_svf_term_for(definition, ls, 0, 0, best_d, best_dz, 0.0f, 0.0f, z);
            if (h.cell0 >= 0)
                acc[h.cell0] += h.w0 * term;
            if (h.cell1 >= 0)
                acc[h.cell1] += h.w1 * term;
        }
        a = s;
        s = e;
    }
}

/* The same by scanning back over each window: cheaper than the hulls
 * while a window holds at most SS_RADIUS_SCAN_STEPS steps. */
SS_FN void ss_radius_scan(const ss_walker *w, const ss_line_set *ls, int s_lo, int s_hi,
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
 * (SS_WALK_DIGITAL, SS_WALK_CURVED), so that each does only what it needs;
 * box lines, whose steps cost several points each, share one copy. */
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
    case SS_WALK_DIGITAL | SS_WALK_CURVED:
        ss_svf_steps(&w, ls, s_lo, s_hi, run->term, k, sa, ca, z, grad, stack, acc,
                     SS_WALK_DIGITAL | SS_WALK_CURVED);
        break;
    default:
        ss_svf_steps(&w, ls, s_lo, s_hi, run->term, k, sa, ca, z, grad, stack, acc,
                     ss_walk_flags(ls, k));
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

/* The steps of a line worth walking for a sun that clears every cell whose
 * bound level is at most lit_level: those up to its last sample that gives
 * a horizon to a cell above that level (none: s_lo). Past it, cells get
 * part of their samples or none, and so a horizon below their bound, which
 * the sun clears as it clears the whole walk's. */
SS_FN int ss_line_shadow_end(const ss_walker *w, const ss_line_set *ls, int s_lo, int s_hi,
                             SS_GLOBAL const unsigned char *levels, int lit_level)
{
    int box = ls->model == SS_LINE_MODEL_BOX;
    for (int s = s_hi - 1; s >= s_lo; --s) {
        ss_line_sample p = ss_walker_sample(ls, w, s);
        int cell = ss_line_cell(ls, p.major, p.minor0);
        if (p.minor0 >= 0 && p.minor0 < ls->minor_len && levels[cell] > lit_level)
            return s + 1;
        /* A box line's step gives a horizon to its nearest cell alone. */
        if (!box && p.minor0 + 1 < ls->minor_len && p.w1 > 0.0f &&
            levels[cell + ls->stride_minor] > lit_level)
            return s + 1;
    }
    return s_lo;
}

/* Whether a step of [s_from, count) of a line may give a horizon to a
 * cell whose block (kernels/ss_band.h; blocks: the largest level of each,
 * over the grid) is above lit_level: the cells ss_line_shadow_end tests,
 * by their blocks' levels, each at least the cell's. The steps go in runs
 * within one block column (or row) of the major axis, each run's cells
 * lying between its first and last steps' across the line (the line is
 * straight): two samples and a block or two a run, not a sample a step. */
SS_FN int ss_line_shadow_ahead(const ss_walker *w, const ss_line_set *ls, int s_from, int count,
                               SS_GLOBAL const unsigned char *blocks, int width, int lit_level)
{
    int side = 1 << SS_LIT_BLOCK_SHIFT;
    int nbx = (width + side - 1) >> SS_LIT_BLOCK_SHIFT;
    /* A box line's step gives a horizon to its nearest cell alone. */
    int reach = ls->model == SS_LINE_MODEL_BOX ? 0 : 1;
    for (int s1 = count - 1; s1 >= s_from;) {
        ss_line_sample last = ss_walker_sample(ls, w, s1);
        /* Back to the first step of the run in last's block of majors:
         * majors move by one a step, up or down. */
        int off = last.major & (side - 1);
        int back = w->dmajor > 0 ? off : side - 1 - off;
        int s0 = s1 - back > s_from ? s1 - back : s_from;
        ss_line_sample first = ss_walker_sample(ls, w, s0);
        int lo = first.minor0 < last.minor0 ? first.minor0 : last.minor0;
        int hi = (first.minor0 > last.minor0 ? first.minor0 : last.minor0) + reach;
        lo = lo > 0 ? lo : 0;
        hi = hi < ls->minor_len - 1 ? hi : ls->minor_len - 1;
        int major_block = last.major >> SS_LIT_BLOCK_SHIFT;
        for (int m = lo >> SS_LIT_BLOCK_SHIFT; m <= hi >> SS_LIT_BLOCK_SHIFT && lo <= hi; ++m) {
            int row = ls->major_is_row ? major_block : m, col = ls->major_is_row ? m : major_block;
            if (blocks[row * nbx + col] > lit_level)
                return 1;
        }
        s1 = s0 - 1;
    }
    return 0;
}

/* A band's blocks of sector k: after the planes of its held rows. */
SS_FN SS_GLOBAL const unsigned char *ss_lit_blocks(SS_GLOBAL const unsigned char *lit_levels,
                                                   const ss_band_run *run, int k)
{
    int side = 1 << SS_LIT_BLOCK_SHIFT;
    ss_i64 nbx = (run->width + side - 1) >> SS_LIT_BLOCK_SHIFT;
    ss_i64 nby = (run->height + side - 1) >> SS_LIT_BLOCK_SHIFT;
    return lit_levels + SS_LIT_SECTORS * (ss_i64)run->held_rows * run->width + k * nbx * nby;
}

/* A horizon walk of a line's band steps into its direction's planes;
 * returns the steps it left unwalked (ss_line_shadow_end). In bands, the
 * walk goes on through the band's steps where a block ahead may need it
 * (ss_line_shadow_ahead), with its hull handed on; else it stops as on
 * the whole grid, and hands nothing on: no step ahead is walked (a cell's
 * level is at most its block's). On
 * the host, by a copy of the walk compiled for the line's flags as
 * ss_band_sum_line's (box lines share one copy): 6 % faster sweeps. A
 * device keeps one general copy: four made PoCL's first compile of the
 * kernels on a machine 1.4 s longer. */
SS_FN int ss_band_horizon_line(const ss_band_dir *d, const ss_band_run *run, int line,
                               SS_GLOBAL const float *z, SS_GLOBAL int *stack,
                               SS_GLOBAL float *outs, ss_band_hulls hulls,
                               SS_GLOBAL const unsigned char *lit_levels)
{
    ss_walker w;
    int s_lo, s_hi, count, skipped = 0;
    if (!ss_band_line_begin(&w, d, run, line, hulls, &s_lo, &s_hi, &count))
        return 0;
    /* The bounds hold for interpolated and box lines (the host makes them
     * for the run's model), bent down by curvature or not. */
    int lit = lit_levels && d->ls.model != SS_LINE_MODEL_DIGITAL && run->curv_k >= 0.0f
                  ? d->lit_level
                  : -1;
    int done = s_hi; /* the step the line's state is recorded at */
    if (lit >= 0) {
        /* The bounds of the sector of the direction's azimuth: the held
         * rows' plane, and in bands the blocks' after the planes. */
        int stops = run->whole || !ss_line_shadow_ahead(&w, &d->ls, s_hi, count,
                                                        ss_lit_blocks(lit_levels, run,
                                                                      d->lit_sector),
                                                        run->width, lit);
        lit_levels += (ss_i64)d->lit_sector * run->held_rows * run->width;
        if (stops) {
            int end = ss_line_shadow_end(&w, &d->ls, s_lo, s_hi, lit_levels, lit);
            skipped = s_hi - end;
            s_hi = end;
            done = count;
        }
    }
    /* Planes not asked for are never written: the angle plane stands in. */
    SS_GLOBAL float *angle = ss_band_plane(outs, run, d->slot, 0);
    SS_GLOBAL float *weight = ss_band_plane(outs, run, d->slot, 1);
    SS_GLOBAL float *dist = run->planes > 2 ? ss_band_plane(outs, run, d->slot, 2) : angle;
    SS_GLOBAL float *cast = run->planes > 3 ? ss_band_plane(outs, run, d->slot, 3) : angle;
    const ss_line_set *ls = &d->ls;
    float k = run->curv_k;
#ifdef __OPENCL_VERSION__
    ss_horizon_steps(&w, ls, s_lo, s_hi, k, z, stack, angle, weight, dist, cast, run->want,
                     ss_walk_flags(ls, k), lit_levels, lit);
#else
    switch (ss_walk_flags(ls, k)) {
    case 0:
        ss_horizon_steps(&w, ls, s_lo, s_hi, k, z, stack, angle, weight, dist, cast, run->want, 0,
                         lit_levels, lit);
        break;
    case SS_WALK_DIGITAL:
        ss_horizon_steps(&w, ls, s_lo, s_hi, k, z, stack, angle, weight, dist, cast, run->want,
                         SS_WALK_DIGITAL, lit_levels, lit);
        break;
    case SS_WALK_CURVED:
        ss_horizon_steps(&w, ls, s_lo, s_hi, k, z, stack, angle, weight, dist, cast, run->want,
                         SS_WALK_CURVED, lit_levels, lit);
        break;
    case SS_WALK_DIGITAL | SS_WALK_CURVED:
        ss_horizon_steps(&w, ls, s_lo, s_hi, k, z, stack, angle, weight, dist, cast, run->want,
                         SS_WALK_DIGITAL | SS_WALK_CURVED, lit_levels, lit);
        break;
    default:
        ss_horizon_steps(&w, ls, s_lo, s_hi, k, z, stack, angle, weight, dist, cast, run->want,
                         ss_walk_flags(ls, k), lit_levels, lit);
    }
#endif
    ss_band_line_end(&w, d, run, line, done, count, hulls.state, hulls.counters);
    return skipped;
}

/* A radius-limited term of a line's band steps into acc: no hull handed
 * on, the band holds every row within the radius. */
SS_FN void ss_band_radius_line(const ss_band_dir *d, const ss_band_run *run, int line,
                               SS_GLOBAL const float *z, SS_GLOBAL int *stack,
                               SS_GLOBAL float *acc)
{
    ss_walker w;
    int count = ss_walker_begin(&w, &d->ls, line), s_lo, s_hi;
    ss_band_own_steps(&w, d, run, count, &s_lo, &s_hi);
    int flags = ss_walk_flags(&d->ls, run->curv_k);
    if (run->radius_m <= SS_RADIUS_SCAN_STEPS * d->ls.along_per_step_m)
        ss_radius_scan(&w, &d->ls, s_lo, s_hi, run->term, run->radius_m, run->curv_k, z, acc,
                       flags);
    else
        ss_radius_hulls(&w, &d->ls, s_lo, s_hi, run->term, run->radius_m, run->curv_k, z,
                        (SS_GLOBAL ss_hull_point *)stack, acc, flags);
}

/* Rounds of a direction's lines, so that lines of one round never touch
 * the same cell: digital lines partition the grid (one round); interpolated
 * lines feed two cells per sample and neighbouring lines the same cells
 * (two rounds: even, then odd intercepts); box lines run a round per family
 * (each family's lines partition the grid's home cells). */
SS_FN int ss_line_rounds(const ss_line_set *ls)
{
    return ls->model == SS_LINE_MODEL_INTERPOLATED ? 2 : ls->families;
}

/* Lines of one round. */
SS_FN int ss_round_lines(const ss_line_set *ls, int round)
{
    if (ls->model == SS_LINE_MODEL_INTERPOLATED)
        return (ls->n_lines - round + 1) / 2;
    return round < ls->families ? ls->n_lines : 0;
}

/* Line number of a round's index-th line. */
SS_FN int ss_round_line(const ss_line_set *ls, int round, int index)
{
    return ls->model == SS_LINE_MODEL_INTERPOLATED ? 2 * index + round
                                                   : round * ls->n_lines + index;
}

#endif
