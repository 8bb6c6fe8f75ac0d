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

void test_plane(ss_grid *g, double slope_deg, double aspect_deg)
{
    double t = tan(slope_deg * M_PI / 180), a = aspect_deg * M_PI / 180;
    int cc = g->width / 2, cr = g->height / 2;
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            double east = (c - cc) * g->cell_x_m, north = -(r - cr) * g->cell_y_m;
            /* + 0.0: flat ground is +0, not -0 */
            g->z[(size_t)r * g->width + c] = (float)(-t * (east * sin(a) + north * cos(a)) + 0.0);
        }
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

/* How a cell combines the angles of the samples that feed it. */
typedef enum {
    BRUTE_AHEAD_ONLY, /* mean over the samples with terrain ahead (horizon products) */
    BRUTE_ALL_TERMS   /* mean over all, none_deg counted as a term (openness) */
} brute_mean;

static void brute_horizon(const ss_grid *g, double azimuth_deg, double curv_k, double radius_m,
                          int model, double none_deg, brute_mean mean, const float *claimed_dist,
                          double *angle_deg, double *near_angle_rad, double *claimed_angle_rad,
                          double *claimed_height_m)
{
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, g->width, g->height, g->cell_x_m, g->cell_y_m, azimuth_deg,
                            model);
    double az = azimuth_deg * M_PI / 180.0;
    /* Distance along the azimuth per column and per row, in double. */
    double per_col = -sin(az) * g->cell_x_m, per_row = cos(az) * g->cell_y_m;
    double per_major = ls.major_is_row ? per_row : per_col;
    double per_minor = ls.major_is_row ? per_col : per_row;
    size_t n_cells = (size_t)g->width * g->height;
    /* Per cell: the weight summed into angle_deg, and the rank of the
     * sample whose horizon near_angle_rad holds (0: none yet). */
    double *weight = calloc(n_cells, sizeof(double));
    int *rank = calloc(n_cells, sizeof(int));
    for (size_t c = 0; c < n_cells; ++c) {
        angle_deg[c] = 0.0;
        near_angle_rad[c] = claimed_angle_rad[c] = NAN;
        if (claimed_height_m)
            claimed_height_m[c] = NAN;
    }
    int max_len = g->width > g->height ? g->width : g->height;
    double *pos = malloc(sizeof(double) * max_len), *height = malloc(sizeof(double) * max_len);
    int *valid = malloc(sizeof(int) * max_len), *occludes = malloc(sizeof(int) * max_len);
    ss_line_sample *smp = malloc(sizeof(ss_line_sample) * max_len);
    for (int line = 0; line < ls.n_lines; ++line) {
        int first, n = ss_line_extent(&ls, line, &first);
        for (int s = 0; s < n; ++s) {
            ss_line_sample p = ss_line_sample_at(&ls, ss_line_intercept16(&ls, line),
                                                 ss_line_major_at(&ls, first, n, s));
            smp[s] = p;
            /* Exact minor position of the sample: the cell itself on digital
             * lines, the point between two cells on interpolated ones. */
            double minor = model == SS_LINE_MODEL_DIGITAL ? p.minor0 : p.minor0 + (double)p.w1;
            pos[s] = p.major * per_major + minor * per_minor;
            double z0 = NAN, z1 = NAN;
            if (p.minor0 >= 0 && p.w1 < 1)
                z0 = g->z[ss_line_cell(&ls, p.major, p.minor0)];
            if (p.minor0 + 1 < ls.minor_len && p.w1 > 0)
                z1 = g->z[ss_line_cell(&ls, p.major, p.minor0 + 1)];
            valid[s] = isfinite(z0) || isfinite(z1);
            /* Only full interpolations occlude (ss_sample_cells explains why). */
            occludes[s] = (isfinite(z0) || p.w1 == 1) && (isfinite(z1) || p.w1 == 0);
            height[s] = isfinite(z0) && isfinite(z1) ? (1 - p.w1) * z0 + p.w1 * z1
                                                     : (isfinite(z0) ? z0 : z1);
        }
        for (int v = 0; v < n; ++v) {
            if (!valid[v])
                continue;
            /* The sample's cells (k = 0: minor0, 1: minor0 + 1) that it feeds
             * with a positive weight, and what each claims as distance. */
            double w[2] = {1.0 - smp[v].w1, smp[v].w1}, claimed[2] = {NAN, NAN};
            double claimed_angle[2] = {NAN, NAN}, claimed_height[2] = {NAN, NAN};
            size_t cell[2] = {0, 0};
            int feeds[2];
            for (int k = 0; k < 2; ++k) {
                int minor = smp[v].minor0 + k;
                feeds[k] = minor >= 0 && minor < ls.minor_len && w[k] > 0;
                if (!feeds[k])
                    continue;
                cell[k] = (size_t)ss_line_cell(&ls, smp[v].major, minor);
                if (claimed_dist)
                    claimed[k] = claimed_dist[cell[k]];
            }
            /* Slopes rank like angles and cost a division, not an atan2. */
            double best = -INFINITY, best_d = 0;
            for (int t = 0; t < v; ++t) {
                if (!occludes[t])
                    continue;
                double d = pos[v] - pos[t];
                if (radius_m > 0 && d > radius_m)
                    continue;
                double slope = (height[t] - height[v] - d * d * curv_k) / d;
                if (slope > best || (slope == best && d > best_d)) {
                    best = slope;
                    best_d = d;
                }
                for (int k = 0; k < 2; ++k)
                    if (fabs(d - claimed[k]) <= 1e-4 * (1.0 + d)) {
                        claimed_angle[k] = atan(slope);
                        claimed_height[k] = height[t];
                    }
            }
            int ahead = best != -INFINITY;
            double angle = ahead ? atan(best) : none_deg * M_PI / 180;
            for (int k = 0; k < 2; ++k) {
                if (!feeds[k])
                    continue;
                if (!ahead && claimed[k] == 0.0)
                    claimed_angle[k] = angle;
                if (ahead || mean == BRUTE_ALL_TERMS) {
                    angle_deg[cell[k]] += w[k] * angle * 180.0 / M_PI;
                    weight[cell[k]] += w[k];
                }
                /* The cell's distance names its nearer sample (a tie goes to
                 * the sample whose minor0 it is) among those with terrain
                 * ahead, if any: rank by (ahead, nearer). */
                int nearer = k == 0 ? w[k] >= 0.5 : w[k] > 0.5;
                int r = 1 + 2 * ahead + nearer;
                if (r > rank[cell[k]]) {
                    rank[cell[k]] = r;
                    near_angle_rad[cell[k]] = angle;
                    claimed_angle_rad[cell[k]] = claimed_angle[k];
                    if (claimed_height_m)
                        claimed_height_m[cell[k]] = claimed_height[k];
                }
            }
        }
    }
    for (size_t c = 0; c < n_cells; ++c) {
        if (!isfinite(g->z[c]))
            angle_deg[c] = NAN;
        else if (mean == BRUTE_AHEAD_ONLY)
            angle_deg[c] = weight[c] > 0 ? angle_deg[c] / weight[c] : none_deg;
    }
    free(weight);
    free(rank);
    free(pos);
    free(height);
    free(valid);
    free(occludes);
    free(smp);
}

void test_brute_horizon(const ss_grid *g, double azimuth_deg, double curv_k, int model,
                        const float *claimed_dist, double *angle_deg, double *near_angle_rad,
                        double *claimed_angle_rad)
{
    brute_horizon(g, azimuth_deg, curv_k, 0.0, model, -90.0, BRUTE_AHEAD_ONLY, claimed_dist,
                  angle_deg, near_angle_rad, claimed_angle_rad, NULL);
}

void test_brute_caster_height(const ss_grid *g, double azimuth_deg, double curv_k, int model,
                              const float *claimed_dist, double *claimed_height_m)
{
    size_t n = (size_t)g->width * g->height;
    double *angle = malloc(n * sizeof(double)), *near = malloc(n * sizeof(double));
    double *claimed = malloc(n * sizeof(double));
    brute_horizon(g, azimuth_deg, curv_k, 0.0, model, -90.0, BRUTE_AHEAD_ONLY, claimed_dist, angle,
                  near, claimed, claimed_height_m);
    free(angle);
    free(near);
    free(claimed);
}

void test_brute_horizon_none(const ss_grid *g, double azimuth_deg, int model, double none_deg,
                             double *angle_deg, double *near_angle_rad, double *claimed_angle_rad)
{
    brute_horizon(g, azimuth_deg, 0.0, 0.0, model, none_deg, BRUTE_AHEAD_ONLY, NULL, angle_deg,
                  near_angle_rad, claimed_angle_rad, NULL);
}

void test_brute_horizon_terms(const ss_grid *g, double azimuth_deg, double curv_k,
                              double radius_m, int model, double none_deg, double *angle_deg)
{
    size_t n = (size_t)g->width * g->height;
    double *near = malloc(n * sizeof(double)), *claimed = malloc(n * sizeof(double));
    brute_horizon(g, azimuth_deg, curv_k, radius_m, model, none_deg, BRUTE_ALL_TERMS, NULL,
                  angle_deg, near, claimed, NULL);
    free(near);
    free(claimed);
}

typedef struct {
    float *angle, *dist, *cast;
    size_t n;
} sink_copy;

static int copy_sink(int index, double az, const float *angle, const float *dist,
                     const float *cast, void *user)
{
    (void)index;
    (void)az;
    sink_copy *sc = user;
    memcpy(sc->angle, angle, sc->n * sizeof(float));
    if (dist && sc->dist)
        memcpy(sc->dist, dist, sc->n * sizeof(float));
    if (cast && sc->cast)
        memcpy(sc->cast, cast, sc->n * sizeof(float));
    return 1;
}

ss_status test_lib_horizon(const char *device, const ss_grid *g, double azimuth_deg,
                           double earth_radius_m, double refraction_k, int model,
                           float *angle_deg, float *dist_m, char *err, size_t err_size)
{
    return test_lib_caster(device, g, azimuth_deg, earth_radius_m, refraction_k, model,
                           angle_deg, dist_m, NULL, err, err_size);
}

ss_status test_lib_caster(const char *device, const ss_grid *g, double azimuth_deg,
                          double earth_radius_m, double refraction_k, int model, float *angle_deg,
                          float *dist_m, float *cast_height_m, char *err, size_t err_size)
{
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, device);
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 1;
    opt.offset_deg = azimuth_deg;
    opt.earth_radius_m = earth_radius_m;
    opt.refraction_k = refraction_k;
    opt.lines = (ss_line_model)model;
    sink_copy sc = {angle_deg, dist_m, cast_height_m, (size_t)g->width * g->height};
    int want = (dist_m ? SS_HORIZON_DISTANCE : 0) | (cast_height_m ? SS_HORIZON_CAST_HEIGHT : 0);
    ss_status st = ss_horizon(ctx, g, &opt, want, copy_sink, &sc);
    if (st != SS_OK && err)
        snprintf(err, err_size, "%s", ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return st;
}

int test_have_pocl(void)
{
    ss_ctx *ctx = ss_ctx_new();
    char devices[4096] = "";
    int have = ss_list_devices(ctx, devices, sizeof devices) > 0 &&
               strstr(devices, "Portable Computing Language") != NULL;
    ss_ctx_free(ctx);
    return have;
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

ss_source test_source(const ss_grid *g, ss_rows_read read, void *user, int band_rows,
                      ss_band_stats *stats)
{
    ss_source src = {.width = g->width,
                     .height = g->height,
                     .cell_x_m = g->cell_x_m,
                     .cell_y_m = g->cell_y_m,
                     .z_origin_m = &g->z_origin_m,
                     .read = read,
                     .read_user = user,
                     .band_rows = band_rows,
                     .stats = stats};
    return src;
}
