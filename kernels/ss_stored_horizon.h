/* Interpolated shadows' stored horizons (shared by kernels and C): each
 * stored direction's horizon angle per cell, in hundredths of a degree as
 * a 16-bit integer (0.005 degrees of rounding, half the bytes of a float),
 * and a cell's horizon at an azimuth between two stored directions. The
 * host's steps (src/core/insolation_lanes.h), the cumulative sky and the
 * device's steps (ss_insolation_cells.h) all read them through these. */
#ifndef SS_STORED_HORIZON_H
#define SS_STORED_HORIZON_H

#include "ss_compat.h"

#define SS_HORIZON_SCALE 100.0f

/* A stored horizon in degrees. */
SS_FN float ss_stored_horizon(short stored)
{
    return stored / SS_HORIZON_SCALE;
}

/* The horizon (degrees) weight t of the way from stored direction h0's to
 * the next one's, h1: unfused on a device as on the host (whose lanes
 * turn contraction off), so both test each cell's sun against the same
 * float. */
SS_FN float ss_stored_horizon_between(short h0, short h1, float t)
{
#ifdef __OPENCL_VERSION__
#pragma OPENCL FP_CONTRACT OFF
#endif
    return ((1.0f - t) * h0 + t * h1) / SS_HORIZON_SCALE;
}

#endif
