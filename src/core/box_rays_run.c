#include "config.h"

#include <stdlib.h>

#include "box_rays_run.h"

ss_status ss_box_rays_begin(ss_ctx *ctx, const ss_source *src, float sign, ss_box_rays_run *run)
{
    const float *z;
    ss_status st = ss_source_heights(ctx, src, &run->owned, &z);
    if (st != SS_OK)
        return st;
    run->grid = (ss_grid){src->width, src->height, src->cell_x_m, src->cell_y_m, 0.0, (float *)z};
    run->band_rows = ss_source_band_rows(src);
    run->tops = ss_box_sky_tops_new(&run->grid, sign);
    if (run->tops)
        return SS_OK;
    free(run->owned);
    run->owned = NULL;
    return ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the tops of %d x %d cells", src->width,
                   src->height);
}

void ss_box_rays_end(ss_box_rays_run *run)
{
    ss_box_sky_tops_free(run->tops);
    free(run->owned);
}

static int band_rows_at(const ss_box_rays_run *run, int row0)
{
    int left = run->grid.height - row0;
    return left < run->band_rows ? left : run->band_rows;
}

ss_band_view ss_box_rays_band(const ss_box_rays_run *run, int row0)
{
    const ss_grid *g = &run->grid;
    return (ss_band_view){.row0 = row0,
                          .n_rows = band_rows_at(run, row0),
                          .lo = 0,
                          .held_rows = g->height,
                          .width = g->width,
                          .height = g->height,
                          .z = g->z,
                          .own_z = g->z + (size_t)row0 * g->width};
}
