/* Test helpers (see testlib.h). */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lines.h"
#include "testlib.h"

ss_grid test_grid(int width, int height, double cell_x_m, double cell_y_m)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_grid g;
    if (ss_grid_alloc(ctx, &g, width, height, cell_x_m, cell_y_m) != SS_OK) {
        printf("Bail out! %s\n", ss_ctx_message(ctx));
        exit(99);
    }
    ss_ctx_free(ctx);
    return g;
}

static unsigned rng_next(unsigned *state)
{
    unsigned x = *state ? *state : 0x9e3779b9u;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    return *state = x;
}

static double rng_unit(unsigned *state)
{
    return (rng_next(state) & 0xffffff) / 16777216.0;
}

void test_fill(ss_grid *g, terrain_kind kind, unsigned seed, double relief_m)
{
    unsigned s = seed * 2654435761u + 1;
    double fx[6], fy[6], ph[6], amp[6];
    for (int k = 0; k < 6; ++k) {
        fx[k] = (rng_unit(&s) - 0.5) * 0.6;
        fy[k] = (rng_unit(&s) - 0.5) * 0.6;
        ph[k] = rng_unit(&s) * 6.283;
        amp[k] = relief_m / (k + 1);
    }
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            double z = 0;
            switch (kind) {
            case TERRAIN_NOISE:
                z = rng_unit(&s) * relief_m;
                break;
            case TERRAIN_SMOOTH:
                for (int k = 0; k < 6; ++k)
                    z += amp[k] * sin(fx[k] * c + fy[k] * r + ph[k]);
                break;
            case TERRAIN_PLATEAUS:
                z = floor(rng_unit(&s) * 4.0) * relief_m / 4.0;
                if (rng_unit(&s) < 0.7)
                    z = relief_m / 4.0; /* mostly one level: long runs of ties */
                break;
            case TERRAIN_SPIKES:
                z = rng_unit(&s) < 0.01 ? relief_m : 0.0;
                break;
            }
            g->z[(size_t)r * g->width + c] = (float)z;
        }
}

void test_holes(ss_grid *g, unsigned seed, int n_holes, int max_size)
{
    unsigned s = seed * 747796405u + 7;
    for (int i = 0; i < n_holes; ++i) {
        int w = 1 + (int)(rng_unit(&s) * max_size), h = 1 + (int)(rng_unit(&s) * max_size);
        int c0 = (int)(rng_unit(&s) * g->width), r0 = (int)(rng_unit(&s) * g->height);
        for (int r = r0; r < r0 + h && r < g->height; ++r)
            for (int c = c0; c < c0 + w && c < g->width; ++c)
                g->z[(size_t)r * g->width + c] = NAN;
    }
}

void test_brute_horizon(const ss_grid *g, double azimuth_deg, double curv_k,
                        const float *claimed_dist, double *angle_rad, double *dist_m,
                        double *claimed_angle_rad)
{
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, g->width, g->height, g->cell_x_m, g->cell_y_m, azimuth_deg);
    double az = azimuth_deg * M_PI / 180.0;
    /* Distance along the azimuth between cell centres, in double. */
    double per_col = -sin(az) * g->cell_x_m, per_row = cos(az) * g->cell_y_m;
    int max_len = g->width > g->height ? g->width : g->height;
    int *cols = malloc(sizeof(int) * max_len), *rows = malloc(sizeof(int) * max_len);
    for (int line = 0; line < ls.n_lines; ++line) {
        int first, n = ss_line_extent(&ls, line, &first);
        for (int s = 0; s < n; ++s) {
            int major = ss_line_major_at(&ls, first, n, s);
            int minor = ss_line_minor(&ls, ls.line_min + line, major);
            cols[s] = ls.major_is_row ? minor : major;
            rows[s] = ls.major_is_row ? major : minor;
        }
        for (int v = 0; v < n; ++v) {
            size_t cv = (size_t)rows[v] * g->width + cols[v];
            double zv = g->z[cv];
            angle_rad[cv] = dist_m[cv] = NAN;
            if (claimed_angle_rad)
                claimed_angle_rad[cv] = NAN;
            if (!isfinite(zv))
                continue;
            /* Slopes rank like angles and cost a division, not an atan2. */
            double best = -INFINITY, best_d = 0;
            for (int t = 0; t < v; ++t) {
                double zt = g->z[(size_t)rows[t] * g->width + cols[t]];
                if (!isfinite(zt))
                    continue;
                double d = (cols[v] - cols[t]) * per_col + (rows[v] - rows[t]) * per_row;
                double slope = (zt - zv - d * d * curv_k) / d;
                if (slope > best || (slope == best && d > best_d)) {
                    best = slope;
                    best_d = d;
                }
                if (claimed_angle_rad && claimed_dist &&
                    fabs(d - claimed_dist[cv]) <= 1e-4 * (1.0 + d))
                    claimed_angle_rad[cv] = atan(slope);
            }
            angle_rad[cv] = best == -INFINITY ? -M_PI / 2 : atan(best);
            dist_m[cv] = best_d;
            if (claimed_angle_rad && claimed_dist && claimed_dist[cv] == 0.0f && best == -INFINITY)
                claimed_angle_rad[cv] = -M_PI / 2;
        }
    }
    free(cols);
    free(rows);
}

typedef struct {
    float *angle, *dist;
    size_t n;
} sink_copy;

static int copy_sink(int index, double az, const float *angle, const float *dist, void *user)
{
    (void)index;
    (void)az;
    sink_copy *sc = user;
    memcpy(sc->angle, angle, sc->n * sizeof(float));
    if (dist && sc->dist)
        memcpy(sc->dist, dist, sc->n * sizeof(float));
    return 1;
}

ss_status test_lib_horizon(const char *device, const ss_grid *g, double azimuth_deg,
                           double earth_radius_m, double refraction_k, float *angle_deg,
                           float *dist_m, char *err, size_t err_size)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, device);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 1;
    opt.offset_deg = azimuth_deg;
    opt.earth_radius_m = earth_radius_m;
    opt.refraction_k = refraction_k;
    sink_copy sc = {angle_deg, dist_m, (size_t)g->width * g->height};
    ss_status st = ss_horizon(ctx, g, &opt, dist_m != NULL, copy_sink, &sc);
    if (st != SS_OK && err)
        snprintf(err, err_size, "%s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st;
}

const char *test_shared_data(const char *name)
{
    static char path[1024];
    const char *dirs[2] = {getenv("SS_SHARED_DATA"), TOP_SRCDIR "/../shared/data"};
    for (int i = 0; i < 2; ++i) {
        if (!dirs[i])
            continue;
        snprintf(path, sizeof path, "%s/%s", dirs[i], name);
        if (access(path, R_OK) == 0)
            return path;
    }
    return NULL;
}
