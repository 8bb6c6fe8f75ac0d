/* Box lines: what a line meets in one step when every cell is a
 * flat-topped column (shared by kernels and C; doc/model.md, "City DSMs").
 *
 * Seen from a point, a column's top subtends its largest elevation at an
 * edge: the near edge when it stands above the point, the far edge when
 * below. So along a line, the column tops it crosses are represented
 * exactly by a point at every column boundary it crosses, with the taller
 * of the two columns there. A step of a line (one major index) meets:
 *   - the boundary with the previous step's column (across the major axis),
 *   - at most one boundary across the minor axis (|slope| <= 1),
 *   - the centre of its nearest cell, projected on the line: a point of
 *     that cell's top, so taking it into the hull changes no horizon, and
 *     its tangent is the cell's horizon along this line.
 * The line runs beside the centre by delta (its minor offset there); a cell
 * takes its horizon from the one line of all families that runs nearest,
 * within half a family spacing. */
#ifndef SS_BOX_H
#define SS_BOX_H

#include "ss_lines.h"

#define SS_BOX_FAR 0     /* the boundary with the previous step's column */
#define SS_BOX_CROSS 1   /* the boundary across the minor axis inside the step */
#define SS_BOX_CENTRE 2  /* the nearest cell's centre */
#define SS_BOX_EVENTS 3  /* points a step may meet: also stack slots per home cell */

typedef struct {
    float u;  /* position along the walk in steps from the origin step */
    float m;  /* minor offset of a centre from the line (cells; 0 for boundaries) */
    float z;  /* the point's height */
    int kind; /* SS_BOX_* */
} ss_box_point;

typedef struct {
    ss_box_point p[SS_BOX_EVENTS]; /* in walk order */
    int n;
    int centre_cell; /* buffer index of the nearest cell, -1 outside the grid */
    int owned;       /* 1: this line is the cell's nearest of all families */
} ss_box_step;

/* The nearest integer of a position in units of 2^-17 cell (ties up). */
SS_FN int ss_box_cell17(ss_i64 p)
{
    return (int)(((p + 65536 + ((ss_i64)1 << 49)) >> 17) - ((ss_i64)1 << 32));
}

/* The taller finite height of cells (major, minor_a) and (major_b,
 * minor_b) of the grid; 0 when neither is in the grid with a height. */
SS_FN int ss_box_taller(const ss_line_set *ls, SS_GLOBAL const float *z, int major_a, int minor_a,
                        int major_b, int minor_b, float *h)
{
    int found = 0;
    int majors[2] = {major_a, major_b}, minors[2] = {minor_a, minor_b};
    for (int k = 0; k < 2; ++k) {
        if (majors[k] < 0 || majors[k] >= ls->major_len || minors[k] < 0 ||
            minors[k] >= ls->minor_len)
            continue;
        float v = z[ss_line_cell(ls, majors[k], minors[k])];
        if (SS_ISFINITE(v) && (!found || v > *h)) {
            *h = v;
            found = 1;
        }
    }
    return found;
}

/* The points step s_rel (steps from the origin) of a line meets at major
 * index `major`, where the line's position is y16 (16.16, plus one half:
 * box lines round to the nearest cell) and moves by dy16 per step. */
SS_FN ss_box_step ss_box_step_at(const ss_line_set *ls, SS_GLOBAL const float *z, int major,
                                 ss_i64 y16, ss_i64 dy16, int dmajor, float s_rel)
{
    ss_box_step b;
    b.n = 0;
    ss_i64 minor0 = ss_floor16(y16);
    ss_i64 delta16 = y16 - 32768 - minor0 * 65536; /* in [-1/2, 1/2) cell */
    ss_i64 far17 = 2 * (y16 - 32768) - dy16, near17 = 2 * (y16 - 32768) + dy16;
    int r_far = ss_box_cell17(far17), r_near = ss_box_cell17(near17);
    float h = 0.0f;
    if (ss_box_taller(ls, z, major - dmajor, r_far, major, r_far, &h)) {
        ss_box_point p = {s_rel - 0.5f, 0.0f, h, SS_BOX_FAR};
        b.p[b.n++] = p;
    }
    int has_cross = r_far != r_near && ss_box_taller(ls, z, major, r_far, major, r_near, &h);
    ss_box_point cross = {0.0f, 0.0f, h, SS_BOX_CROSS};
    if (has_cross) {
        ss_i64 edge17 = (ss_i64)(r_far > r_near ? r_far : r_near) * 131072 - 65536;
        cross.u = s_rel - 0.5f + (float)(edge17 - far17) / (float)(near17 - far17);
    }
    int in = minor0 >= 0 && minor0 < ls->minor_len;
    b.centre_cell = in ? ss_line_cell(ls, major, (int)minor0) : -1;
    ss_i64 half_spacing = 32768 / ls->families;
    b.owned = in && delta16 >= -half_spacing && delta16 < half_spacing;
    float zc = in ? z[b.centre_cell] : 0.0f;
    ss_box_point centre = {s_rel, (float)(-delta16) * (1.0f / 65536.0f), zc, SS_BOX_CENTRE};
    int has_centre = in && SS_ISFINITE(zc);
    /* The centre goes first on a tie, so every point it sees lies ahead. */
    int centre_first = !has_cross || centre.u * ls->along_per_step_m +
                                             centre.m * ls->along_per_minor_m <=
                                         cross.u * ls->along_per_step_m;
    if (has_centre && centre_first)
        b.p[b.n++] = centre;
    if (has_cross)
        b.p[b.n++] = cross;
    if (has_centre && !centre_first)
        b.p[b.n++] = centre;
    return b;
}

#endif
