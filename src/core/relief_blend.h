/* RVT's VAT relief blend of rows (relief_blend.c). */
#ifndef SS_RELIEF_BLEND_H
#define SS_RELIEF_BLEND_H

#include "skysweep.h"

/* The VAT blend (0..1, SS_NODATA at nodata) of rows [row0, row1) of grid
 * into out, from those rows' geometric SVF and positive openness. */
void ss_vat_rows(const ss_grid *grid, int row0, int row1, const float *svf,
                 const float *openness, float *out);

#endif
