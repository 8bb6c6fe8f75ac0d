/* A cell's terms for insolation's steps (kernels/ss_cell_step.h holds
 * what one step adds to a cell, shared with the device). */
#ifndef SS_INSOLATION_CELL_H
#define SS_INSOLATION_CELL_H

#include <math.h>

#include "ss_cell_step.h"

/* The terms of a cell from its gradient, radiative SVF and height above
 * the datum. */
static inline ss_cell_terms ss_cell_terms_of(float dz_de, float dz_dn, float sky_view,
                                             double height_m)
{
    ss_cell_terms t;
    t.dz_de = dz_de;
    t.dz_dn = dz_dn;
    t.sky_view = sky_view;
    float slope = atanf(sqrtf(dz_de * dz_de + dz_dn * dz_dn));
    t.slope_term = ss_muneer_slope_term(slope);
    t.sin_tilt = sinf(slope);
    t.band_seen = 1.0f;
    t.normal_norm = sqrtf(1.0f + dz_de * dz_de + dz_dn * dz_dn);
    /* Air pressure relative to sea level (ESRA's p/p0). No dry land lies
     * below -1000 m, and far below it the factor overflows: a DEM of
     * bathymetry or fill values gets the -1000 m air. */
    t.pressure_factor = (float)exp(-fmax(height_m, -1000.0) / 8434.5);
    return t;
}

#endif
