/* What a walk by each cell's own ray holds while it runs band by band
 * (horizon_walk.c, sky_walk.c): the heights whole, as a grid, the tops its
 * rays stop by, and the band views it hands the consumers. */
#ifndef SS_BOX_RAYS_RUN_H
#define SS_BOX_RAYS_RUN_H

#include "box_sky.h"
#include "products_internal.h"

typedef struct {
    float *owned;          /* the copy of the heights, where one was made */
    ss_grid grid;          /* the heights held whole: only read */
    ss_box_sky_tops *tops; /* of the heights times the run's sign */
    int band_rows;         /* the source's */
} ss_box_rays_run;

/* The source's heights and their tops times sign (1, or -1 for negative
 * openness); on failure nothing is left to free. */
ss_status ss_box_rays_begin(ss_ctx *ctx, const ss_source *src, float sign, ss_box_rays_run *run);
void ss_box_rays_end(ss_box_rays_run *run);

/* The band at row0 (band_rows rows, fewer at the grid's end) as a
 * consumer sees it: every row held. */
ss_band_view ss_box_rays_band(const ss_box_rays_run *run, int row0);

#endif
