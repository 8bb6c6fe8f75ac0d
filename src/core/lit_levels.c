/* Per-cell horizon bounds (lit_levels.h).
 *
 * The proof, for interpolated lines (kernels/ss_lines.h). A sample P that
 * gives cell c a horizon lies at c's major index, less than a cell across
 * the line from c, and its height interpolates c and its neighbour across
 * the line. An occluding sample Q interpolates two cells q, q' across the
 * line that both have heights. A horizon's tangent is (z_Q - z_P -
 * curvature) / distance walked from P to Q, curvature only lowers it, and
 * a cell's horizon is a weighted mean of its samples'. Two bounds hold for
 * every such pair:
 *
 * 1. Heights and distance. z_P is at least the lowest of c and its
 *    neighbours across the line, z_Q at most the higher of q, q'. Each
 *    sample lies within a cell of its cells and the line's slope is at
 *    most one cell across per major step, so |d_minor| <= |d_major| + 1
 *    between c and q, and the distance is at least hypot(|d_major|
 *    c_major, (|d_minor| - 2)+ c_minor).
 * 2. Slopes. Where every cell within 2 of the box around P and Q has a
 *    height, the samples between them lie on the surface interpolated
 *    across the lines, and each major step rises at most Gx + |m| Gy over
 *    a run of sqrt(cx^2 + m^2 cy^2), which Cauchy-Schwarz bounds by
 *    hypot(Gx / cx, Gy / cy) (G: the largest height difference between
 *    neighbours along each axis there; m: the slope, cells across per
 *    step). The rise from P to Q is the sum of its steps'.
 *
 * The cells q are taken in zones: those within NEAR_R one by one, then
 * for each level j of a pyramid of blocks of 2^j cells, their highest
 * heights, at the nearest distance from any cell of c's own block, for
 * blocks RING_LO..RING_M blocks away. The zones cover the grid. Each
 * zone's bound 1 is capped by bound 2 over the window that holds the
 * zone, and c's bound is the largest over the zones.
 *
 * The proof, for box lines (kernels/ss_box.h) of f families. Cell c takes
 * its horizon at its centre C, projected on the one line that runs
 * nearest: P, at height z_c itself. The line runs beside C by at most half
 * a family spacing, 1/(2f) of a cell across it, so C lies at most
 * e = max(cx, cy) / (2f) from the line. Every point Q that can give P a
 * horizon lies on the line and is either the centre of a cell q, at z_q,
 * or a point of the boundary between two columns, at the taller one's
 * height: then q is that taller column, and Q lies on its square. So z_Q
 * <= z_q with Q in the closed square of a cell q that has a height. If q
 * is c, the tangent is at most 0. Otherwise the walk's distance from P to
 * Q, measured along the line, is |PQ| = sqrt(|CQ|^2 - |CP|^2) >= sqrt(D^2
 * - e^2), D being the distance from C to q's square: hypot((|d_x| - 1/2)
 * cx, (|d_y| - 1/2) cy) for q |d_x|, |d_y| cells away (a term 0 where its
 * offset is 0). The tangent (z_Q - z_c - curvature) / |PQ| is at most
 * (z_q - z_c) / sqrt(D^2 - e^2): curvature only lowers it, and where D <=
 * e no bound holds (a taller q then leaves c unbounded; one family per
 * cell lets a point touch a face). Positions along the walk are floats of
 * up to half a line's steps, so each may be off by that times 2^-24
 * steps: the distance bound is lowered by max(w, h) hypot(cx, cy) 2^-20,
 * many times that. Bound 2 has no counterpart (a column's face rises
 * without a slope), so box bounds are bound 1's alone, over the same
 * zones, with z_c for the lowest sample and the box distance for each
 * zone's nearest cell. */
#include "config.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "lit_levels.h"

#define NEAR_R 7  /* cells, in Chebyshev distance, bounded one by one */
#define RING_M 9  /* blocks, the outer edge of each level's ring */
#define RING_LO 4 /* blocks, the inner edge: nearer ones are the finer zones' */
/* Float rounding in the walks: a bound must clear a level by this much. */
#define ROUNDING_MARGIN 1e-3f

int ss_lit_levels_used(int walked_steps, int lines)
{
    return walked_steps >= 48 && (lines == SS_LINES_INTERPOLATED || lines == SS_LINES_BOX);
}

double ss_lit_level_deg(int level)
{
    return (level + 1) * SS_LIT_STEP_DEG;
}

int ss_lit_level_below(double elevation_deg)
{
    if (!(elevation_deg >= SS_LIT_STEP_DEG))
        return -1;
    int k = (int)floor(elevation_deg / SS_LIT_STEP_DEG) - 1;
    /* floor may land a level high where the division rounds up */
    while (k >= 0 && ss_lit_level_deg(k) > elevation_deg)
        --k;
    return k < SS_LIT_LEVELS ? k : SS_LIT_LEVELS - 1;
}

/* The lines a bound is for, and what its distances need. */
typedef struct {
    int box;        /* box lines (else interpolated) */
    double cx, cy;  /* cell sizes, metres */
    double beside;  /* box: the farthest a cell's centre lies from its line (e) */
    double slack;   /* box: the walks' float error in a distance */
} line_geometry;

/* The box proof's distance for cells ax, ay >= 0 apart along the axes, not
 * both 0; 0 where none is proven. */
static double box_distance(int ax, int ay, const line_geometry *g)
{
    double dx = fmax(0.0, ax - 0.5) * g->cx, dy = fmax(0.0, ay - 0.5) * g->cy;
    double sq = dx * dx + dy * dy - g->beside * g->beside;
    return sq > 0.0 ? fmax(0.0, sqrt(sq) - g->slack) : 0.0;
}

/* The factor that turns a height difference into a tangent bound over a
 * distance d: past the largest float where d is 0, so that any rise
 * leaves the cell unbounded and none leaves it at 0. */
static float inverse_distance(double d)
{
    return d > 0.0 ? (float)(1.0 / d) : FLT_MAX;
}

/* Bound 1's distance for cells dx, dy >= 0 cells apart along the axes, by
 * lines whose major axis is x (major_x) or y (major_y); 0 if neither. */
static double pair_distance(int dx, int dy, int major_x, int major_y, double cx, double cy)
{
    double d = INFINITY;
    if (major_x)
        d = fmin(d, hypot(dx * cx, fmax(0.0, dy - 2.0) * cy));
    if (major_y)
        d = fmin(d, hypot(dy * cy, fmax(0.0, dx - 2.0) * cx));
    return isfinite(d) ? d : 0.0;
}

/* The lowest height of a sample giving cell c a horizon: its partner
 * across the line is a neighbour north or south on lines whose major axis
 * is the columns (lo_ns), east or west on the others (lo_ew); lo, either.
 * +INFINITY at nodata cells, whose bounds then never count. */
static void lowest_samples(const float *z, int w, int h, float *lo_ns, float *lo_ew, float *lo)
{
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            size_t c = (size_t)y * w + x;
            float ns = z[c], ew = z[c];
            if (!isfinite(z[c])) {
                lo_ns[c] = lo_ew[c] = lo[c] = INFINITY;
                continue;
            }
            if (x > 0 && isfinite(z[c - 1]))
                ew = fminf(ew, z[c - 1]);
            if (x + 1 < w && isfinite(z[c + 1]))
                ew = fminf(ew, z[c + 1]);
            if (y > 0 && isfinite(z[c - w]))
                ns = fminf(ns, z[c - w]);
            if (y + 1 < h && isfinite(z[c + w]))
                ns = fminf(ns, z[c + w]);
            lo_ns[c] = ns;
            lo_ew[c] = ew;
            lo[c] = fminf(ns, ew);
        }
}

/* The height differences between neighbours along x (at the west cell of
 * each pair) and y (at the north cell): +INFINITY where a cell of the pair
 * has no height, 0 past the last column or row. */
static void neighbour_steps(const float *z, int w, int h, float *gx, float *gy)
{
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            size_t c = (size_t)y * w + x;
            float v = z[c];
            gx[c] = x + 1 < w ? fabsf(z[c + 1] - v) : 0.0f;
            gy[c] = y + 1 < h ? fabsf(z[c + w] - v) : 0.0f;
            gx[c] = isnan(gx[c]) || !isfinite(v) ? INFINITY : gx[c];
            gy[c] = isnan(gy[c]) || !isfinite(v) ? INFINITY : gy[c];
        }
}

/* out[i] = the largest of in[i - r .. i + r] (stride apart, n values),
 * +INFINITY where the window leaves [0, n): van Herk and Gil-Werman's
 * running maxima over blocks of 2r + 1, in tmp (2 n floats). */
static void window_max_1d(const float *in, size_t stride, int n, int r, float *out, float *tmp)
{
    int k = 2 * r + 1;
    float *ahead = tmp, *behind = tmp + n;
    for (int i = 0; i < n; ++i)
        ahead[i] = i % k == 0 ? in[i * stride] : fmaxf(ahead[i - 1], in[i * stride]);
    for (int i = n - 1; i >= 0; --i)
        behind[i] = i % k == k - 1 || i == n - 1 ? in[i * stride]
                                                 : fmaxf(behind[i + 1], in[i * stride]);
    for (int i = 0; i < n; ++i)
        out[i * stride] = i - r < 0 || i + r >= n ? INFINITY : fmaxf(behind[i - r], ahead[i + r]);
}

/* out = the largest of in over the square of radius r around each cell,
 * +INFINITY where it leaves the grid; tmp: w x h floats. */
static int window_max(const float *in, int w, int h, int r, float *out, float *tmp)
{
    int ok = 1;
#pragma omp parallel
    {
        float *line = malloc(sizeof(float) * 2 * (size_t)(w > h ? w : h));
        if (!line) {
#pragma omp atomic write
            ok = 0;
        }
#pragma omp for schedule(static)
        for (int y = 0; y < h; ++y)
            if (line)
                window_max_1d(in + (size_t)y * w, 1, w, r, tmp + (size_t)y * w, line);
#pragma omp for schedule(static)
        for (int x = 0; x < w; ++x)
            if (line)
                window_max_1d(tmp + x, (size_t)w, h, r, out + x, line);
        free(line);
    }
    return ok;
}

/* Caps every zone bound in zone[] at bound 2 over the square of radius
 * reach + 2 around its cell (gx NULL: no cap, box lines), and raises best
 * to it. */
static int add_zone(const float *gx, const float *gy, int w, int h, double cx, double cy,
                    int reach, float *zone, float *best, float *win_x, float *win_y, float *tmp)
{
    if (gx && (!window_max(gx, w, h, reach + 2, win_x, tmp) ||
               !window_max(gy, w, h, reach + 2, win_y, tmp)))
        return 0;
    size_t n = (size_t)w * h;
    float icx = (float)(1.0 / cx), icy = (float)(1.0 / cy);
#pragma omp parallel for schedule(static)
    for (size_t c = 0; c < n; ++c) {
        float slope = gx ? hypotf(win_x[c] * icx, win_y[c] * icy) : INFINITY;
        float t = zone[c] < slope ? zone[c] : slope;
        best[c] = t > best[c] ? t : best[c];
        zone[c] = -INFINITY;
    }
    return 1;
}

/* zone[x] = max(zone[x], (e[x + shift] - lo[x]) * inv) for x in [x0, x1). */
static void add_tangents(float *zone, const float *e, const float *lo, int x0, int x1,
                         int shift, float inv)
{
#pragma omp simd
    for (int x = x0; x < x1; ++x) {
        float t = (e[x + shift] - lo[x]) * inv;
        zone[x] = t > zone[x] ? t : zone[x];
    }
}

/* Bound 1 over the cells r_lo..r_hi away (Chebyshev), one by one, for
 * each line orientation that can pair them, with its own lowest samples
 * (box lines: one distance, lo_ns and lo_ew both the centres' heights). */
static void near_zone(const float *z, const float *lo_ns, const float *lo_ew, int w, int h,
                      const line_geometry *g, int r_lo, int r_hi, float *zone)
{
    double cx = g->cx, cy = g->cy;
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) {
        float *row_zone = zone + (size_t)y * w;
        for (int dy = -r_hi; dy <= r_hi; ++dy) {
            if (y + dy < 0 || y + dy >= h)
                continue;
            const float *row = z + (size_t)(y + dy) * w;
            for (int dx = -r_hi; dx <= r_hi; ++dx) {
                int ax = abs(dx), ay = abs(dy), x0 = dx < 0 ? -dx : 0, x1 = dx > 0 ? w - dx : w;
                if ((ax > ay ? ax : ay) < r_lo)
                    continue;
                if (g->box) {
                    add_tangents(row_zone, row, lo_ns + (size_t)y * w, x0, x1, dx,
                                 inverse_distance(box_distance(ax, ay, g)));
                    continue;
                }
                double along_x = pair_distance(ax, ay, ax > 0 && ay <= ax + 1, 0, cx, cy);
                double along_y = pair_distance(ax, ay, 0, ay > 0 && ax <= ay + 1, cx, cy);
                if (along_x > 0)
                    add_tangents(row_zone, row, lo_ns + (size_t)y * w, x0, x1, dx,
                                 (float)(1.0 / along_x));
                if (along_y > 0)
                    add_tangents(row_zone, row, lo_ew + (size_t)y * w, x0, x1, dx,
                                 (float)(1.0 / along_y));
            }
        }
    }
}

/* The highest height of each block of two by two of the level below
 * (nbx x nby blocks of a grid of pw x ph). */
static void halve(const float *below, int pw, int ph, float *out, int nbx, int nby)
{
#pragma omp parallel for schedule(static)
    for (int by = 0; by < nby; ++by)
        for (int bx = 0; bx < nbx; ++bx) {
            float m = -INFINITY;
            for (int k = 0; k < 4; ++k) {
                int x = 2 * bx + (k & 1), y = 2 * by + (k >> 1);
                if (x < pw && y < ph)
                    m = fmaxf(m, below[(size_t)y * pw + x]);
            }
            out[(size_t)by * nbx + bx] = m;
        }
}

/* Bound 1 over level j's ring: blocks of s = 2^j cells (heights: the
 * level's nbx x nby maxima). Each block row's rows of maxima are spread
 * over cells once (spread[x] = the block over cell x) and serve its s rows
 * of cells. */
static int ring_zone(const float *level, int nbx, int nby, int j, const float *lo, int w, int h,
                     const line_geometry *g, float *zone)
{
    int s = 1 << j, span = nbx * s;
    int ok = 1;
#pragma omp parallel
    {
        float *spread = malloc(sizeof(float) * (size_t)span);
        if (!spread) {
#pragma omp atomic write
            ok = 0;
        }
#pragma omp for schedule(dynamic, 1)
        for (int by = 0; by < nby; ++by) {
            if (!spread)
                continue;
            for (int dby = -RING_M; dby <= RING_M; ++dby) {
                int ry = by + dby;
                if (ry < 0 || ry >= nby)
                    continue;
                for (int x = 0; x < span; ++x)
                    spread[x] = level[(size_t)ry * nbx + (x >> j)];
                int ay = abs(dby), gap_y = ay > 0 ? (ay - 1) * s + 1 : 0;
                for (int dbx = -RING_M; dbx <= RING_M; ++dbx) {
                    int ax = abs(dbx);
                    if ((ax > ay ? ax : ay) < RING_LO)
                        continue;
                    int gap_x = ax > 0 ? (ax - 1) * s + 1 : 0;
                    float inv = inverse_distance(
                        g->box ? box_distance(gap_x, gap_y, g)
                               : pair_distance(gap_x, gap_y, 1, 1, g->cx, g->cy));
                    int x0 = dbx < 0 ? -dbx * s : 0;
                    int x1 = span - (dbx > 0 ? dbx * s : 0);
                    x1 = x1 < w ? x1 : w;
                    for (int y = by * s; y < (by + 1) * s && y < h; ++y)
                        add_tangents(zone + (size_t)y * w, spread, lo + (size_t)y * w, x0, x1,
                                     dbx * s, inv);
                }
            }
        }
        free(spread);
    }
    return ok;
}

/* The centres' own heights, +INFINITY at nodata cells: the lowest
 * samples of box lines. */
static void centre_heights(const float *z, size_t n, float *lo)
{
#pragma omp parallel for schedule(static)
    for (size_t c = 0; c < n; ++c)
        lo[c] = isfinite(z[c]) ? z[c] : INFINITY;
}

/* The tangent bound of every cell into best (w x h), the planes p being
 * work space of the same size. */
#define WORK_PLANES 10
static int bound_tangents(const float *z, int w, int h, const line_geometry *g, float *best,
                          float *p[WORK_PLANES])
{
    float *lo = p[0], *zone = p[1], *level = p[2], *next = p[3], *gx = p[4], *gy = p[5];
    float *win_x = p[6], *win_y = p[7], *lo_ns = p[8], *lo_ew = p[9];
    size_t n = (size_t)w * h;
    if (g->box) {
        centre_heights(z, n, lo);
        lo_ns = lo_ew = lo;
        gx = gy = NULL; /* no slope caps */
    } else {
        lowest_samples(z, w, h, lo_ns, lo_ew, lo);
        neighbour_steps(z, w, h, gx, gy);
    }
    for (size_t c = 0; c < n; ++c) {
        best[c] = zone[c] = -INFINITY;
        level[c] = isfinite(z[c]) ? z[c] : -INFINITY; /* never the highest */
    }
    double cx = g->cx, cy = g->cy;
    /* The nearest cells in rings of their own, each capped by the slopes
     * of a window only as wide as it needs. */
    static const int near_rings[][2] = {{1, 2}, {3, 4}, {5, NEAR_R}};
    int ok = 1;
    for (int k = 0; ok && k < 3; ++k) {
        near_zone(level, lo_ns, lo_ew, w, h, g, near_rings[k][0], near_rings[k][1], zone);
        ok = add_zone(gx, gy, w, h, cx, cy, near_rings[k][1], zone, best, win_x, win_y, next);
    }
    /* Level j's ring holds cells within (RING_M + 1) 2^j - 1 of c and
     * covers every cell within (RING_M - 1) 2^j + 1. The blocks it skips
     * lie within RING_LO 2^j - 1: within NEAR_R at level 1, and within the
     * level below's cover at the others. */
    int pw = w, ph = h, cover = NEAR_R, farthest = (w > h ? w : h) - 1;
    for (int j = 1; ok && cover < farthest; ++j) {
        int nbx = (pw + 1) / 2, nby = (ph + 1) / 2;
        halve(level, pw, ph, next, nbx, nby);
        float *t = level;
        level = next;
        next = t;
        pw = nbx;
        ph = nby;
        /* next, the level below, is work space from here on. */
        ok = ring_zone(level, nbx, nby, j, lo, w, h, g, zone) &&
             add_zone(gx, gy, w, h, cx, cy, (RING_M + 1) * (1 << j) - 1, zone, best, win_x,
                      win_y, next);
        cover = (RING_M - 1) * (1 << j) + 1;
    }
    return ok;
}

/* The levels of the bounds g's proof gives (lit_levels.h). */
static unsigned char *levels_of(const float *z, int w, int h, const line_geometry *g)
{
    size_t n = (size_t)w * h;
    float *best = ss_malloc(n * sizeof(float)), *p[WORK_PLANES];
    int ok = best != NULL;
    for (int i = 0; i < WORK_PLANES; ++i) {
        p[i] = ss_malloc(n * sizeof(float));
        ok = ok && p[i];
    }
    unsigned char *out = ss_malloc(n);
    ok = ok && out && bound_tangents(z, w, h, g, best, p);
    if (ok) {
#pragma omp parallel for schedule(static)
        for (size_t c = 0; c < n; ++c) {
            double deg = atan(best[c] * (1.0 + ROUNDING_MARGIN) + ROUNDING_MARGIN) * (180.0 / M_PI);
            /* The first level above deg (an angle of 0 is below level 0's). */
            int k = deg < 0.0 ? 0 : (int)floor(deg / SS_LIT_STEP_DEG);
            while (k < SS_LIT_LEVELS && !(deg < ss_lit_level_deg(k)))
                ++k;
            out[c] = !isfinite(z[c])        ? 0
                     : k < SS_LIT_LEVELS ? (unsigned char)k
                                         : SS_LIT_UNBOUNDED;
        }
    }
    free(best);
    for (int i = 0; i < WORK_PLANES; ++i)
        free(p[i]);
    if (!ok) {
        free(out);
        return NULL;
    }
    return out;
}

unsigned char *ss_lit_levels(const float *z, int w, int h, double cx, double cy)
{
    line_geometry g = {0, cx, cy, 0.0, 0.0};
    return levels_of(z, w, h, &g);
}

unsigned char *ss_lit_levels_box(const float *z, int w, int h, double cx, double cy,
                                 int families)
{
    line_geometry g = {1, cx, cy, 0.5 / families * fmax(cx, cy),
                       (w > h ? w : h) * hypot(cx, cy) * 0x1p-20};
    return levels_of(z, w, h, &g);
}
