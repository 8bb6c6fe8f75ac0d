/* The box model's sky view by each cell's own ray, four cells side by side
 * in AVX2's lanes (box_sky_walk.h), which ss_box_sky_add takes where the
 * CPU has AVX2. The condition is SS_SKY_LANES_AVX2's, tested before any
 * header so that the pragma covers the inline walk this copy takes in;
 * elsewhere this file compiles to nothing. Each lane rounds as
 * ss_sky_tangent does because the build fuses no product into a sum
 * (Makefile.am's -ffp-contract=off, which box_sky.c needs as much: with
 * FMA and contraction on, its walk would round differently). */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#pragma GCC target("avx2")
#include "config.h"

#include <immintrin.h>
#include <limits.h>
#include <math.h>

#include "box_sky_walk.h"

typedef double lanes_d __attribute__((vector_size(SS_SKY_LANES * sizeof(double))));
typedef long long lanes_m __attribute__((vector_size(SS_SKY_LANES * sizeof(long long))));

static int lanes_any(lanes_m m)
{
    return _mm256_movemask_pd((__m256d)m) != 0;
}

/* The lanes of a where in is set, else of b. */
static lanes_d lanes_pick(lanes_m in, lanes_d a, lanes_d b)
{
    return (lanes_d)(((lanes_m)a & in) | ((lanes_m)b & ~in));
}

/* ss_sky_walk for the four lanes at once over squares [k, end): the four
 * cells' rays cross the same list, at heights one column apart, so each
 * square is one load of four heights. A lane past its stop stays so (the
 * squares' t_in grow, and a stop only falls). Returns where the walk
 * ended: end, or before it where every lane is past its stop. */
static int lanes_walk(const ss_sky_square *sq, int k, int end, const float *z, float sign,
                      lanes_d eye, lanes_d room, double curv_k, lanes_d *best_io,
                      lanes_d *stop_io)
{
    lanes_d best = *best_io, stop = *stop_io;
    __m128 signs = _mm_set1_ps(sign);
    for (; k < end; ++k) {
        double t = sq[k].t_in;
        lanes_d tv = {t, t, t, t};
        lanes_m going = tv < stop;
        if (!lanes_any(going))
            break;
        __m128 top = _mm_mul_ps(_mm_loadu_ps(z + sq[k].offset), signs);
        lanes_d rise = (lanes_d)_mm256_cvtps_pd(top) - eye - curv_k * t * t;
        lanes_m higher = (rise > best * tv) & going;
        if (lanes_any(higher)) {
            lanes_d raised = rise / tv;
            stop = lanes_pick(higher, room / raised, stop);
            best = lanes_pick(higher, raised, best);
        }
    }
    *best_io = best;
    *stop_io = stop;
    return k;
}

/* All four lanes start in one block (col is a multiple of four, and so is
 * SS_SKY_BLOCK), cross its last row together and its last column one
 * after another. A block, or while the lanes are astride two the pair,
 * whose highest top no lane could see above its best angle at the first
 * square is passed over; the rest is walked. Past the first lane's edge
 * of the grid each lane finishes alone, as ss_sky_tangent would. */
void ss_sky_tangents_avx2(const ss_grid *g, const ss_sky_ray *ray, const ss_box_sky_tops *tops,
                          int col, int row, float sign, double curv_k, double *tangent)
{
    const float *z = g->z + (size_t)row * g->width + col;
    int n[SS_SKY_LANES], n_min = INT_MAX;
    lanes_d eye, room, best = {0, 0, 0, 0}, stop;
    for (int i = 0; i < SS_SKY_LANES; ++i) {
        n[i] = ss_sky_ray_squares(g, ray, col + i, row);
        n_min = n[i] < n_min ? n[i] : n_min;
        eye[i] = sign * z[i];
        room[i] = tops->top - eye[i];
        stop[i] = room[i] > 0.0 ? INFINITY : 0.0;
    }
    const ss_sky_square *sq = ray->sq;
    int bx = col / SS_SKY_BLOCK, by = row / SS_SKY_BLOCK;
    /* The first and the last lane to leave the block: their last columns
     * (the lane ahead leaves first), and the lanes' last row. */
    int first_x = ss_sky_block_exit(ray->sx > 0 ? col + SS_SKY_LANES - 1 : col, ray->sx);
    int last_x = first_x + SS_SKY_LANES - 1, last_y = ss_sky_block_exit(row, ray->sy);
    int astride = 0, k = 0;
    while (k < n_min) {
        int lane_x = astride ? last_x : first_x;
        int end_x = ss_sky_block_end(ray->within_x, g->width, lane_x, n_min);
        int end_y = ss_sky_block_end(ray->within_y, g->height, last_y, n_min);
        int by_y = end_y < end_x, end = by_y ? end_y : end_x;
        const float *block_top = tops->block_top + (size_t)by * tops->across;
        float top = block_top[bx];
        if (astride && bx + ray->sx >= 0 && bx + ray->sx < tops->across)
            top = fmaxf(top, block_top[bx + ray->sx]);
        double t = sq[k].t_in;
        lanes_d tv = {t, t, t, t};
        if (!lanes_any((top - eye > best * tv) & (tv < stop)))
            k = end;
        else if ((k = lanes_walk(sq, k, end, z, sign, eye, room, curv_k, &best, &stop)) < end)
            break; /* every lane is past its stop */
        if (by_y) {
            by += ray->sy;
            last_y += SS_SKY_BLOCK;
        } else if (!astride) {
            astride = 1;
        } else {
            astride = 0;
            bx += ray->sx;
            first_x += SS_SKY_BLOCK;
            last_x += SS_SKY_BLOCK;
        }
        if (bx < 0 || bx >= tops->across || by < 0 || by >= tops->down)
            break; /* every lane has left the grid */
    }
    for (int i = 0; i < SS_SKY_LANES; ++i) {
        double b = best[i], s = stop[i];
        int at; /* not asked of the lanes */
        ss_sky_walk(sq, k, n[i], z + i, sign, eye[i], room[i], curv_k, &b, &s, &at);
        tangent[i] = b;
    }
}
#endif
