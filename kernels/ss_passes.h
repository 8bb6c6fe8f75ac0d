/* What one work-item does: walk one line of one direction and hand each
 * cell's horizon to a product. Shared by kernels/sweep.cl (one work-item
 * per line) and the C twin (src/core/backend_ref.c), so both run the same
 * code. A product is a few lines here; the walk and the hull are never
 * written again. */
#ifndef SS_PASSES_H
#define SS_PASSES_H

#include "ss_sweep.h"
#include "ss_terms.h"

/* Adds one direction's SVF term to acc for every valid cell of the line. */
SS_FN void ss_pass_svf(const ss_line_set *ls, int line, int definition, float curv_k,
                       float sin_az, float cos_az, float cell_x_m, float cell_y_m, int height,
                       SS_GLOBAL const float *z, SS_GLOBAL int *stack, SS_GLOBAL float *acc)
{
    ss_walker w;
    int n = ss_walker_begin(&w, ls, line);
    for (int i = 0; i < n; ++i) {
        ss_cell_horizon h = ss_walker_step(&w, ls, z, stack, curv_k);
        if (!h.valid)
            continue;
        float term;
        if (definition == SS_SVF_GEOMETRIC) {
            term = ss_svf_geometric_term(h.d, h.dz);
        } else if (definition == SS_SVF_HORIZONTAL) {
            term = ss_svf_horizontal_term(h.d, h.dz);
        } else {
            float dz_de, dz_dn;
            ss_gradient_horn(z, ls->width, height, h.col, h.row, cell_x_m, cell_y_m, &dz_de,
                             &dz_dn);
            term = ss_svf_tilted_term(h.d, h.dz, sin_az, cos_az, dz_de, dz_dn);
        }
        acc[h.cell] += term;
    }
}

/* Writes the horizon angle (degrees) and, if want_dist, the distance to the
 * casting cell (metres, 0 when nothing lies ahead) of every cell of the line. */
SS_FN void ss_pass_horizon(const ss_line_set *ls, int line, float curv_k,
                           SS_GLOBAL const float *z, SS_GLOBAL int *stack,
                           SS_GLOBAL float *angle_deg, SS_GLOBAL float *dist_m, int want_dist)
{
    ss_walker w;
    int n = ss_walker_begin(&w, ls, line);
    for (int i = 0; i < n; ++i) {
        ss_cell_horizon h = ss_walker_step(&w, ls, z, stack, curv_k);
        angle_deg[h.cell] = h.valid ? ss_horizon_deg(h.d, h.dz) : SS_NODATA_OUT;
        if (want_dist)
            dist_m[h.cell] = h.valid ? h.d : SS_NODATA_OUT;
    }
}

/* The bare pass: the same lines, each cell read and written once, no hull.
 * It is the yardstick for the sweep's cost (DESIGN.md, speed) and, with
 * z = 1, counts how often each cell is visited. */
SS_FN void ss_pass_bare(const ss_line_set *ls, int line, SS_GLOBAL const float *z,
                        SS_GLOBAL float *out)
{
    int first;
    int n = ss_line_extent(ls, line, &first);
    int b = ls->line_min + line;
    for (int s = 0; s < n; ++s) {
        int major = ss_line_major_at(ls, first, n, s);
        int cell = ss_line_cell(ls, major, ss_line_minor(ls, b, major));
        out[cell] += z[cell];
    }
}

#endif
