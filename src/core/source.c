/* A run's source of heights (engine.h): a grid held in memory or a reader
 * of rows, and what the driver and the products ask of it. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "engine.h"

ss_source ss_source_of_grid(const ss_grid *grid)
{
    ss_source src = {.width = grid->width,
                     .height = grid->height,
                     .cell_x_m = grid->cell_x_m,
                     .cell_y_m = grid->cell_y_m,
                     .z_origin_m = &grid->z_origin_m,
                     .z = grid->z};
    return src;
}

int ss_source_band_rows(const ss_source *src)
{
    return src->band_rows > 0 && src->band_rows < src->height ? src->band_rows : src->height;
}

double ss_source_origin(const ss_source *src)
{
    return src->z_origin_m ? *src->z_origin_m : 0.0;
}

ss_status ss_source_check(ss_ctx *ctx, const ss_source *src)
{
    /* Heights in memory are checked as a grid's: sizes, cell sizes and
     * heights, at least one of them valid. A reader's show themselves as
     * they are read (ss_engine_run refuses a DEM with no valid height). */
    if (src && src->z) {
        ss_grid g = {src->width, src->height, src->cell_x_m, src->cell_y_m,
                     ss_source_origin(src), (float *)src->z};
        ss_status st = ss_grid_check(ctx, &g, NULL);
        if (st != SS_OK)
            return st;
    }
    if (!src || src->width < 1 || src->height < 1 || (src->width < 2 && src->height < 2) ||
        !(src->cell_x_m > 0) || !(src->cell_y_m > 0) || !isfinite(src->cell_x_m) ||
        !isfinite(src->cell_y_m) || (!src->z && !src->read) || src->band_rows < 0)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "a DEM needs at least 2 cells, positive cell sizes, heights or a reader of "
                       "rows, and 0 or more rows per band");
    if ((double)src->width * (double)src->height > 2147483647.0)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "a DEM of %d x %d cells is beyond 2^31 cells",
                       src->width, src->height);
    return SS_OK;
}

ss_status ss_source_read_rows(ss_ctx *ctx, const ss_source *src, int lo, int n, float *out)
{
    size_t w = (size_t)src->width;
    if (src->z) {
        memcpy(out, src->z + (size_t)lo * w, (size_t)n * w * sizeof(float));
        return SS_OK;
    }
    unsigned long failures = ctx->failures;
    ss_status st = src->read(src->read_user, lo, n, out);
    if (st != SS_OK && ctx->failures == failures) /* else the reader's own message */
        st = ss_fail(ctx, st, "could not read DEM rows %d..%d", lo, lo + n - 1);
    return st;
}

/* Infinite heights as nodata, as ss_grid_check counts them: a ray's
 * comparisons would meet an infinite top as a wall. */
static void infinities_to_nodata(float *z, size_t n)
{
    for (size_t c = 0; c < n; ++c)
        if (isinf(z[c]))
            z[c] = NAN;
}

static int any_infinite(const float *z, size_t n)
{
    for (size_t c = 0; c < n; ++c)
        if (isinf(z[c]))
            return 1;
    return 0;
}

ss_status ss_source_heights(ss_ctx *ctx, const ss_source *src, float **owned, const float **z)
{
    ss_call_begin(ctx);
    *owned = NULL;
    *z = NULL;
    ss_status st = ss_source_check(ctx, src); /* heights held: at least one valid */
    if (st != SS_OK)
        return st;
    size_t w = (size_t)src->width;
    *z = src->z;
    if (src->z && !any_infinite(src->z, w * src->height))
        return SS_OK;
    float *all = ss_malloc(w * src->height * sizeof(float));
    if (!all)
        return ss_fail(ctx, SS_ERR_MEMORY,
                       "out of memory for the DEM's heights held whole (%.0f MiB)",
                       (double)(w * src->height * sizeof(float)) / 1048576.0);
    if (src->z) {
        memcpy(all, src->z, w * src->height * sizeof(float));
    } else { /* read as the bands are, so that the reader needs no more */
        int rows = ss_source_band_rows(src);
        for (int r = 0; r < src->height && st == SS_OK; r += rows) {
            int n = src->height - r < rows ? src->height - r : rows;
            st = ss_source_read_rows(ctx, src, r, n, all + (size_t)r * w);
            if (st == SS_OK)
                st = ss_check_cancel(ctx, "reading the heights");
        }
    }
    infinities_to_nodata(all, w * src->height);
    int any_height = 0;
    for (size_t c = 0; st == SS_OK && !any_height && c < w * src->height; ++c)
        any_height = isfinite(all[c]);
    if (st == SS_OK && !any_height)
        st = ss_fail(ctx, SS_ERR_INPUT, "the DEM holds no valid height: every cell is nodata");
    if (st != SS_OK) {
        free(all);
        return st;
    }
    *owned = all;
    *z = all;
    return SS_OK;
}
