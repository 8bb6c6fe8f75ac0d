/* The DEM in memory and the checks that make a grid sweepable. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "backend.h"

/* Beyond these a cell size is not a DEM's (and products of sizes would lose
 * float precision); 1e-6 m to 1e7 m covers microtopography to continents. */
#define SS_CELL_MIN_M 1e-6
#define SS_CELL_MAX_M 1e7
/* Heights (relative to z_origin_m) beyond this are not terrain; products
 * of heights and distances then stay far from float overflow. */
#define SS_Z_ABS_MAX_M 1e7
/* The sweep forms cell indices and fixed-point line positions in 32 bits. */
#define SS_AXIS_MAX (1 << 24)

ss_status ss_grid_alloc(ss_ctx *ctx, ss_grid *grid, int width, int height, double cell_x_m,
                        double cell_y_m)
{
    ss_call_begin(ctx);
    grid->z = NULL;
    grid->width = width;
    grid->height = height;
    grid->cell_x_m = cell_x_m;
    grid->cell_y_m = cell_y_m;
    grid->z_origin_m = 0.0;
    if (width < 1 || height < 1 || width >= SS_AXIS_MAX || height >= SS_AXIS_MAX ||
        (double)width * height >= 2147483647.0)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "grid of %d x %d cells is outside what one sweep handles (1 to 2^31 "
                       "cells, each side below 2^24)",
                       width, height);
    size_t n = (size_t)width * (size_t)height;
    grid->z = ss_alloc_grid(n * sizeof(float));
    if (!grid->z)
        return ss_fail(ctx, SS_ERR_MEMORY, "cannot allocate %zu MB for a %d x %d grid",
                       n * sizeof(float) >> 20, width, height);
    for (size_t i = 0; i < n; ++i)
        grid->z[i] = NAN;
    return SS_OK;
}

void ss_grid_free(ss_grid *grid)
{
    if (grid) {
        free(grid->z);
        grid->z = NULL;
    }
}

float ss_grid_stored_height(ss_grid *grid, int *have_origin, double height_m)
{
    if (!(fabs(height_m) <= SS_Z_PLAUSIBLE_M))
        return NAN;
    if (!*have_origin) {
        grid->z_origin_m = nearbyint(height_m);
        *have_origin = 1;
    }
    return (float)(height_m - grid->z_origin_m);
}

void ss_grid_set_heights(ss_grid *grid, const double *heights_m, size_t *rejected)
{
    size_t n = (size_t)grid->width * (size_t)grid->height, bad = 0;
    int have_origin = 0;
    for (size_t i = 0; i < n; ++i) {
        grid->z[i] = ss_grid_stored_height(grid, &have_origin, heights_m[i]);
        bad += isfinite(heights_m[i]) && isnan(grid->z[i]);
    }
    if (rejected)
        *rejected = bad;
}

ss_status ss_grid_check(ss_ctx *ctx, const ss_grid *grid, size_t *valid_cells)
{
    ss_call_begin(ctx);
    if (!grid || !grid->z)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "no grid given");
    if (grid->width < 1 || grid->height < 1 || grid->width >= SS_AXIS_MAX ||
        grid->height >= SS_AXIS_MAX || (double)grid->width * grid->height >= 2147483647.0)
        return ss_fail(ctx, SS_ERR_INPUT, "grid of %d x %d cells cannot be swept",
                       grid->width, grid->height);
    if (grid->width * grid->height < 2)
        return ss_fail(ctx, SS_ERR_INPUT,
                       "the DEM has a single cell: a 1 x 1 grid has no horizon to compute");
    if (!(grid->cell_x_m >= SS_CELL_MIN_M && grid->cell_x_m <= SS_CELL_MAX_M &&
          grid->cell_y_m >= SS_CELL_MIN_M && grid->cell_y_m <= SS_CELL_MAX_M))
        return ss_fail(ctx, SS_ERR_INPUT,
                       "cell size %g x %g m is not usable (each must be within %g..%g m)",
                       grid->cell_x_m, grid->cell_y_m, SS_CELL_MIN_M, SS_CELL_MAX_M);
    size_t n = (size_t)grid->width * (size_t)grid->height, valid = 0;
    for (size_t i = 0; i < n; ++i) {
        float z = grid->z[i];
        if (!isfinite(z))
            continue;
        if (fabsf(z) > SS_Z_ABS_MAX_M)
            return ss_fail(ctx, SS_ERR_INPUT,
                           "height %g m at column %zu, row %zu is beyond +-%g m of the grid "
                           "origin: not terrain (mark such cells as nodata)",
                           (double)z, i % (size_t)grid->width, i / (size_t)grid->width,
                           SS_Z_ABS_MAX_M);
        valid++;
    }
    if (valid == 0)
        return ss_fail(ctx, SS_ERR_INPUT, "the DEM has no valid heights (every cell is nodata)");
    if (valid_cells)
        *valid_cells = valid;
    return SS_OK;
}

/* Horn's gradient of every cell (backend.h): computed once per grid or band
 * instead of for both cells of every sample of every direction. */
void ss_gradient_grid(const ss_grid *g, float *out)
{
    float cx = (float)g->cell_x_m, cy = (float)g->cell_y_m;
#pragma omp parallel for schedule(static)
    for (int row = 0; row < g->height; ++row)
        for (int col = 0; col < g->width; ++col) {
            size_t c = (size_t)row * g->width + col;
            out[2 * c] = out[2 * c + 1] = 0.0f;
            if (isfinite(g->z[c]))
                ss_gradient_horn(g->z, g->width, g->height, col, row, cx, cy, &out[2 * c],
                                 &out[2 * c + 1]);
        }
}
