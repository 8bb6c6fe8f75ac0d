/* The horizon sweep along one digital line (shared by kernels and C).
 *
 * Walking a line cell by cell, an upper convex hull of the cells seen so far
 * (all of them lie ahead of the current cell in the azimuth) gives the
 * current cell its exact horizon: the hull vertex that the tangent from the
 * cell touches (Timonen & Westerholm 2010, sec. 5; Barrett 2011). Each cell
 * is pushed once and popped at most once, so a line of n cells costs O(n).
 *
 * Earth curvature (with refraction folded into the radius) is exact inside
 * the hull: the hull is the upper hull of the bent heights z~ = z - k x^2
 * (k = 1 / (2 R_eff)), and the tangent from v touches it where the curved
 * elevation (z_t - z_v - k d^2) / d is largest (reference/physics.md sec. 5).
 * Bent heights are never stored: a difference z~_t - z~_v is formed as
 * (z_t - z_v) + k d (x_t + x_v), which keeps the float precision of the
 * raw height difference. curv_k = k; 0 switches curvature off.
 *
 * The hull stack needs no storage of its own: stack slot i of a line is
 * kept in the stack grid at the home cell of the line's i-th sample, which
 * no line running at the same time shares, and which has already been
 * walked. Each slot holds the step index of a hull vertex; the top
 * SS_RING vertices are also kept whole in private memory, so the pops that
 * follow most pushes need no global reads.
 *
 * A walk can stop after any step and resume later in other buffers (a
 * band of rows, kernels/ss_band.h, when the grid is not held whole):
 * the hull so far is then handed on as whole points, the `carried` slots
 * below slot_base, and the slots pushed after the resumption live at the
 * home cells of the samples walked since, counted from sample_base.
 */
#ifndef SS_SWEEP_H
#define SS_SWEEP_H

#include "ss_box.h"

/* A sample's height is kept as base + offset (a cell's height and the
 * interpolated step toward its neighbour), so that differences between
 * samples are formed from differences of cell heights and keep the float
 * precision of the local relief, not of the heights' magnitude. */
typedef struct {
    float u;     /* step index minus the origin step (exact in float) */
    float m;     /* minor index minus the origin's (digital lines; else 0) */
    float z;     /* height of the sample's base cell, relative to the grid origin */
    float z_off; /* interpolated offset from the base cell's height */
} ss_hull_point;

/* What a walk must handle, fixed per line so that the compiler drops what
 * a line does not need (interpolated lines have offsets and no minor term,
 * digital and box lines the reverse; most runs have no curvature). */
#define SS_WALK_DIGITAL 1
#define SS_WALK_CURVED 2
#define SS_WALK_BOX 4 /* with SS_WALK_DIGITAL: a step meets column boundaries (ss_box.h) */

/* Hull vertices kept in private memory: the top SS_RING stack slots (a
 * power of two). */
#define SS_RING 8

typedef struct {
    ss_i64 b16;       /* line intercept, 16.16 fixed point */
    int first;        /* lowest major index of the line */
    int count;        /* samples on the line */
    int major0;       /* major index of step 0, and its change per step */
    int dmajor;
    ss_i64 y0;        /* 16.16 position across the line at step 0, and per step */
    ss_i64 dy;
    int origin_s;     /* step whose sample is position 0 (mid-line keeps */
    int origin_minor; /* positions, and so the curvature terms, small) */
    int depth;        /* vertices on the hull stack */
    int ring_low;     /* lowest stack slot whose copy in ring is valid */
    int slot_base;    /* slots below are carried in whole (0 unless resumed) */
    int sample_base;  /* step of the first sample walked since resuming (0) */
    SS_GLOBAL const ss_hull_point *carried; /* slots [0, slot_base) */
    ss_hull_point ring[SS_RING]; /* slot i at ring[i & (SS_RING - 1)] */
} ss_walker;

/* What one sample hands to a product: its horizon as a vector in the
 * vertical plane of the azimuth (d > 0: distance along the azimuth to the
 * casting sample, dz: its height above this one after curvature; (0, -1)
 * when nothing lies ahead, i.e. -90 degrees) and the cells that receive it,
 * with weights. */
typedef struct {
    int valid;        /* 0: no height here: no horizon, not an occluder */
    int occludes;     /* 1: a true interpolation, so it may cast horizons */
    int cell0, cell1; /* receiving cells, -1 when absent */
    float w0, w1;     /* their weights */
    int major;        /* the cells' major index; minors are minor0, minor0 + 1 */
    int minor0;
    float d, dz;
    float zc; /* height of the casting sample relative to the grid origin, when d > 0 */
} ss_sample_horizon;

/* Height of a sample (base + offset, see ss_hull_point) and the cells it
 * feeds. A sample has a height when at least one cell with a positive weight
 * has one; nodata cells and cells outside the grid drop out of the
 * interpolation. Only a sample whose every positive-weight cell has a height
 * occludes: one that leans on a single cell across a grid edge or a nodata
 * hole sits beside its true surface, and taken as an occluder it would cast
 * false horizons along the whole line. It still gets a horizon, for the
 * cells it feeds. */
SS_FN ss_sample_horizon ss_sample_cells(const ss_line_set *ls, ss_line_sample p,
                                        SS_GLOBAL const float *z, float *base, float *offset)
{
    ss_sample_horizon h;
    h.major = p.major;
    h.minor0 = p.minor0;
    h.d = 0.0f;
    h.dz = -1.0f;
    h.zc = 0.0f;
    h.w1 = p.w1;
    h.w0 = 1.0f - p.w1; /* > 0: the fraction is below 1 */
    int cell = ss_line_cell(ls, p.major, p.minor0);
    int in0 = p.minor0 >= 0, in1 = p.minor0 + 1 < ls->minor_len && p.w1 > 0.0f;
    float z0 = in0 ? z[cell] : 0.0f;
    float z1 = in1 ? z[cell + ls->stride_minor] : 0.0f;
    int ok0 = in0 && SS_ISFINITE(z0), ok1 = in1 && SS_ISFINITE(z1);
    h.cell0 = in0 ? cell : -1;
    h.cell1 = in1 ? cell + ls->stride_minor : -1;
    h.valid = ok0 || ok1;
    h.occludes = ok0 && (ok1 || p.w1 == 0.0f);
    *base = ok0 ? z0 : z1;
    *offset = ok0 && ok1 ? p.w1 * (z1 - z0) : 0.0f;
    return h;
}

/* The sample at step s of the walker's line. */
SS_FN ss_line_sample ss_walker_sample(const ss_line_set *ls, const ss_walker *w, int s)
{
    return ss_line_sample_y16(ls, w->major0 + s * w->dmajor, w->y0 + (ss_i64)s * w->dy);
}

/* Starts line number `line`; returns its number of samples. */
SS_FN int ss_walker_begin(ss_walker *w, const ss_line_set *ls, int line)
{
    w->b16 = ss_line_intercept16(ls, line);
    w->count = ss_line_extent(ls, line, &w->first);
    w->dmajor = ls->step;
    w->major0 = ls->step > 0 ? w->first : w->first + w->count - 1;
    w->y0 = ss_line_y16(ls, w->b16, w->major0);
    /* Positions are linear in the major index: the slope has 16 fractional bits. */
    w->dy = (ss_i64)w->dmajor * (ls->slope_fx / 65536);
    w->depth = 0;
    w->ring_low = 0;
    w->slot_base = 0;
    w->sample_base = 0;
    w->carried = 0;
    w->origin_s = w->count / 2;
    w->origin_minor = ss_walker_sample(ls, w, w->origin_s).minor0;
    return w->count;
}

/* Position of hull point p along the walk, metres from the origin sample. */
SS_FN float ss_hull_x(const ss_line_set *ls, ss_hull_point p)
{
    return p.u * ls->along_per_step_m + p.m * ls->along_per_minor_m;
}

/* Distance from hull point t to the later point v. u and m are integers
 * held exactly in float, so the differences are exact and the distance
 * keeps full float precision on long lines. */
SS_FN float ss_hull_dist(const ss_line_set *ls, ss_hull_point v, ss_hull_point t, int flags)
{
    float d = (v.u - t.u) * ls->along_per_step_m;
    if (flags & SS_WALK_DIGITAL)
        d += (v.m - t.m) * ls->along_per_minor_m;
    return d;
}

/* Height of hull point t relative to the grid origin (digital lines have
 * no offsets). */
SS_FN float ss_hull_height(ss_hull_point t, int flags)
{
    return (flags & SS_WALK_DIGITAL) ? t.z : t.z + t.z_off;
}

/* Height of hull point t above v, from differences of like parts. */

SS_FN float ss_hull_height_above(ss_hull_point v, ss_hull_point t, int flags)
{
    float dz = t.z - v.z;
    if (!(flags & SS_WALK_DIGITAL))
        dz += t.z_off - v.z_off;
    return dz;
}

/* Bent-height difference z~_t - z~_v of hull point t over v at distance d. */
SS_FN float ss_hull_rise(const ss_line_set *ls, ss_hull_point v, ss_hull_point t, float d,
                         float curv_k, int flags)
{
    float dz = ss_hull_height_above(v, t, flags);
    if (flags & SS_WALK_CURVED)
        dz += curv_k * d * (ss_hull_x(ls, t) + ss_hull_x(ls, v));
    return dz;
}

/* The hull point of the sample at step s. */
SS_FN ss_hull_point ss_hull_point_at(const ss_walker *w, int s, ss_line_sample q, float base,
                                     float offset)
{
    ss_hull_point p;
    p.u = (float)(s - w->origin_s);
    p.m = (float)(q.minor0 - w->origin_minor);
    p.z = base;
    p.z_off = offset;
    return p;
}

/* Where stack slot `slot` (at or above slot_base) lives in the stack grid:
 * at the home cell of the (slot - slot_base)-th sample walked since the
 * walk began or resumed. A box line pushes up to SS_BOX_EVENTS points a
 * step, so its stack grid holds that many slots per cell. */
SS_FN int ss_walker_home(const ss_line_set *ls, const ss_walker *w, int slot)
{
    int k = slot - w->slot_base;
    if (ls->model != SS_LINE_MODEL_BOX)
        return ss_walker_sample(ls, w, w->sample_base + k).home;
    return SS_BOX_EVENTS * ss_walker_sample(ls, w, w->sample_base + k / SS_BOX_EVENTS).home +
           k % SS_BOX_EVENTS;
}

/* The points that step s of a box line meets (ss_box.h). */
SS_FN ss_box_step ss_walker_box_step(const ss_line_set *ls, const ss_walker *w,
                                     SS_GLOBAL const float *z, int s)
{
    return ss_box_step_at(ls, z, w->major0 + s * w->dmajor, w->y0 + (ss_i64)s * w->dy, w->dy,
                          w->dmajor, (float)(s - w->origin_s));
}

SS_FN ss_hull_point ss_box_hull_point(ss_box_point b)
{
    ss_hull_point p;
    p.u = b.u;
    p.m = b.m;
    p.z = b.z;
    p.z_off = 0.0f;
    return p;
}

/* Rebuilds stack slot `slot` from the stack grid: the slot (at its home
 * cell) holds the vertex's step index (box lines: SS_BOX_EVENTS times the
 * step plus the point's kind); carried slots are whole points. Only
 * occluding samples are pushed, so the vertex is a full interpolation. */
SS_FN ss_hull_point ss_walker_load(const ss_line_set *ls, const ss_walker *w,
                                   SS_GLOBAL const float *z, SS_GLOBAL const int *stack,
                                   int slot)
{
    if (slot < w->slot_base)
        return w->carried[slot];
    int s = stack[ss_walker_home(ls, w, slot)];
    if (ls->model == SS_LINE_MODEL_BOX) {
        ss_box_step b = ss_walker_box_step(ls, w, z, s / SS_BOX_EVENTS);
        int k = 0;
        while (k + 1 < b.n && b.p[k].kind != s % SS_BOX_EVENTS)
            ++k;
        return ss_box_hull_point(b.p[k]);
    }
    ss_line_sample q = ss_walker_sample(ls, w, s);
    float base, offset;
    ss_sample_cells(ls, q, z, &base, &offset);
    return ss_hull_point_at(w, s, q, base, offset);
}

/* Vertex in stack slot `slot` (below the top): from the ring, which is
 * refilled downward from the stack grid when the hull shrinks below it
 * (the ring positions it takes belong to slots above the top, no longer
 * live). */
SS_FN ss_hull_point ss_walker_vertex(ss_walker *w, const ss_line_set *ls,
                                     SS_GLOBAL const float *z, SS_GLOBAL const int *stack,
                                     int slot)
{
    while (w->ring_low > slot) {
        w->ring_low--;
        w->ring[w->ring_low & (SS_RING - 1)] = ss_walker_load(ls, w, z, stack, w->ring_low);
    }
    return w->ring[slot & (SS_RING - 1)];
}

SS_FN void ss_walker_push(ss_walker *w, const ss_line_set *ls, SS_GLOBAL int *stack,
                          ss_hull_point v, int s)
{
    int slot = w->depth++;
    /* A resumed hull that shrank into its carried slots grows again from
     * there: those slots now live at home cells too. */
    if (slot < w->slot_base)
        w->slot_base = slot;
    stack[ss_walker_home(ls, w, slot)] = s;
    w->ring[slot & (SS_RING - 1)] = v;
    if (slot - w->ring_low >= SS_RING)
        w->ring_low = slot - SS_RING + 1;
}

/* Takes occluding point v (stack value id) into the hull and gives h its
 * horizon: the tangent from v over the hull before it, found while popping
 * what v hides. */
SS_FN void ss_walker_insert(ss_walker *w, const ss_line_set *ls, SS_GLOBAL const float *z,
                            SS_GLOBAL int *stack, float curv_k, ss_hull_point v, int id,
                            ss_sample_horizon *h, int flags)
{
    if (w->depth > 0) {
        ss_hull_point top = w->ring[(w->depth - 1) & (SS_RING - 1)];
        float d1 = ss_hull_dist(ls, v, top, flags);
        float dz1 = ss_hull_rise(ls, v, top, d1, curv_k, flags);
        while (w->depth >= 2) {
            ss_hull_point second = ss_walker_vertex(w, ls, z, stack, w->depth - 2);
            float d2 = ss_hull_dist(ls, v, second, flags);
            float dz2 = ss_hull_rise(ls, v, second, d2, curv_k, flags);
            if (dz2 * d1 < dz1 * d2)
                break;
            /* The top lies on or under the chord from the second vertex to v,
             * so it can never again be anyone's horizon: pop it. Popping
             * collinear vertices too keeps the farthest of equal horizons. */
            top = second;
            d1 = d2;
            dz1 = dz2;
            w->depth--;
        }
        h->d = d1;
        h->dz = ss_hull_height_above(v, top, flags) - curv_k * d1 * d1;
        h->zc = ss_hull_height(top, flags);
    }
    ss_walker_push(w, ls, stack, v, id);
}

/* Walks step s of a box line: takes every point the step meets into the
 * hull, and returns the centre's horizon for its cell if this line is the
 * cell's nearest. */
SS_FN ss_sample_horizon ss_walker_box(ss_walker *w, const ss_line_set *ls,
                                      SS_GLOBAL const float *z, SS_GLOBAL int *stack,
                                      float curv_k, int s, int flags)
{
    ss_box_step b = ss_walker_box_step(ls, w, z, s);
    ss_sample_horizon h;
    h.valid = 0;
    h.occludes = 1;
    h.cell0 = b.owned ? b.centre_cell : -1;
    h.cell1 = -1;
    h.w0 = 1.0f;
    h.w1 = 0.0f;
    h.major = w->major0 + s * w->dmajor;
    h.minor0 = (int)ss_floor16(w->y0 + (ss_i64)s * w->dy);
    h.d = 0.0f;
    h.dz = -1.0f;
    h.zc = 0.0f;
    for (int k = 0; k < b.n; ++k) {
        ss_sample_horizon seen = h;
        ss_walker_insert(w, ls, z, stack, curv_k, ss_box_hull_point(b.p[k]),
                         SS_BOX_EVENTS * s + b.p[k].kind, &seen, flags);
        if (b.p[k].kind == SS_BOX_CENTRE) {
            h = seen;
            h.valid = 1;
        }
    }
    return h;
}

/* Walks sample s (the next one) of the line and returns its horizon. */
SS_FN ss_sample_horizon ss_walker_step(ss_walker *w, const ss_line_set *ls,
                                       SS_GLOBAL const float *z, SS_GLOBAL int *stack,
                                       float curv_k, int s, int flags)
{
    if (flags & SS_WALK_BOX)
        return ss_walker_box(w, ls, z, stack, curv_k, s, flags);
    ss_line_sample q = ss_walker_sample(ls, w, s);
    float base, offset;
    ss_sample_horizon h = ss_sample_cells(ls, q, z, &base, &offset);
    if (!h.valid)
        return h;
    ss_hull_point v = ss_hull_point_at(w, s, q, base, offset);
    if (h.occludes) {
        ss_walker_insert(w, ls, z, stack, curv_k, v, s, &h, flags);
    } else if (w->depth > 0) {
        /* v will not join the hull, so the hull must stay as it is: walk
         * down from the top while the tangent still rises (the slopes from
         * v along a convex hull rise to the tangent vertex, then fall).
         * Deep slots are read from the stack grid, leaving the ring alone. */
        ss_hull_point best = w->ring[(w->depth - 1) & (SS_RING - 1)];
        float d1 = ss_hull_dist(ls, v, best, flags);
        float dz1 = ss_hull_rise(ls, v, best, d1, curv_k, flags);
        for (int slot = w->depth - 2; slot >= 0; --slot) {
            ss_hull_point t = slot >= w->ring_low ? w->ring[slot & (SS_RING - 1)]
                                                  : ss_walker_load(ls, w, z, stack, slot);
            float d2 = ss_hull_dist(ls, v, t, flags);
            float dz2 = ss_hull_rise(ls, v, t, d2, curv_k, flags);
            if (dz2 * d1 < dz1 * d2)
                break;
            best = t;
            d1 = d2;
            dz1 = dz2;
        }
        h.d = d1;
        h.dz = ss_hull_height_above(v, best, flags) - curv_k * d1 * d1;
        h.zc = ss_hull_height(best, flags);
    }
    return h;
}

/* Resumes a walk just begun (ss_walker_begin) at step s_lo, with the hull
 * of the steps before handed on as n whole points (ss_walker_slot). */
SS_FN void ss_walker_take_hull(ss_walker *w, int s_lo, SS_GLOBAL const ss_hull_point *carried,
                               int n)
{
    w->carried = carried;
    w->slot_base = n;
    w->depth = n;
    w->sample_base = s_lo;
    w->ring_low = n > SS_RING ? n - SS_RING : 0;
    for (int k = w->ring_low; k < n; ++k)
        w->ring[k & (SS_RING - 1)] = carried[k];
}

/* Hull slot k (below depth) as a whole point, to hand the hull on. */
SS_FN ss_hull_point ss_walker_slot(const ss_walker *w, const ss_line_set *ls,
                                   SS_GLOBAL const float *z, SS_GLOBAL const int *stack, int k)
{
    return k >= w->ring_low ? w->ring[k & (SS_RING - 1)] : ss_walker_load(ls, w, z, stack, k);
}

/* The flags of a line set and curvature (see SS_WALK_DIGITAL). */
SS_FN int ss_walk_flags(const ss_line_set *ls, float curv_k)
{
    int model = ls->model == SS_LINE_MODEL_DIGITAL ? SS_WALK_DIGITAL
                : ls->model == SS_LINE_MODEL_BOX   ? SS_WALK_DIGITAL | SS_WALK_BOX
                                                   : 0;
    return model | (curv_k != 0.0f ? SS_WALK_CURVED : 0);
}

#endif
