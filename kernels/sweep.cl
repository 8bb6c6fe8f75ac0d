/* OpenCL entry points: one work-item per line of one round of one
 * direction. The work itself is in ss_passes.h, which the C twin runs too. */
#include "ss_passes.h"

/* grad: the gradient grid for the radiative definition (any buffer for
 * the others, which do not read it). */
__kernel void sweep_svf(ss_line_set ls, int round, int definition, float curv_k, float sin_az,
                        float cos_az, float cell_x_m, float cell_y_m, int height,
                        __global const float *z, __global const float *grad,
                        __global int *stack, __global float *acc)
{
    int i = get_global_id(0);
    if (i < ss_round_lines(&ls, round))
        ss_pass_svf(&ls, ss_round_line(&ls, round, i), definition, curv_k, sin_az, cos_az,
                    cell_x_m, cell_y_m, height, z, grad, stack, acc);
}

__kernel void sweep_horizon(ss_line_set ls, int round, float curv_k, __global const float *z,
                            __global int *stack, __global float *angle_deg,
                            __global float *weight, __global float *dist_m,
                            __global float *cast_z, int want)
{
    int i = get_global_id(0);
    if (i < ss_round_lines(&ls, round))
        ss_pass_horizon(&ls, ss_round_line(&ls, round, i), curv_k, z, stack, angle_deg, weight,
                        dist_m, cast_z, want);
}

/* One work-item per cell, after both rounds of sweep_horizon. */
__kernel void sweep_horizon_finish(int n_cells, float none_deg, __global float *angle_deg,
                                   __global const float *weight)
{
    int cell = get_global_id(0);
    if (cell < n_cells)
        ss_pass_horizon_finish(cell, none_deg, angle_deg, weight);
}

__kernel void sweep_bare(ss_line_set ls, int round, __global const float *z,
                         __global float *out)
{
    int i = get_global_id(0);
    if (i < ss_round_lines(&ls, round))
        ss_pass_bare(&ls, ss_round_line(&ls, round, i), z, out);
}

__kernel void sweep_radius_terms(ss_line_set ls, int round, int definition, float radius_m,
                                 float curv_k, __global const float *z, __global float *acc)
{
    int i = get_global_id(0);
    if (i < ss_round_lines(&ls, round))
        ss_pass_radius_terms(&ls, ss_round_line(&ls, round, i), definition, radius_m, curv_k, z,
                             acc);
}
