/* The box model's horizons by each cell's own ray (box_sky.h's
 * ss_box_horizon_rows): the sky view's walk, its tangent turned into an
 * angle and, where a distance or a casting height is asked, the square
 * that sets it. */
#include "config.h"

#include <math.h>
#include <stddef.h>

#include "box_sky_walk.h"

int ss_box_horizon_rows(const ss_grid *grid, double grid_azimuth_deg, const ss_box_sky_tops *tops,
                        double curv_k, int row0, int n_rows, const volatile sig_atomic_t *cancel,
                        float *angle, float *dist, float *cast)
{
    ss_sky_ray ray = {0};
    int ok = ss_sky_ray_init(&ray, grid, grid_azimuth_deg), w = grid->width;
    /* The lanes find the tangent alone: the square that sets it is the
     * one-cell walk's. */
    int lanes_ok = ss_sky_lanes_here() && !dist && !cast;
    const double degrees = 180.0 / M_PI;
    long pieces = (long)n_rows * ss_sky_pieces(w);
#pragma omp parallel for schedule(dynamic, 4) if (ok)
    for (long piece = 0; piece < pieces; ++piece) {
        ss_sky_piece span = ss_sky_piece_at(piece, row0, w);
        int r = span.row, lanes = 1;
        for (int c = span.col; ok && c < span.end && !(cancel && *cancel); c += lanes) {
            lanes = ss_sky_lanes_at(lanes_ok, c, w);
            const float *z = grid->z + (size_t)r * w + c;
            size_t own = (size_t)(r - row0) * w + c;
            double tangent[SS_SKY_LANES];
            int at = -1;
#if SS_SKY_LANES_AVX2
            if (lanes == SS_SKY_LANES)
                ss_sky_tangents_avx2(grid, &ray, tops, c, r, 1.0f, curv_k, tangent);
            else
#endif
                tangent[0] = ss_sky_tangent(grid, &ray, tops, c, r, 1.0f, curv_k, &at);
            for (int i = 0; i < lanes; ++i)
                angle[own + i] = isfinite(z[i]) ? (float)(atan(tangent[i]) * degrees) : NAN;
            if (dist)
                dist[own] = (float)(at >= 0 ? ray.sq[at].t_in : ray.t_own);
            if (cast)
                cast[own] = at >= 0 ? z[ray.sq[at].offset] : z[0];
        }
    }
    ss_sky_ray_free(&ray);
    return ok;
}
