/* OpenCL entry points: one work-item per line of one direction. The work
 * itself is in ss_passes.h, which the C twin runs too. */
#include "ss_passes.h"

__kernel void sweep_svf(ss_line_set ls, int definition, float curv_k, float sin_az, float cos_az,
                     float cell_x_m, float cell_y_m, int height, __global const float *z,
                     __global int *stack, __global float *acc)
{
    int line = get_global_id(0);
    if (line < ls.n_lines)
        ss_pass_svf(&ls, line, definition, curv_k, sin_az, cos_az, cell_x_m, cell_y_m, height,
                    z, stack, acc);
}

__kernel void sweep_horizon(ss_line_set ls, float curv_k, __global const float *z,
                         __global int *stack, __global float *angle_deg,
                         __global float *dist_m, int want_dist)
{
    int line = get_global_id(0);
    if (line < ls.n_lines)
        ss_pass_horizon(&ls, line, curv_k, z, stack, angle_deg, dist_m, want_dist);
}

__kernel void sweep_bare(ss_line_set ls, __global const float *z, __global float *out)
{
    int line = get_global_id(0);
    if (line < ls.n_lines)
        ss_pass_bare(&ls, line, z, out);
}
