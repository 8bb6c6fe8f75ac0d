/* The box model's sky view by each cell's own ray (box_sky.h). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "box_ray.h"
#include "box_sky_walk.h"
#include "ctx_internal.h" /* ss_malloc */
#include "ss_terms.h"

int ss_sky_ray_init(ss_sky_ray *ray, const ss_grid *g, double grid_azimuth_deg)
{
    double az = grid_azimuth_deg * (M_PI / 180.0);
    ray->sin_az = (float)sin(az);
    ray->cos_az = (float)cos(az);
    ray->sq = ss_malloc(sizeof *ray->sq * ((size_t)g->width + (size_t)g->height));
    ray->within_x = ss_malloc(sizeof(int) * (size_t)g->width);
    ray->within_y = ss_malloc(sizeof(int) * (size_t)g->height);
    box_frame f;
    if (!ray->sq || !ray->within_x || !ray->within_y || !box_frame_init(&f, g, grid_azimuth_deg))
        return 0;
    /* The box shadows' traversal (box_ray.h), from the corner the ray
     * crosses the whole grid from: it leaves the grid where it is the
     * grid's width or height from its cell. */
    box_ray r = box_ray_from(&f, f.col_per_m > 0.0 ? 0 : g->width - 1,
                             f.row_per_m > 0.0 ? 0 : g->height - 1);
    int col0 = r.col, row0 = r.row, n = 0, in_grid = 1;
    ray->t_own = r.tx < r.ty ? r.tx : r.ty;
    ray->sx = r.sx;
    ray->sy = r.sy;
    while (in_grid) {
        int dc = abs(r.col - col0), dr = abs(r.row - row0);
        in_grid = box_ray_next(&f, &r);
        if (abs(r.col - col0) != dc)
            ray->within_x[dc] = n;
        else
            ray->within_y[dr] = n;
        if (in_grid)
            ray->sq[n++] = (ss_sky_square){(ptrdiff_t)(r.row - row0) * g->width + (r.col - col0),
                                           r.t_in};
    }
    /* Columns (rows) the ray never reaches hold every square. */
    for (int m = abs(r.col - col0); m < g->width; ++m)
        ray->within_x[m] = n;
    for (int m = abs(r.row - row0); m < g->height; ++m)
        ray->within_y[m] = n;
    box_frame_free(&f);
    return 1;
}

void ss_sky_ray_free(ss_sky_ray *ray)
{
    free(ray->sq);
    free(ray->within_x);
    free(ray->within_y);
}

/* The highest of sign * z over columns [c0, c1] of one row, and the
 * highest finite one into *finite_top: an infinite height, which
 * ss_grid_check counts as nodata, still stops no walk early (room stays
 * finite, as it was before the blocks), and no block that holds one is
 * passed over, so the walk meets it as the whole walk would. */
static float row_top(const float *z, int c0, int c1, float sign, float *finite_top)
{
    float top = -INFINITY;
    for (int c = c0; c <= c1; ++c) {
        float v = sign * z[c];
        if (v > top) /* false at NaN */
            top = v;
        if (v > *finite_top && v < INFINITY)
            *finite_top = v;
    }
    return top;
}

ss_box_sky_tops *ss_box_sky_tops_new(const ss_grid *g, float sign)
{
    int w = g->width, h = g->height;
    ss_box_sky_tops *tops = ss_calloc(1, sizeof *tops);
    if (!tops)
        return NULL;
    tops->across = (w + SS_SKY_BLOCK - 1) / SS_SKY_BLOCK;
    tops->down = (h + SS_SKY_BLOCK - 1) / SS_SKY_BLOCK;
    size_t n = (size_t)tops->across * (size_t)tops->down;
    tops->block_top = ss_malloc(sizeof(float) * n);
    if (!tops->block_top) {
        ss_box_sky_tops_free(tops);
        return NULL;
    }
    for (size_t i = 0; i < n; ++i)
        tops->block_top[i] = -INFINITY;
    float finite_top = -INFINITY;
    for (int r = 0; r < h; ++r) {
        float *block_top = tops->block_top + (size_t)(r / SS_SKY_BLOCK) * tops->across;
        for (int b = 0; b < tops->across; ++b) {
            int c0 = b * SS_SKY_BLOCK, c1 = c0 + SS_SKY_BLOCK - 1;
            float top = row_top(g->z + (size_t)r * w, c0, c1 < w - 1 ? c1 : w - 1, sign,
                                &finite_top);
            block_top[b] = fmaxf(block_top[b], top);
        }
    }
    tops->top = finite_top;
    return tops;
}

void ss_box_sky_tops_free(ss_box_sky_tops *tops)
{
    if (tops)
        free(tops->block_top);
    free(tops);
}

/* The walk goes block by block: the squares of the list from where the
 * ray crosses into a block to where it crosses out are that block's, so
 * where the block's highest top does not rise above best at the first of
 * them, none does. The blocks only pass over squares that could not change
 * best: the answer is the whole walk's, bit for bit. */
double ss_sky_tangent(const ss_grid *g, const ss_sky_ray *ray, const ss_box_sky_tops *tops,
                      int col, int row, float sign, double curv_k, int *at)
{
    *at = -1;
    int n = ss_sky_ray_squares(g, ray, col, row);
    const float *z = g->z + (size_t)row * g->width + col;
    const ss_sky_square *sq = ray->sq;
    double eye = sign * z[0], room = tops->top - eye, best = 0.0;
    /* No top ahead can rise above best once room <= best * t_in, that is
     * past t_in = room / best: the squares' t_in grow, and a top shows at
     * t_in or beyond. */
    double stop = room > 0.0 ? INFINITY : 0.0;
    /* The ray's block, and the columns and rows it leaves the block by, as
     * counted from its cell (within_x's and within_y's m). */
    int bx = col / SS_SKY_BLOCK, by = row / SS_SKY_BLOCK;
    int last_x = ss_sky_block_exit(col, ray->sx), last_y = ss_sky_block_exit(row, ray->sy);
    for (int k = 0; k < n && sq[k].t_in < stop;) {
        /* The block's squares end where the list first crosses out of its
         * last column or its last row. */
        int end_x = ss_sky_block_end(ray->within_x, g->width, last_x, n);
        int end_y = ss_sky_block_end(ray->within_y, g->height, last_y, n);
        int by_x = end_x < end_y, end = by_x ? end_x : end_y;
        if (tops->block_top[(size_t)by * tops->across + bx] - eye <= best * sq[k].t_in)
            k = end;
        else
            k = ss_sky_walk(sq, k, end, z, sign, eye, room, curv_k, &best, &stop, at);
        if (by_x) {
            bx += ray->sx;
            last_x += SS_SKY_BLOCK;
        } else {
            by += ray->sy;
            last_y += SS_SKY_BLOCK;
        }
        if (bx < 0 || bx >= tops->across || by < 0 || by >= tops->down)
            break; /* the ray has left the grid */
    }
    return best;
}

int ss_sky_lanes_here(void)
{
#if SS_SKY_LANES_AVX2
    return __builtin_cpu_supports("avx2");
#else
    return 0;
#endif
}

int ss_box_sky_add(const ss_grid *grid, int n_dirs, const double *grid_azimuth_deg,
                   int definition, float sign, const ss_box_sky_tops *tops, double curv_k,
                   int row0, int n_rows, const float *grad, const volatile sig_atomic_t *cancel,
                   float *sums)
{
    /* The directions' squares listed once for all the rows, so that each
     * cell's rays run together over the heights around it. */
    ss_sky_ray *rays = ss_calloc((size_t)n_dirs, sizeof *rays);
    int ok = rays != NULL, w = grid->width, lanes_ok = ss_sky_lanes_here();
    for (int d = 0; ok && d < n_dirs; ++d)
        ok = ss_sky_ray_init(&rays[d], grid, grid_azimuth_deg[d]);
    long pieces = (long)n_rows * ss_sky_pieces(w);
#pragma omp parallel for schedule(dynamic, 4) if (ok)
    for (long piece = 0; piece < pieces; ++piece) {
        /* Four cells at a time where the CPU can and four lie ahead in the
         * row (from a multiple of four), else one. */
        ss_sky_piece span = ss_sky_piece_at(piece, row0, w);
        int r = span.row, lanes = 1;
        for (int c = span.col; ok && c < span.end && !(cancel && *cancel); c += lanes) {
            lanes = ss_sky_lanes_at(lanes_ok, c, w);
            const float *z = grid->z + (size_t)r * w + c;
            size_t own = (size_t)(r - row0) * w + c;
            int any = 0;
            float sum[SS_SKY_LANES], de[SS_SKY_LANES], dn[SS_SKY_LANES];
            for (int i = 0; i < lanes; ++i) {
                any |= isfinite(z[i]);
                sum[i] = sums[own + i];
                de[i] = grad ? grad[2 * (own + i)] : 0.0f;
                dn[i] = grad ? grad[2 * (own + i) + 1] : 0.0f;
            }
            if (!any)
                continue;
            for (int d = 0; d < n_dirs; ++d) {
                double t[SS_SKY_LANES];
                int at; /* the sky view takes the tangent alone */
#if SS_SKY_LANES_AVX2
                if (lanes == SS_SKY_LANES)
                    ss_sky_tangents_avx2(grid, &rays[d], tops, c, r, sign, curv_k, t);
                else
#endif
                    t[0] = ss_sky_tangent(grid, &rays[d], tops, c, r, sign, curv_k, &at);
                for (int i = 0; i < lanes; ++i)
                    sum[i] += ss_sky_walk_term(definition, 1.0f, (float)t[i], rays[d].sin_az,
                                               rays[d].cos_az, de[i], dn[i]);
            }
            for (int i = 0; i < lanes; ++i)
                if (isfinite(z[i]))
                    sums[own + i] = sum[i];
        }
    }
    for (int d = 0; rays && d < n_dirs; ++d)
        ss_sky_ray_free(&rays[d]);
    free(rays);
    return ok;
}
