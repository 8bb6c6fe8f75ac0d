/* Continuous reference horizons by ray marching (see reference_march.h). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>

#include "reference_march.h"

#define BLOCK 8

void ref_march_init(ref_march *rm, const ss_grid *grid, double curvature_k, double step_cells)
{
    rm->grid = grid;
    rm->curvature_k = curvature_k;
    rm->step_cells = step_cells > 0 ? step_cells : 0.125;
    rm->no_shortcuts = 0;
    rm->z_max = -INFINITY;
    size_t n = (size_t)grid->width * (size_t)grid->height;
    for (size_t c = 0; c < n; ++c)
        if (isfinite(grid->z[c]) && grid->z[c] > rm->z_max)
            rm->z_max = grid->z[c];
    /* A sample at x in [8 b, 8 b + 8) reads cells up to 8 b + 8: each block's
     * maximum takes in that next row and column. */
    rm->blocks_x = (grid->width + BLOCK - 1) / BLOCK;
    rm->blocks_y = (grid->height + BLOCK - 1) / BLOCK;
    rm->block_max = malloc(sizeof(float) * (size_t)rm->blocks_x * rm->blocks_y);
    for (int by = 0; rm->block_max && by < rm->blocks_y; ++by)
        for (int bx = 0; bx < rm->blocks_x; ++bx) {
            float m = -INFINITY;
            for (int r = by * BLOCK; r <= by * BLOCK + BLOCK && r < grid->height; ++r)
                for (int c = bx * BLOCK; c <= bx * BLOCK + BLOCK && c < grid->width; ++c) {
                    float z = grid->z[(size_t)r * grid->width + c];
                    if (isfinite(z) && z > m)
                        m = z;
                }
            rm->block_max[(size_t)by * rm->blocks_x + bx] = m;
        }
}

void ref_march_free(ref_march *rm)
{
    free(rm->block_max);
    rm->block_max = NULL;
}

/* sin and cos of an angle in degrees, exact (0 or +-1) on multiples of 90:
 * sin(M_PI) is 1.2e-16, which would push a ray along a row of centres off
 * it, onto a nodata neighbour or out of a one-cell-wide grid. */
static void sincos_deg(double deg, double *s, double *c)
{
    double a = fmod(deg, 360.0);
    if (a < 0)
        a += 360.0;
    if (a == 0.0 || a == 90.0 || a == 180.0 || a == 270.0) {
        int q = (int)(a / 90.0);
        const double sv[4] = {0, 1, 0, -1}, cv[4] = {1, 0, -1, 0};
        *s = sv[q];
        *c = cv[q];
        return;
    }
    *s = sin(a * M_PI / 180.0);
    *c = cos(a * M_PI / 180.0);
}

/* Lower stencil index and fraction along an axis of n centres. */
static void axis_stencil(double x, int n, int *i0, double *f)
{
    if (n == 1) {
        *i0 = 0;
        *f = 0.0;
        return;
    }
    if (x < 0)
        x = 0;
    if (x > n - 1)
        x = n - 1;
    int i = (int)floor(x);
    if (i > n - 2)
        i = n - 2;
    *i0 = i;
    *f = x - i;
}

/* Bilinear height at (x = column, y = row) relative to z_ref (so a flat
 * plane gives exactly 0 at any height); 0 when a cell with positive weight
 * is nodata. */
static int bilinear(const ss_grid *g, double x, double y, double z_ref, double *dz)
{
    int i0, j0;
    double fx, fy;
    axis_stencil(x, g->width, &i0, &fx);
    axis_stencil(y, g->height, &j0, &fy);
    const double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    const int di[4] = {0, 1, 0, 1}, dj[4] = {0, 0, 1, 1};
    double sum = 0;
    for (int k = 0; k < 4; ++k) {
        if (!(w[k] > 0))
            continue;
        double v = g->z[(size_t)(j0 + dj[k]) * g->width + (i0 + di[k])];
        if (!isfinite(v))
            return 0;
        sum += w[k] * (v - z_ref);
    }
    *dz = sum;
    return 1;
}

/* Distance along the ray (t per unit distance in index units) before the
 * index coordinate x0 + t d leaves [0, n - 1]. */
static double axis_exit(double x0, double t, int n)
{
    if (t > 0)
        return (n - 1 - x0) / t;
    if (t < 0)
        return -x0 / t;
    return INFINITY;
}

typedef struct {
    const ref_march *rm;
    double x0, y0, ux, uy, z0;
    double best_slope, best_d;
} ray_state;

static void visit(ray_state *r, double d)
{
    if (!(d > 0))
        return;
    double dz;
    if (!bilinear(r->rm->grid, r->x0 + d * r->ux, r->y0 + d * r->uy, r->z0, &dz))
        return;
    double slope = (dz - d * d * r->rm->curvature_k) / d;
    if (slope > r->best_slope || (slope == r->best_slope && d > r->best_d)) {
        r->best_slope = slope;
        r->best_d = d;
    }
}

/* The limit d -> 0+: the slope of the bilinear patch the ray starts into,
 * (z_neighbour - z0) per index step along each axis the ray moves on. On
 * terrain curving up ahead of the cell this is the horizon (the tangent), a
 * supremum no sample at d > 0 reaches. Skipped, like any sample, when a
 * cell of that patch with positive weight is nodata or off the grid. */
static void visit_limit(ray_state *r, int col, int row)
{
    const ss_grid *g = r->rm->grid;
    int sx = r->ux > 0 ? 1 : (r->ux < 0 ? -1 : 0), sy = r->uy > 0 ? 1 : (r->uy < 0 ? -1 : 0);
    int cn = col + sx, rn = row + sy;
    if (cn < 0 || cn >= g->width || rn < 0 || rn >= g->height)
        return;
    double zx = g->z[(size_t)row * g->width + cn], zy = g->z[(size_t)rn * g->width + col];
    double zd = g->z[(size_t)rn * g->width + cn];
    if (!isfinite(zx) || !isfinite(zy) || !isfinite(zd))
        return;
    double slope = (zx - r->z0) * fabs(r->ux) + (zy - r->z0) * fabs(r->uy);
    if (slope > r->best_slope) {
        r->best_slope = slope;
        r->best_d = 0;
    }
}

/* Crossings of integer index values of one axis strictly after a and up to b
 * (index coordinates at the interval's ends), visited at their distances. */
static void visit_crossings(ray_state *r, double x0, double u, double a, double b)
{
    if (u > 0)
        for (double k = floor(a) + 1; k <= b; k += 1)
            visit(r, (k - x0) / u);
    else if (u < 0)
        for (double k = ceil(a) - 1; k >= b; k -= 1)
            visit(r, (k - x0) / u);
}

double ref_horizon_deg(const ref_march *rm, int col, int row, double azimuth_deg, double *dist_m)
{
    const ss_grid *g = rm->grid;
    double z0 = g->z[(size_t)row * g->width + col];
    if (dist_m)
        *dist_m = 0;
    if (!isfinite(z0))
        return NAN;
    double s, c;
    sincos_deg(azimuth_deg, &s, &c);
    /* Index units per metre along the ray: east is +column, north -row. */
    ray_state r = {rm, col, row, s / g->cell_x_m, -c / g->cell_y_m, z0, -INFINITY, 0};
    double d_end = fmin(axis_exit(col, r.ux, g->width), axis_exit(row, r.uy, g->height));
    double step = rm->step_cells * fmin(g->cell_x_m, g->cell_y_m);
    double rise_room = rm->z_max - z0; /* >= 0: z0 is a valid height */
    double prev = 0;
    if (d_end > 0)
        visit_limit(&r, col, row);
    for (long i = 1; prev < d_end; ++i) {
        double d = fmin(i * step, d_end);
        if (!(d > prev))
            continue; /* a skip may end a hair past the next step */
        visit_crossings(&r, col, r.ux, col + prev * r.ux, col + d * r.ux);
        visit_crossings(&r, row, r.uy, row + prev * r.uy, row + d * r.uy);
        visit(&r, d);
        prev = d;
        if (rm->no_shortcuts)
            continue;
        /* Nothing farther can rise above z_max: once (z_max - z0)/d - d k,
         * which only falls with d, is below the best slope, the rest of the
         * ray cannot win. */
        if (rise_room / d - d * rm->curvature_k < r.best_slope)
            break;
        /* Nor can the samples left in this block rise above its maximum:
         * skip to where the ray leaves it, visiting that point itself. */
        double x = col + d * r.ux, y = row + d * r.uy;
        int bx = (int)floor(x / BLOCK), by = (int)floor(y / BLOCK);
        if (!rm->block_max || bx < 0 || by < 0 || bx >= rm->blocks_x || by >= rm->blocks_y)
            continue;
        double exit_x = r.ux > 0 ? ((bx + 1) * BLOCK - x) / r.ux
                                 : (r.ux < 0 ? (bx * BLOCK - x) / r.ux : INFINITY);
        double exit_y = r.uy > 0 ? ((by + 1) * BLOCK - y) / r.uy
                                 : (r.uy < 0 ? (by * BLOCK - y) / r.uy : INFINITY);
        double d_exit = fmin(d + fmin(exit_x, exit_y), d_end);
        double room = rm->block_max[(size_t)by * rm->blocks_x + bx] - z0;
        /* room/d' is monotone in d', so its larger end bounds it. */
        double bound = fmax(room / d, room / d_exit) - d * rm->curvature_k;
        if (d_exit > d && bound < r.best_slope) {
            visit(&r, d_exit);
            prev = d_exit;
            i = (long)floor(d_exit / step);
        }
    }
    if (r.best_slope == -INFINITY)
        return -90.0;
    if (dist_m)
        *dist_m = r.best_d;
    return atan(r.best_slope) * 180.0 / M_PI;
}

static double z_or(const ss_grid *g, int col, int row, double fallback)
{
    if (col < 0 || row < 0 || col >= g->width || row >= g->height)
        return fallback;
    double v = g->z[(size_t)row * g->width + col];
    return isfinite(v) ? v : fallback;
}

void ref_gradient(const ss_grid *g, int col, int row, double *dz_de, double *dz_dn)
{
    double z = g->z[(size_t)row * g->width + col];
    double nw = z_or(g, col - 1, row - 1, z), n = z_or(g, col, row - 1, z),
           ne = z_or(g, col + 1, row - 1, z), w = z_or(g, col - 1, row, z),
           e = z_or(g, col + 1, row, z), sw = z_or(g, col - 1, row + 1, z),
           so = z_or(g, col, row + 1, z), se = z_or(g, col + 1, row + 1, z);
    *dz_de = ((ne + 2 * e + se) - (nw + 2 * w + sw)) / (8 * g->cell_x_m);
    *dz_dn = ((nw + 2 * n + ne) - (sw + 2 * so + se)) / (8 * g->cell_y_m);
}

void ref_svf_from_horizons(const double *horizons_deg, int n_az, double offset_deg, double dz_de,
                           double dz_dn, double svf[3])
{
    double sum_sin = 0, sum_cos2 = 0, sum_tilt = 0;
    double norm = sqrt(1 + dz_de * dz_de + dz_dn * dz_dn);
    for (int i = 0; i < n_az; ++i) {
        double h = horizons_deg[i] * M_PI / 180.0;
        double hp = h > 0 ? h : 0; /* convention A: sky only above the horizontal */
        sum_sin += sin(hp);
        sum_cos2 += cos(hp) * cos(hp);
        /* Dozier & Frew (1990) eq. 7b in HORAYZON's elevation form
         * (physics.md 2.2c), the horizon raised to the cell's tangent plane
         * where that plane rises above it (Dozier 2022). */
        double s, c;
        sincos_deg(offset_deg + 360.0 * i / n_az, &s, &c);
        double rise = dz_de * s + dz_dn * c;
        double h_eff = fmax(hp, atan(rise));
        double nxy = -rise / norm, nz = 1 / norm;
        sum_tilt +=
            nxy * (M_PI / 2 - h_eff - sin(h_eff) * cos(h_eff)) + nz * cos(h_eff) * cos(h_eff);
    }
    svf[SS_SVF_DEF_GEOMETRIC] = 1 - sum_sin / n_az;
    svf[SS_SVF_DEF_HORIZONTAL] = sum_cos2 / n_az;
    svf[SS_SVF_DEF_RADIATIVE] = sum_tilt / n_az;
}

void ref_svf(const ref_march *rm, int col, int row, int n_az, double offset_deg, double svf[3],
             double *horizons_deg)
{
    const ss_grid *g = rm->grid;
    if (!isfinite(g->z[(size_t)row * g->width + col])) {
        svf[0] = svf[1] = svf[2] = NAN;
        return;
    }
    double local[3600];
    double *h = horizons_deg ? horizons_deg
                             : (n_az <= 3600 ? local : malloc(sizeof(double) * (size_t)n_az));
    for (int i = 0; i < n_az; ++i)
        h[i] = ref_horizon_deg(rm, col, row, offset_deg + 360.0 * i / n_az, NULL);
    double dz_de, dz_dn;
    ref_gradient(g, col, row, &dz_de, &dz_dn);
    ref_svf_from_horizons(h, n_az, offset_deg, dz_de, dz_dn, svf);
    if (h != local && h != horizons_deg)
        free(h);
}
