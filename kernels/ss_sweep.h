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
 * walked. Each slot holds the step index of a hull vertex; the two top
 * vertices are cached in registers.
 */
#ifndef SS_SWEEP_H
#define SS_SWEEP_H

#include "ss_lines.h"

/* A sample's height is kept as base + offset (a cell's height and the
 * interpolated step toward its neighbour), so that differences between
 * samples are formed from differences of cell heights and keep the float
 * precision of the local relief, not of the heights' magnitude. */
typedef struct {
    int s;       /* step index along the line, in walk order */
    int minor;   /* minor index of the sample's cell (digital lines) */
    float x;     /* position along the walk, metres from the line's origin sample */
    float z;     /* height of the sample's base cell, relative to the grid origin */
    float z_off; /* interpolated offset from the base cell's height */
} ss_hull_point;

typedef struct {
    int b;           /* line intercept */
    int first;       /* lowest major index of the line */
    int count;       /* samples on the line */
    int next;        /* next step to take */
    int origin_s;    /* step whose sample is position 0 (mid-line keeps */
    int origin_minor;/* positions, and so the curvature terms, small) */
    int depth;       /* vertices on the hull stack */
    ss_hull_point top, second; /* cached copies of the two top stack slots */
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
    h.w1 = p.w1;
    h.w0 = 1.0f - p.w1;
    h.cell0 = p.minor0 >= 0 && h.w0 > 0.0f ? ss_line_cell(ls, p.major, p.minor0) : -1;
    h.cell1 = p.minor0 + 1 < ls->minor_len && h.w1 > 0.0f
                  ? ss_line_cell(ls, p.major, p.minor0 + 1)
                  : -1;
    float z0 = h.cell0 >= 0 ? z[h.cell0] : 0.0f;
    float z1 = h.cell1 >= 0 ? z[h.cell1] : 0.0f;
    int ok0 = h.cell0 >= 0 && SS_ISFINITE(z0);
    int ok1 = h.cell1 >= 0 && SS_ISFINITE(z1);
    h.valid = ok0 || ok1;
    h.occludes = (ok0 || h.w0 == 0.0f) && (ok1 || h.w1 == 0.0f);
    *base = ok0 ? z0 : z1;
    *offset = ok0 && ok1 ? h.w1 * (z1 - z0) : 0.0f;
    return h;
}

/* Starts line number `line`; returns its number of samples. */
SS_FN int ss_walker_begin(ss_walker *w, const ss_line_set *ls, int line)
{
    w->b = ls->line_min + line;
    w->count = ss_line_extent(ls, line, &w->first);
    w->next = 0;
    w->depth = 0;
    w->origin_s = w->count / 2;
    w->origin_minor =
        ss_line_minor(ls, w->b, ss_line_major_at(ls, w->first, w->count, w->origin_s));
    return w->count;
}

/* Position of a sample along the walk, metres from the origin sample. */
SS_FN float ss_walker_along(const ss_line_set *ls, const ss_walker *w, int s, int minor)
{
    return (float)(s - w->origin_s) * ls->along_per_step_m +
           (float)(minor - w->origin_minor) * ls->along_per_minor_m;
}

/* Distance from hull point t to the later point v, from integer index
 * differences so that it keeps full float precision on long lines. */
SS_FN float ss_hull_dist(const ss_line_set *ls, ss_hull_point v, ss_hull_point t)
{
    return (float)(v.s - t.s) * ls->along_per_step_m +
           (float)(v.minor - t.minor) * ls->along_per_minor_m;
}

/* Height of hull point t above v. */
SS_FN float ss_hull_height_above(ss_hull_point v, ss_hull_point t)
{
    return (t.z - v.z) + (t.z_off - v.z_off);
}

/* Bent-height difference z~_t - z~_v of hull point t over v at distance d. */
SS_FN float ss_hull_rise(ss_hull_point v, ss_hull_point t, float d, float curv_k)
{
    return ss_hull_height_above(v, t) + curv_k * d * (t.x + v.x);
}

SS_FN ss_line_sample ss_walker_sample(const ss_line_set *ls, const ss_walker *w, int s)
{
    return ss_line_sample_at(ls, w->b, ss_line_major_at(ls, w->first, w->count, s));
}

/* The hull vertex kept in stack slot `slot`: the slot (at the home cell of
 * the line's slot-th sample) holds the vertex's step index. Only occluding
 * samples are pushed, so the vertex is a full interpolation. */
SS_FN ss_hull_point ss_walker_load(const ss_line_set *ls, const ss_walker *w,
                                   SS_GLOBAL const float *z, SS_GLOBAL const int *stack,
                                   int slot)
{
    ss_hull_point p;
    p.s = stack[ss_walker_sample(ls, w, slot).home];
    ss_line_sample q = ss_walker_sample(ls, w, p.s);
    ss_sample_cells(ls, q, z, &p.z, &p.z_off);
    p.minor = q.minor0;
    p.x = ss_walker_along(ls, w, p.s, p.minor);
    return p;
}

/* Walks the next sample of the line and returns its horizon. */
SS_FN ss_sample_horizon ss_walker_step(ss_walker *w, const ss_line_set *ls,
                                       SS_GLOBAL const float *z, SS_GLOBAL int *stack,
                                       float curv_k)
{
    int s = w->next++;
    ss_line_sample q = ss_walker_sample(ls, w, s);
    ss_hull_point v;
    ss_sample_horizon h = ss_sample_cells(ls, q, z, &v.z, &v.z_off);
    if (!h.valid)
        return h;
    v.s = s;
    v.minor = q.minor0;
    v.x = ss_walker_along(ls, w, s, v.minor);
    if (w->depth > 0 && h.occludes) {
        float d1 = ss_hull_dist(ls, v, w->top);
        float dz1 = ss_hull_rise(v, w->top, d1, curv_k);
        while (w->depth >= 2) {
            float d2 = ss_hull_dist(ls, v, w->second);
            float dz2 = ss_hull_rise(v, w->second, d2, curv_k);
            if (dz2 * d1 < dz1 * d2)
                break;
            /* The top lies on or under the chord from the second vertex to v,
             * so it can never again be anyone's horizon: pop it. Popping
             * collinear vertices too keeps the farthest of equal horizons. */
            w->top = w->second;
            d1 = d2;
            dz1 = dz2;
            w->depth--;
            if (w->depth >= 2)
                w->second = ss_walker_load(ls, w, z, stack, w->depth - 2);
        }
        h.d = d1;
        h.dz = ss_hull_height_above(v, w->top) - curv_k * d1 * d1;
    } else if (w->depth > 0) {
        /* v will not join the hull, so the hull must stay as it is: walk
         * down from the top while the tangent still rises (the slopes from
         * v along a convex hull rise to the tangent vertex, then fall). */
        ss_hull_point best = w->top;
        float d1 = ss_hull_dist(ls, v, best);
        float dz1 = ss_hull_rise(v, best, d1, curv_k);
        for (int slot = w->depth - 2; slot >= 0; --slot) {
            ss_hull_point t = slot == w->depth - 2 ? w->second
                                                   : ss_walker_load(ls, w, z, stack, slot);
            float d2 = ss_hull_dist(ls, v, t);
            float dz2 = ss_hull_rise(v, t, d2, curv_k);
            if (dz2 * d1 < dz1 * d2)
                break;
            best = t;
            d1 = d2;
            dz1 = dz2;
        }
        h.d = d1;
        h.dz = ss_hull_height_above(v, best) - curv_k * d1 * d1;
    }
    if (!h.occludes)
        return h;
    stack[ss_walker_sample(ls, w, w->depth).home] = s;
    w->second = w->top;
    w->top = v;
    w->depth++;
    return h;
}

#endif
