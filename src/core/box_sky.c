/* The box model's sky view by each cell's own ray (box_sky.h). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "box_sky.h"
#include "ctx_internal.h" /* ss_malloc */
#include "ss_terms.h"

/* A square a ray crosses: its place from the ray's cell in the heights,
 * and the metres from the cell's centre where the ray enters it. (A top
 * below the eye would show where the ray leaves its square, but never
 * above the eye's own top, at 0 degrees: only tops above the eye count.) */
typedef struct {
    ptrdiff_t offset;
    double t_in;
} sky_square;

/* The squares every ray toward one azimuth crosses, in order, until it is
 * a grid's width or height away from its cell (no ray of the grid goes
 * farther): at most width + height of them. The offsets' columns and rows
 * move by sx and sy, never back: within_x[m] squares lie at most m
 * columns from the cell (m < width), within_y[m] at most m rows, so a ray
 * from a cell m columns and m' rows from the grid's edge ahead crosses the
 * first min(within_x[m], within_y[m']) of them in the grid. */
typedef struct {
    sky_square *sq;
    int sx, sy;
    int *within_x, *within_y;
    float sin_az, cos_az;
} sky_ray;

/* The squares of a ray toward grid azimuth az_rad (ss_box_sky_add's
 * traversal). Returns 0 when out of memory. */
static int sky_ray_init(sky_ray *ray, const ss_grid *g, double az_rad)
{
    double col_per_m = sin(az_rad) / g->cell_x_m, row_per_m = -cos(az_rad) / g->cell_y_m;
    double step_x = col_per_m != 0.0 ? 1.0 / fabs(col_per_m) : INFINITY;
    double step_y = row_per_m != 0.0 ? 1.0 / fabs(row_per_m) : INFINITY;
    double tx = 0.5 * step_x, ty = 0.5 * step_y;
    ray->sx = col_per_m > 0.0 ? 1 : -1;
    ray->sy = row_per_m > 0.0 ? 1 : -1;
    ray->sin_az = (float)sin(az_rad);
    ray->cos_az = (float)cos(az_rad);
    ray->sq = ss_malloc(sizeof *ray->sq * ((size_t)g->width + (size_t)g->height));
    ray->within_x = ss_malloc(sizeof(int) * (size_t)g->width);
    ray->within_y = ss_malloc(sizeof(int) * (size_t)g->height);
    if (!ray->sq || !ray->within_x || !ray->within_y)
        return 0;
    int n = 0, dc = 0, dr = 0;
    double t_in = fmin(tx, ty); /* where the ray leaves its own square */
    for (;;) {
        if (tx < ty) {
            ray->within_x[abs(dc)] = n;
            dc += ray->sx;
            tx += step_x;
        } else {
            ray->within_y[abs(dr)] = n;
            dr += ray->sy;
            ty += step_y;
        }
        if (abs(dc) >= g->width || abs(dr) >= g->height)
            break;
        ray->sq[n++] = (sky_square){(ptrdiff_t)dr * g->width + dc, t_in};
        t_in = fmin(tx, ty);
    }
    /* Columns (rows) the ray never reaches hold every square. */
    for (int m = abs(dc); m < g->width; ++m)
        ray->within_x[m] = n;
    for (int m = abs(dr); m < g->height; ++m)
        ray->within_y[m] = n;
    return 1;
}

static void sky_ray_free(sky_ray *ray)
{
    free(ray->sq);
    free(ray->within_x);
    free(ray->within_y);
}

struct ss_box_sky_tops {
    double top;       /* the highest of sign * height over the grid */
    int across, down; /* blocks */
    float *block_top; /* across * down, -INFINITY where no heights */
};

#define SKY_BLOCK 32

/* The highest of sign * z over columns [c0, c1] of one row. */
static float row_top(const float *z, int c0, int c1, float sign)
{
    float top = -INFINITY;
    for (int c = c0; c <= c1; ++c)
        if (sign * z[c] > top) /* false at NaN */
            top = sign * z[c];
    return top;
}

ss_box_sky_tops *ss_box_sky_tops_new(const ss_grid *g, float sign)
{
    int w = g->width, h = g->height;
    ss_box_sky_tops *tops = ss_calloc(1, sizeof *tops);
    if (!tops)
        return NULL;
    tops->across = (w + SKY_BLOCK - 1) / SKY_BLOCK;
    tops->down = (h + SKY_BLOCK - 1) / SKY_BLOCK;
    /* Each row's highest over each block's columns. */
    float *rows = ss_malloc(sizeof(float) * (size_t)h * (size_t)tops->across);
    tops->block_top = ss_malloc(sizeof(float) * (size_t)tops->across * (size_t)tops->down);
    if (!rows || !tops->block_top) {
        free(rows);
        ss_box_sky_tops_free(tops);
        return NULL;
    }
    for (int r = 0; r < h; ++r)
        for (int b = 0; b < tops->across; ++b) {
            int c0 = b * SKY_BLOCK, c1 = c0 + SKY_BLOCK - 1;
            rows[(size_t)r * tops->across + b] =
                row_top(g->z + (size_t)r * w, c0, c1 < w - 1 ? c1 : w - 1, sign);
        }
    tops->top = -INFINITY;
    for (int by = 0; by < tops->down; ++by)
        for (int b = 0; b < tops->across; ++b) {
            int r0 = by * SKY_BLOCK, r1 = r0 + SKY_BLOCK - 1;
            float top = -INFINITY;
            for (int r = r0; r <= r1 && r < h; ++r)
                top = fmaxf(top, rows[(size_t)r * tops->across + b]);
            tops->block_top[(size_t)by * tops->across + b] = top;
            tops->top = fmax(tops->top, top);
        }
    free(rows);
    return tops;
}

void ss_box_sky_tops_free(ss_box_sky_tops *tops)
{
    if (tops)
        free(tops->block_top);
    free(tops);
}

/* The tangent of cell (col, row)'s box horizon along the ray, never below
 * 0 (its own top reaches its edge). The walk goes block by block: the
 * squares of the list from where the ray crosses into a block to where it
 * crosses out are that block's, so where the block's highest top does not
 * rise above best at the first of them, none does. The blocks only pass
 * over squares that could not change best: the answer is the whole
 * walk's, bit for bit. */
static double box_tangent(const ss_grid *g, const sky_ray *ray, const ss_box_sky_tops *tops,
                          int col, int row, float sign, double curv_k)
{
    int ahead_x = ray->sx > 0 ? g->width - 1 - col : col;
    int ahead_y = ray->sy > 0 ? g->height - 1 - row : row;
    int n = ray->within_x[ahead_x] < ray->within_y[ahead_y] ? ray->within_x[ahead_x]
                                                             : ray->within_y[ahead_y];
    const float *z = g->z + (size_t)row * g->width + col;
    const sky_square *sq = ray->sq;
    double eye = sign * z[0], room = tops->top - eye, best = 0.0;
    /* No top ahead can rise above best once room <= best * t_in, that is
     * past t_in = room / best: the squares' t_in grow, and a top shows at
     * t_in or beyond. */
    double stop = room > 0.0 ? INFINITY : 0.0;
    /* The ray's block, and the columns and rows it leaves the block by, as
     * counted from its cell (within_x's and within_y's m). */
    int bx = col / SKY_BLOCK, by = row / SKY_BLOCK;
    int last_x = ray->sx > 0 ? SKY_BLOCK - 1 - (col - bx * SKY_BLOCK) : col - bx * SKY_BLOCK;
    int last_y = ray->sy > 0 ? SKY_BLOCK - 1 - (row - by * SKY_BLOCK) : row - by * SKY_BLOCK;
    for (int k = 0; k < n && sq[k].t_in < stop;) {
        /* The block's squares end where the list first crosses out of its
         * last column or its last row (n past the grid's). */
        int end_x = last_x < g->width ? ray->within_x[last_x] : n;
        int end_y = last_y < g->height ? ray->within_y[last_y] : n;
        int by_x = end_x < end_y, end = by_x ? end_x : end_y;
        end = end < n ? end : n;
        if (tops->block_top[(size_t)by * tops->across + bx] - eye <= best * sq[k].t_in) {
            k = end > k ? end : k;
        } else {
            /* A top at or below the eye cannot pass best * t >= 0, nor can
             * nodata (NaN): no branch on them. */
            for (; k < end && sq[k].t_in < stop; ++k) {
                double t = sq[k].t_in, rise = sign * z[sq[k].offset] - eye - curv_k * t * t;
                if (rise > best * t) {
                    best = rise / t;
                    stop = room / best;
                }
            }
        }
        if (by_x) {
            bx += ray->sx;
            last_x += SKY_BLOCK;
        } else {
            by += ray->sy;
            last_y += SKY_BLOCK;
        }
        if (bx < 0 || bx >= tops->across || by < 0 || by >= tops->down)
            break; /* the ray has left the grid: k == n */
    }
    return best;
}

int ss_box_sky_add(const ss_grid *grid, int n_dirs, const double *grid_azimuth_deg,
                   int definition, float sign, const ss_box_sky_tops *tops, double curv_k,
                   int row0, int n_rows, const float *grad, const volatile sig_atomic_t *cancel,
                   float *sums)
{
    /* The directions' squares listed once for all the rows, so that each
     * cell's rays run together over the heights around it. */
    sky_ray *rays = ss_calloc((size_t)n_dirs, sizeof *rays);
    int ok = rays != NULL;
    for (int d = 0; ok && d < n_dirs; ++d)
        ok = sky_ray_init(&rays[d], grid, grid_azimuth_deg[d] * (M_PI / 180.0));
    int w = grid->width;
#pragma omp parallel for schedule(dynamic, 4) if (ok)
    for (int r = row0; r < row0 + n_rows; ++r) {
        for (int c = 0; ok && c < w && !(cancel && *cancel); ++c) {
            if (!isfinite(grid->z[(size_t)r * w + c]))
                continue;
            size_t own = (size_t)(r - row0) * w + c;
            float de = grad ? grad[2 * own] : 0.0f, dn = grad ? grad[2 * own + 1] : 0.0f;
            float sum = sums[own];
            for (int d = 0; d < n_dirs; ++d) {
                double t = box_tangent(grid, &rays[d], tops, c, r, sign, curv_k);
                sum += ss_sky_walk_term(definition, 1.0f, (float)t, rays[d].sin_az,
                                        rays[d].cos_az, de, dn);
            }
            sums[own] = sum;
        }
    }
    for (int d = 0; rays && d < n_dirs; ++d)
        sky_ray_free(&rays[d]);
    free(rays);
    return ok;
}
