/* The box-model ray march (tests/box_march.h). */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "box_march.h"
#include "testlib.h"

/* One ray's exact cell traversal (Amanatides & Woo 1987) from cell (r, c)
 * toward azimuth az (clockwise from the grid's north): the square it is
 * in, (ci, ri), and the metres from the start where it entered (t_in) and
 * leaves (t_out) it. */
typedef struct {
    int ci, ri, sx, sy;
    double tx, ty, step_x, step_y; /* the next column and row boundaries, and between them */
    double t_in, t_out;
} march_ray;

static march_ray march_ray_from(const ss_grid *g, int r, int c, double az)
{
    double dx = sin(az * M_PI / 180) / g->cell_x_m;  /* columns per metre */
    double dy = -cos(az * M_PI / 180) / g->cell_y_m; /* rows per metre (north: up) */
    march_ray m = {.ci = c, .ri = r, .sx = dx > 0 ? 1 : -1, .sy = dy > 0 ? 1 : -1};
    m.tx = fabs(dx) > 1e-12 ? 0.5 / fabs(dx) : INFINITY;
    m.ty = fabs(dy) > 1e-12 ? 0.5 / fabs(dy) : INFINITY;
    m.step_x = fabs(dx) > 1e-12 ? 1.0 / fabs(dx) : INFINITY;
    m.step_y = fabs(dy) > 1e-12 ? 1.0 / fabs(dy) : INFINITY;
    m.t_in = 0.0;
    m.t_out = fmin(m.tx, m.ty); /* where the ray leaves its own square */
    return m;
}

/* Into the next square: 0 where the ray has left the grid. */
static int march_ray_next(const ss_grid *g, march_ray *m)
{
    m->t_in = m->t_out;
    if (m->tx < m->ty) {
        m->ci += m->sx;
        m->tx += m->step_x;
    } else {
        m->ri += m->sy;
        m->ty += m->step_y;
    }
    m->t_out = fmin(m->tx, m->ty);
    return m->ci >= 0 && m->ri >= 0 && m->ci < g->width && m->ri < g->height;
}

static float march_ray_height(const ss_grid *g, const march_ray *m)
{
    return g->z[(size_t)m->ri * g->width + m->ci];
}

int box_march_lit(const ss_grid *g, int r, int c, double az, double el, double z_max)
{
    return box_march_lit_curved(g, r, c, az, el, z_max, 0.0);
}

int box_march_lit_curved(const ss_grid *g, int r, int c, double az, double el, double z_max,
                         double curv_k)
{
    double z0 = g->z[(size_t)r * g->width + c];
    double tan_el = tan(el * M_PI / 180);
    march_ray m = march_ray_from(g, r, c, az);
    while (march_ray_next(g, &m) && z0 + tan_el * m.t_in <= z_max) {
        float h = march_ray_height(g, &m);
        if (isfinite(h) && h - z0 - curv_k * m.t_in * m.t_in > tan_el * m.t_in)
            return 0;
    }
    return 1;
}

int box_march_crossed(const ss_grid *g, const float *top_m, const float *bottom_m, int r, int c,
                      double az, double el, double z_max)
{
    double z0 = g->z[(size_t)r * g->width + c];
    double tan_el = tan(el * M_PI / 180);
    march_ray m = march_ray_from(g, r, c, az);
    while (march_ray_next(g, &m) && z0 + tan_el * m.t_in <= z_max) {
        size_t j = (size_t)m.ri * g->width + m.ci;
        /* The ray rises from z0 + t_in tan(el) to z0 + t_out tan(el) over the square. */
        if (isfinite(g->z[j]) && top_m[j] > bottom_m[j] &&
            z0 + tan_el * m.t_in < g->z[j] + top_m[j] &&
            z0 + tan_el * m.t_out > g->z[j] + bottom_m[j])
            return 1;
    }
    return 0;
}

double box_march_horizon_deg(const ss_grid *g, int r, int c, double az)
{
    return box_march_horizon_curved_deg(g, r, c, az, 0.0);
}

double box_march_horizon_curved_deg(const ss_grid *g, int r, int c, double az, double curv_k)
{
    double z0 = g->z[(size_t)r * g->width + c];
    march_ray m = march_ray_from(g, r, c, az);
    double best = 0.0; /* the cell's own top reaches to its edge: 0 deg there */
    while (march_ray_next(g, &m)) {
        float h = march_ray_height(g, &m);
        /* A column above the eye shows its near edge, one below its far edge. */
        if (isfinite(h)) {
            double t = h > z0 ? m.t_in : m.t_out;
            best = fmax(best, atan((h - z0 - curv_k * t * t) / t) * 180 / M_PI);
        }
    }
    return best;
}

void box_march_point_near(const ss_grid *g, int r, int c, double az, double curv_k,
                          double dist_m, double height_m, box_march_point *p)
{
    double z0 = g->z[(size_t)r * g->width + c];
    march_ray m = march_ray_from(g, r, c, az);
    /* The cell's own top, at 0 deg where it ends. */
    *p = (box_march_point){m.t_out, z0, 0.0};
    while (march_ray_next(g, &m) && m.t_in <= 2.0 * dist_m + 2.0 * (g->cell_x_m + g->cell_y_m)) {
        float h = march_ray_height(g, &m);
        /* Only a column above the eye rises above 0 deg, at its near edge.
         * Where the ray passes at or near a corner, two columns show at
         * distances a float (dist_m's) cannot tell apart. */
        double t = m.t_in, off = fabs(t - dist_m) - fabs(p->dist_m - dist_m);
        double tie = 1e-6 * fmax(1.0, dist_m);
        int nearer =
            off < -tie || (off <= tie && fabs(h - height_m) < fabs(p->height_m - height_m));
        if (isfinite(h) && h > z0 && nearer)
            *p = (box_march_point){t, h, atan((h - z0 - curv_k * t * t) / t) * 180 / M_PI};
    }
}

void box_march_holes(ss_grid *g)
{
    for (size_t i = 0; i < (size_t)g->width * g->height; i += 37)
        g->z[i] = NAN;
    g->cell_y_m = 1.5;
}

ss_grid box_march_strip(int width, int height)
{
    ss_grid g = test_grid(width, height, 1.0, 1.0);
    for (int i = 0; i < width * height; ++i)
        g.z[i] = (float)((i * 7919) % 23);
    return g;
}

ss_grid box_march_tower(void)
{
    ss_grid g = test_grid(90, 70, 2.0, 2.0);
    for (size_t i = 0; i < (size_t)90 * 70; ++i)
        g.z[i] = 0.0f;
    g.z[(size_t)35 * 90 + 45] = 80.0f;
    return g;
}

ss_grid box_march_hills(void)
{
    ss_grid g = test_grid(120, 100, 2.0, 2.0);
    for (int r = 0; r < 100; ++r)
        for (int c = 0; c < 120; ++c)
            g.z[(size_t)r * 120 + c] = (float)(12.0 * sin(c / 9.0) * cos(r / 13.0) + 0.15 * c +
                                               30.0 * exp(-pow((r - 70) / 6.0, 2)));
    return g;
}

double box_march_top(const ss_grid *g)
{
    double z_max = -INFINITY;
    for (size_t i = 0; i < (size_t)g->width * g->height; ++i)
        if (isfinite(g->z[i]) && g->z[i] > z_max)
            z_max = g->z[i];
    return z_max;
}

ss_grid box_march_city(int n)
{
    ss_grid g = test_grid(n, n, 1, 1);
    for (size_t i = 0; i < (size_t)n * n; ++i)
        g.z[i] = 0.0f;
    unsigned s = 7;
    for (int b = 0; b < n * n / 600; ++b) {
        s = s * 1103515245u + 12345u;
        int w = 6 + (int)(s >> 16) % 35;
        s = s * 1103515245u + 12345u;
        int h = 6 + (int)(s >> 16) % 35;
        s = s * 1103515245u + 12345u;
        int c0 = (int)(s >> 16) % n, r0 = (int)((s >> 4) % (unsigned)n);
        s = s * 1103515245u + 12345u;
        float top = 4.0f + (float)((s >> 16) % 41);
        for (int r = r0; r < r0 + h && r < n; ++r)
            for (int c = c0; c < c0 + w && c < n; ++c)
                g.z[(size_t)r * n + c] = top;
    }
    return g;
}

double box_march_agreement(const ss_grid *g, const ss_sweep_options *opt, double az, double el,
                           char *err)
{
    size_t n = (size_t)g->width * g->height;
    float *lit = malloc(n * sizeof(float));
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    double z_max = box_march_top(g), share = NAN;
    if (lit && ss_cast_shadow(ctx, g, opt, az, el, NULL, lit, NULL) == SS_OK) {
        size_t same = 0, valid = 0;
        for (int r = 0; r < g->height; ++r)
            for (int c = 0; c < g->width; ++c) {
                size_t i = (size_t)r * g->width + c;
                if (!isfinite(g->z[i]))
                    continue;
                valid++;
                same += (lit[i] == 1.0f) == box_march_lit(g, r, c, az, el, z_max);
            }
        share = (double)same / (double)valid;
    } else {
        snprintf(err, 300, "%s", lit ? ss_ctx_message(ctx) : "out of memory");
    }
    ss_ctx_free(ctx);
    free(lit);
    return share;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double box_march_svf_error(const ss_grid *g, const ss_sweep_options *opt, double *p95, char *err)
{
    size_t n = (size_t)g->width * g->height;
    float *svf = malloc(n * sizeof(float));
    double *errors = malloc(n * sizeof(double));
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    double sum = 0, error = NAN;
    if (p95)
        *p95 = NAN;
    if (svf && errors && ss_svf(ctx, g, opt, SS_SVF_DEF_GEOMETRIC, svf) == SS_OK) {
#pragma omp parallel for reduction(+ : sum) schedule(dynamic, 4)
        for (int r = 0; r < g->height; ++r)
            for (int c = 0; c < g->width; ++c) {
                size_t i = (size_t)r * g->width + c;
                errors[i] = NAN;
                if (!isfinite(g->z[i]))
                    continue;
                double blocked = 0;
                for (int k = 0; k < opt->directions; ++k)
                    blocked += sin(box_march_horizon_deg(g, r, c, ss_direction_azimuth(opt, k)) *
                                   M_PI / 180);
                errors[i] = fabs(svf[i] - (1 - blocked / opt->directions));
                sum += errors[i];
            }
        size_t valid = 0;
        for (size_t i = 0; i < n; ++i)
            if (!isnan(errors[i]))
                errors[valid++] = errors[i];
        error = sum / (double)valid;
        if (p95) {
            /* The nearest rank: the smallest error that 95 % of cells are within. */
            qsort(errors, valid, sizeof *errors, by_value);
            *p95 = errors[(size_t)ceil(0.95 * (double)valid) - 1];
        }
    } else {
        snprintf(err, 300, "%s", svf && errors ? ss_ctx_message(ctx) : "out of memory");
    }
    ss_ctx_free(ctx);
    free(errors);
    free(svf);
    return error;
}

const double box_march_azimuths[BOX_MARCH_AZIMUTHS] = {
    0.0,    0.01,   17.3,   44.99,  45.0,   45.01,  63.4,   89.99, 90.0,   90.01,
    101.7,  134.99, 135.0,  152.2,  179.99, 180.0,  180.01, 197.6, 224.99, 225.0,
    225.01, 243.3,  269.99, 270.0,  270.01, 288.8,  314.99, 315.0, 315.01, 333.1,
    359.99, 7.7,    26.57,  116.57, 206.57, 296.57, 11.0,   191.0, 78.0,   258.0};

ss_sweep_options box_march_options(int directions, double offset_deg, double grid_north_deg,
                                   double curv_k)
{
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = SS_LINES_BOX;
    opt.directions = directions;
    opt.offset_deg = offset_deg;
    opt.grid_north_deg = grid_north_deg;
    if (curv_k > 0) { /* curv_k = (1 - k) / (2 R) with k = 0 */
        opt.earth_radius_m = 1.0 / (2.0 * curv_k);
        opt.refraction_k = 0.0;
    }
    return opt;
}
