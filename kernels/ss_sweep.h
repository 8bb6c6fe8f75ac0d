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
 * kept in the stack grid at the cell of the line's i-th step, which belongs
 * to that line alone and has already been walked. Each slot holds the step
 * index of a hull vertex; the two top vertices are cached in registers.
 */
#ifndef SS_SWEEP_H
#define SS_SWEEP_H

#include "ss_lines.h"

typedef struct {
    int s;     /* step index along the line, in walk order */
    int minor; /* minor index of that cell */
    float x;   /* position along the walk, metres from the line's origin cell */
    float z;   /* height relative to the grid origin */
} ss_hull_point;

typedef struct {
    int b;           /* line intercept */
    int first;       /* lowest major index of the line */
    int count;       /* cells on the line */
    int next;        /* next step to take */
    int origin_s;    /* step whose cell centre is position 0 (mid-line keeps */
    int origin_minor;/* positions, and so the curvature terms, small) */
    int depth;       /* vertices on the hull stack */
    ss_hull_point top, second; /* cached copies of the two top stack slots */
} ss_walker;

/* The horizon of one cell as a vector in the vertical plane of the azimuth:
 * d > 0 is the distance along the azimuth to the casting cell and dz its
 * height above the viewer after curvature. With nothing ahead (the first
 * cell of a line) it is (0, -1): straight down, i.e. -90 degrees. */
typedef struct {
    int cell;  /* grid index of the cell just walked */
    int col, row;
    int valid; /* 0: nodata cell; it neither gets a horizon nor occludes */
    float d, dz;
} ss_cell_horizon;

SS_FN int ss_walker_cell_at(const ss_line_set *ls, const ss_walker *w, int s, int *minor)
{
    int major = ss_line_major_at(ls, w->first, w->count, s);
    *minor = ss_line_minor(ls, w->b, major);
    return ss_line_cell(ls, major, *minor);
}

/* Starts line number `line`; returns its number of cells. */
SS_FN int ss_walker_begin(ss_walker *w, const ss_line_set *ls, int line)
{
    w->b = ls->line_min + line;
    w->count = ss_line_extent(ls, line, &w->first);
    w->next = 0;
    w->depth = 0;
    w->origin_s = w->count / 2;
    w->origin_minor = 0;
    if (w->count > 0)
        ss_walker_cell_at(ls, w, w->origin_s, &w->origin_minor);
    return w->count;
}

/* Position of a cell along the walk, metres from the origin cell. */
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

/* Bent-height difference z~_t - z~_v of hull point t over v at distance d. */
SS_FN float ss_hull_rise(ss_hull_point v, ss_hull_point t, float d, float curv_k)
{
    return (t.z - v.z) + curv_k * d * (t.x + v.x);
}

SS_FN ss_hull_point ss_walker_load(const ss_line_set *ls, const ss_walker *w,
                                   SS_GLOBAL const float *z, SS_GLOBAL const int *stack,
                                   int slot)
{
    int slot_minor;
    ss_hull_point p;
    p.s = stack[ss_walker_cell_at(ls, w, slot, &slot_minor)];
    int cell = ss_walker_cell_at(ls, w, p.s, &p.minor);
    p.x = ss_walker_along(ls, w, p.s, p.minor);
    p.z = z[cell];
    return p;
}

/* Walks the next cell of the line and returns its horizon. */
SS_FN ss_cell_horizon ss_walker_step(ss_walker *w, const ss_line_set *ls, SS_GLOBAL const float *z,
                                SS_GLOBAL int *stack, float curv_k)
{
    ss_cell_horizon h;
    int s = w->next++;
    int minor;
    int major = ss_line_major_at(ls, w->first, w->count, s);
    minor = ss_line_minor(ls, w->b, major);
    h.cell = ss_line_cell(ls, major, minor);
    h.col = ls->major_is_row ? minor : major;
    h.row = ls->major_is_row ? major : minor;
    h.d = 0.0f;
    h.dz = -1.0f;
    float zv = z[h.cell];
    h.valid = SS_ISFINITE(zv) ? 1 : 0;
    if (!h.valid)
        return h;

    ss_hull_point v;
    v.s = s;
    v.minor = minor;
    v.x = ss_walker_along(ls, w, s, minor);
    v.z = zv;
    if (w->depth > 0) {
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
        h.dz = (w->top.z - v.z) - curv_k * d1 * d1;
    }
    int slot_minor;
    stack[ss_walker_cell_at(ls, w, w->depth, &slot_minor)] = s;
    w->second = w->top;
    w->top = v;
    w->depth++;
    return h;
}

#endif
