/* A time step's sun at a cell from a lattice of nodes (skysweep.h,
 * ss_sun_lattice; shared by kernels and C): bilinear between the nodes,
 * with SPA's refraction computed per cell where the sun is down at any of
 * the four nodes around it (refraction bends too sharply there to
 * interpolate). The host interpolates runs of cells
 * (src/core/sun_lattice.c); a device's work-item takes one cell
 * (ss_lattice_sun_at). Both compute each cell's value with these
 * functions: the same bits where the device has doubles and does not fuse
 * a multiply and add (OpenCL may), else within their rounding. Degrees
 * throughout. */
#ifndef SS_SUN_LATTICE_H
#define SS_SUN_LATTICE_H

#include "ss_compat.h"

/* The lattice's arithmetic: double on the host and on devices that have
 * it, else float. The host says which when it builds the kernels
 * (SS_REAL_DOUBLE), and hands the device its nodes in that type. SS_R
 * writes a constant in it. */
#ifdef __OPENCL_VERSION__
#if SS_REAL_DOUBLE
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double ss_real;
#define SS_R(x) x
#else
typedef float ss_real;
#define SS_R(x) SS_R_FLOAT(x)
#define SS_R_FLOAT(x) x##f
#endif
#else
typedef double ss_real;
#define SS_R(x) x
#endif

#define SS_SUN_RADIUS_DEG 0.26667 /* SPA's semidiameter for rise, set and refraction */

/* SPA's refraction (step 13: Saemundsson's formula scaled by pressure, hPa,
 * and temperature, C) of a sun at true elevation e0; none below the sun's
 * setting at atmos_refract_deg. */
SS_FN ss_real ss_refraction_deg(ss_real e0, ss_real pressure_hpa, ss_real temperature_c,
                                ss_real atmos_refract_deg)
{
    if (e0 < -(SS_R(SS_SUN_RADIUS_DEG) + atmos_refract_deg))
        return SS_R(0.0);
    const ss_real rad = SS_R(3.14159265358979323846) / SS_R(180.0);
    return (pressure_hpa / SS_R(1010.0)) * (SS_R(283.0) / (SS_R(273.0) + temperature_c)) *
           SS_R(1.02) / (SS_R(60.0) * tan(rad * (e0 + SS_R(10.3) / (e0 + SS_R(5.11)))));
}

/* x's place between lattice columns or rows a and b (0 where they
 * coincide). */
SS_FN ss_real ss_lattice_between(int x, int a, int b)
{
    return b > a ? (ss_real)(x - a) / (ss_real)(b - a) : SS_R(0.0);
}

/* The value a fraction t of the way from a to b. */
SS_FN ss_real ss_lattice_blend(ss_real t, ss_real a, ss_real b)
{
    return (SS_R(1.0) - t) * a + t * b;
}

/* A lattice as a device holds it: node (i, j) at j * n_cols + i of each
 * of the three node arrays, and the air for refraction. */
typedef struct {
    int n_cols, n_rows;
    SS_GLOBAL const int *cols, *rows;
    SS_GLOBAL const ss_real *azimuth, *elevation, *refraction;
    ss_real pressure_hpa, temperature_c, atmos_refract_deg;
} ss_lattice_view;

/* Cell (row, col)'s grid azimuth, true and apparent elevation. The cell
 * takes the segment of lattice columns it starts (the last column the last
 * segment's end), and the segment of rows as the host's runs do. */
SS_FN void ss_lattice_sun_at(const ss_lattice_view *l, int row, int col, float *azimuth,
                             float *elevation, float *apparent)
{
    int j = 0, i = 0;
    while (j + 2 < l->n_rows && l->rows[j + 1] < row)
        ++j;
    while (i + 2 < l->n_cols && l->cols[i + 1] <= col)
        ++i;
    ss_real ty = ss_lattice_between(row, l->rows[j], l->rows[j + 1]);
    ss_real t = ss_lattice_between(col, l->cols[i], l->cols[i + 1]);
    int a = j * l->n_cols + i, b = a + 1, d = a + l->n_cols, e = d + 1;
    ss_real az0 = ss_lattice_blend(ty, l->azimuth[a], l->azimuth[d]);
    ss_real az1 = ss_lattice_blend(ty, l->azimuth[b], l->azimuth[e]);
    ss_real e00 = ss_lattice_blend(ty, l->elevation[a], l->elevation[d]);
    ss_real e01 = ss_lattice_blend(ty, l->elevation[b], l->elevation[e]);
    ss_real e0 = ss_lattice_blend(t, e00, e01);
    int smooth =
        l->elevation[a] > 0 && l->elevation[b] > 0 && l->elevation[d] > 0 && l->elevation[e] > 0;
    ss_real refraction =
        smooth ? ss_lattice_blend(t, ss_lattice_blend(ty, l->refraction[a], l->refraction[d]),
                                  ss_lattice_blend(ty, l->refraction[b], l->refraction[e]))
               : ss_refraction_deg(e0, l->pressure_hpa, l->temperature_c, l->atmos_refract_deg);
    *azimuth = (float)ss_lattice_blend(t, az0, az1);
    *elevation = (float)e0;
    *apparent = (float)(e0 + refraction);
}

#endif
