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
 * zone's nearest cell.
 *
 * The proof per sector of azimuths [a0, a1] (the grid's frame). A walk at
 * azimuth A looks for horizons toward A along lines whose direction u is
 * A's but for the fixed-point slope, 2^-17 minor cells a major step off,
 * which turns u by at most eps = 2^-16 max(cx, cy) / min(cx, cy) radians.
 * Write q - c for the vector, in metres east and north, from c's centre
 * C to q's. Interpolated lines: q - c = (P - C) + |PQ| u + (q - Q), the
 * first and last across the line by under a cell and at most a cell of
 * the minor axis, so q's centre lies within L = 2 max(cx, cy) of the ray
 * from C along u. Box lines: P is C's projection, within e of C, and Q
 * lies in q's square, within hypot(cx, cy) / 2 of its centre: L = e +
 * hypot(cx, cy) / 2 (plus the slack in positions). So q gives c a horizon
 * in the sector only if q - c lies within L of the wedge of rays at the
 * azimuths [a0 - eps, a1 + eps]: if q - c lies outside the wedge at
 * distance r, its angle from the wedge's nearer edge is at most asin(L /
 * r). A zone's pair of blocks (or of cells, blocks of one) spans the
 * offsets q - c of a rectangle; its corners give the azimuths it spans,
 * widened by asin(L / its distance from C) (every azimuth where L reaches
 * that far), and the zone counts toward the sector's bound only where
 * those meet the sector's. Bounds 1 and 2 are the same in every sector;
 * each sector keeps the largest of the zones that count toward it. */
#include "config.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cell_store.h"
#include "engine.h"
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

int ss_lit_sectors_for(int walked_steps, int lines, int families)
{
    double walks = (double)walked_steps * (lines == SS_LINES_BOX ? families : 1);
    return walks >= 2048.0 ? SS_LIT_SECTORS : 1;
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
    double lateral; /* the farthest an occluding cell's centre lies from the ray (L) */
    double turn;    /* radians: the most a line's direction differs from its azimuth (eps) */
    int sectors;    /* SS_LIT_SECTORS, or 1: one bound for every azimuth */
} line_geometry;

int ss_lit_sector(double grid_azimuth_deg)
{
    double a = fmod(grid_azimuth_deg, 360.0);
    a = a < 0.0 ? a + 360.0 : a;
    int k = (int)(a * (SS_LIT_SECTORS / 360.0));
    return k < SS_LIT_SECTORS ? k : SS_LIT_SECTORS - 1;
}

/* The azimuth difference a - b wrapped to [-pi, pi]. */
static double turn_between(double a, double b)
{
    return remainder(a - b, 2.0 * M_PI);
}

/* Whether cells q whose offsets from c (cells east, south) lie in
 * [x_lo, x_hi] x [y_lo, y_hi] can give c a horizon in sector k (the head
 * comment's proof): the rectangle's azimuths, widened by the lateral
 * reach, meet the sector's, widened by the lines' turn. */
static int offsets_seen(int k, double x_lo, double x_hi, double y_lo, double y_hi,
                        const line_geometry *g)
{
    if (g->sectors == 1)
        return 1;
    double e_lo = x_lo * g->cx, e_hi = x_hi * g->cx, n_lo = -y_hi * g->cy, n_hi = -y_lo * g->cy;
    double near_e = e_lo > 0.0 ? e_lo : (e_hi < 0.0 ? -e_hi : 0.0);
    double near_n = n_lo > 0.0 ? n_lo : (n_hi < 0.0 ? -n_hi : 0.0);
    double r = hypot(near_e, near_n);
    if (!(r > g->lateral))
        return 1;
    double mid = atan2(0.5 * (e_lo + e_hi), 0.5 * (n_lo + n_hi)), lo = 0.0, hi = 0.0;
    for (int i = 0; i < 4; ++i) {
        double t = turn_between(atan2(i & 1 ? e_hi : e_lo, i & 2 ? n_hi : n_lo), mid);
        lo = fmin(lo, t);
        hi = fmax(hi, t);
    }
    double width = 2.0 * M_PI / SS_LIT_SECTORS;
    double reach = asin(g->lateral / r) + g->turn;
    double sector_mid = (k + 0.5) * width;
    double gap = fabs(turn_between(mid + 0.5 * (lo + hi), sector_mid));
    return gap <= 0.5 * (hi - lo) + 0.5 * width + reach;
}

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

/* Bound 2 over the square of radius reach + 2 around each cell, into cap
 * (gx NULL: no cap, box lines, +INFINITY); win_y and tmp: work space. */
static int zone_cap(const float *gx, const float *gy, int w, int h, double cx, double cy,
                    int reach, float *cap, float *win_y, float *tmp)
{
    size_t n = (size_t)w * h;
    if (!gx) {
        for (size_t c = 0; c < n; ++c)
            cap[c] = INFINITY;
        return 1;
    }
    if (!window_max(gx, w, h, reach + 2, cap, tmp) || !window_max(gy, w, h, reach + 2, win_y, tmp))
        return 0;
    float icx = (float)(1.0 / cx), icy = (float)(1.0 / cy);
#pragma omp parallel for schedule(static)
    for (size_t c = 0; c < n; ++c)
        cap[c] = hypotf(cap[c] * icx, win_y[c] * icy);
    return 1;
}

/* Caps every zone bound in zone[] at cap, raises best to it, and empties
 * the zone for the next. */
static void add_zone(const float *cap, size_t n, float *zone, float *best)
{
#pragma omp parallel for schedule(static)
    for (size_t c = 0; c < n; ++c) {
        float t = zone[c] < cap[c] ? zone[c] : cap[c];
        best[c] = t > best[c] ? t : best[c];
        zone[c] = -INFINITY;
    }
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

/* Bound 1 over the cells r_lo..r_hi away (Chebyshev) that can give a
 * horizon in sector k, one by one, for each line orientation that can
 * pair them, with its own lowest samples (box lines: one distance, lo_ns
 * and lo_ew both the centres' heights). */
static void near_zone(const float *z, const float *lo_ns, const float *lo_ew, int w, int h,
                      const line_geometry *g, int k, int r_lo, int r_hi, float *zone)
{
    double cx = g->cx, cy = g->cy;
    unsigned char seen[2 * NEAR_R + 1][2 * NEAR_R + 1];
    for (int dy = -r_hi; dy <= r_hi; ++dy)
        for (int dx = -r_hi; dx <= r_hi; ++dx)
            seen[dy + NEAR_R][dx + NEAR_R] = (unsigned char)offsets_seen(k, dx, dx, dy, dy, g);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) {
        float *row_zone = zone + (size_t)y * w;
        for (int dy = -r_hi; dy <= r_hi; ++dy) {
            if (y + dy < 0 || y + dy >= h)
                continue;
            const float *row = z + (size_t)(y + dy) * w;
            for (int dx = -r_hi; dx <= r_hi; ++dx) {
                int ax = abs(dx), ay = abs(dy), x0 = dx < 0 ? -dx : 0, x1 = dx > 0 ? w - dx : w;
                if ((ax > ay ? ax : ay) < r_lo || !seen[dy + NEAR_R][dx + NEAR_R])
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

/* Bound 1 over level j's ring in sector k: blocks of s = 2^j cells
 * (heights: the level's nbx x nby maxima) whose cells can give a horizon
 * to a cell of the block at the ring's centre in that sector. The cells
 * are rows [row0, row0 + h) of the level's grid (a window of a grid read
 * in bands, else row0 0). Each block row's rows of maxima are spread over
 * cells once (spread[x] = the block over cell x) and serve its rows of
 * cells. */
static int ring_zone(const float *level, int nbx, int nby, int j, int row0, const float *lo,
                     int w, int h, const line_geometry *g, int k, float *zone)
{
    int s = 1 << j, span = nbx * s;
    int ok = 1;
    unsigned char seen[2 * RING_M + 1][2 * RING_M + 1];
    for (int dby = -RING_M; dby <= RING_M; ++dby)
        for (int dbx = -RING_M; dbx <= RING_M; ++dbx)
            seen[dby + RING_M][dbx + RING_M] = (unsigned char)offsets_seen(
                k, dbx * s - (s - 1), dbx * s + (s - 1), dby * s - (s - 1), dby * s + (s - 1), g);
    int by0 = row0 >> j, by1 = (row0 + h - 1) >> j;
#pragma omp parallel
    {
        float *spread = malloc(sizeof(float) * (size_t)span);
        if (!spread) {
#pragma omp atomic write
            ok = 0;
        }
#pragma omp for schedule(dynamic, 1)
        for (int by = by0; by <= by1; ++by) {
            if (!spread)
                continue;
            int y0 = by * s > row0 ? by * s : row0;
            int y1 = (by + 1) * s < row0 + h ? (by + 1) * s : row0 + h;
            for (int dby = -RING_M; dby <= RING_M; ++dby) {
                int ry = by + dby;
                if (ry < 0 || ry >= nby)
                    continue;
                for (int x = 0; x < span; ++x)
                    spread[x] = level[(size_t)ry * nbx + (x >> j)];
                int ay = abs(dby), gap_y = ay > 0 ? (ay - 1) * s + 1 : 0;
                for (int dbx = -RING_M; dbx <= RING_M; ++dbx) {
                    int ax = abs(dbx);
                    if ((ax > ay ? ax : ay) < RING_LO || !seen[dby + RING_M][dbx + RING_M])
                        continue;
                    int gap_x = ax > 0 ? (ax - 1) * s + 1 : 0;
                    float inv = inverse_distance(
                        g->box ? box_distance(gap_x, gap_y, g)
                               : pair_distance(gap_x, gap_y, 1, 1, g->cx, g->cy));
                    int x0 = dbx < 0 ? -dbx * s : 0;
                    int x1 = span - (dbx > 0 ? dbx * s : 0);
                    x1 = x1 < w ? x1 : w;
                    for (int y = y0; y < y1; ++y)
                        add_tangents(zone + (size_t)(y - row0) * w, spread,
                                     lo + (size_t)(y - row0) * w, x0, x1, dbx * s, inv);
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

/* Each zone of the nearest cells or of a level's ring, in every sector:
 * the cells of the zone that count toward the sector (near_zone,
 * ring_zone), capped by the zone's bound 2. */
typedef struct {
    const float *lo, *lo_ns, *lo_ew, *level;
    int nbx, nby, j;  /* a ring's level (j > 0), or 0: the nearest cells */
    int row0;         /* a ring's: the cells' first row in the level's grid */
    int r_lo, r_hi;   /* the nearest cells' ring */
} zone_source;

static int add_sectors(const zone_source *zs, const float *cap, int w, int h,
                       const line_geometry *g, float *zone, float *best)
{
    size_t n = (size_t)w * h;
    for (int k = 0; k < g->sectors; ++k) {
        if (zs->j > 0) {
            if (!ring_zone(zs->level, zs->nbx, zs->nby, zs->j, zs->row0, zs->lo, w, h, g, k, zone))
                return 0;
        } else {
            near_zone(zs->level, zs->lo_ns, zs->lo_ew, w, h, g, k, zs->r_lo, zs->r_hi, zone);
        }
        add_zone(cap, n, zone, best + (size_t)k * n);
    }
    return 1;
}

/* The levels FAR_J and up of a grid read in bands: the highest height of
 * each block of 2^j cells, held whole while each band's window makes the
 * levels below from its own rows (ss_lit_bands_make). */
#define FAR_J 3
#define FAR_MAX 32
typedef struct {
    float *level[FAR_MAX]; /* level FAR_J + i */
    int nbx[FAR_MAX], nby[FAR_MAX], n;
    int height;            /* the grid's */
} far_pyramid;

/* Where the cells that get bounds lie: a window of rows [row0, row0 + h)
 * of a grid read in bands, with that grid's far pyramid; far NULL: the
 * whole grid (row0 0). */
typedef struct {
    int row0;
    const far_pyramid *far;
} window;

/* The tangent bound of every sector and cell of a window of w x h cells
 * into best (g->sectors planes of w x h), the planes p being work
 * space of one plane's size. Cells beyond the window count as missing, so
 * the bounds of a window's cells hold where the window holds every cell
 * within LOCAL_REACH rows of them, or reaches the grid's edge. */
#define WORK_PLANES 10
_Static_assert(SS_LIT_MAKING_CELL_BYTES ==
                   4 + 4 * SS_LIT_SECTORS + WORK_PLANES * sizeof(float) + SS_LIT_SECTORS,
               "lit_levels.h counts the work planes levels_of makes");
static int bound_tangents(const float *z, int w, int h, const window *win,
                          const line_geometry *g, float *best, float *p[WORK_PLANES])
{
    float *lo = p[0], *zone = p[1], *level = p[2], *next = p[3], *gx = p[4], *gy = p[5];
    float *cap = p[6], *win_y = p[7], *lo_ns = p[8], *lo_ew = p[9];
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
        zone[c] = -INFINITY;
        level[c] = isfinite(z[c]) ? z[c] : -INFINITY; /* never the highest */
    }
    for (size_t c = 0; c < n * g->sectors; ++c)
        best[c] = -INFINITY;
    double cx = g->cx, cy = g->cy;
    /* The nearest cells in rings of their own, each capped by the slopes
     * of a window only as wide as it needs. */
    static const int near_rings[][2] = {{1, 2}, {3, 4}, {5, NEAR_R}};
    int ok = 1;
    for (int k = 0; ok && k < 3; ++k) {
        zone_source zs = {lo,   lo_ns, lo_ew, level, 0, 0, 0, 0, near_rings[k][0],
                          near_rings[k][1]};
        ok = zone_cap(gx, gy, w, h, cx, cy, near_rings[k][1], cap, win_y, next) &&
             add_sectors(&zs, cap, w, h, g, zone, best);
    }
    /* Level j's ring holds cells within (RING_M + 1) 2^j - 1 of c and
     * covers every cell within (RING_M - 1) 2^j + 1. The blocks it skips
     * lie within RING_LO 2^j - 1: within NEAR_R at level 1, and within the
     * level below's cover at the others. A window takes levels FAR_J and up
     * from its grid's pyramid, with no slope cap (a cap only lowers a
     * bound). */
    const far_pyramid *far = win->far;
    int grid_h = far ? far->height : h;
    int pw = w, ph = h, cover = NEAR_R, farthest = (w > grid_h ? w : grid_h) - 1;
    for (int j = 1; ok && cover < farthest; ++j) {
        zone_source zs;
        if (far && j >= FAR_J) {
            int i = j - FAR_J;
            if (i >= far->n)
                return 0;
            zs = (zone_source){lo, lo_ns, lo_ew, far->level[i], far->nbx[i], far->nby[i],
                               j,  win->row0, 0,  0};
            ok = zone_cap(NULL, NULL, w, h, cx, cy, 0, cap, win_y, next);
        } else {
            int nbx = (pw + 1) / 2, nby = (ph + 1) / 2;
            halve(level, pw, ph, next, nbx, nby);
            float *t = level;
            level = next;
            next = t;
            pw = nbx;
            ph = nby;
            /* next, the level below, is work space from here on. */
            zs = (zone_source){lo, lo_ns, lo_ew, level, nbx, nby, j, 0, 0, 0};
            ok = zone_cap(gx, gy, w, h, cx, cy, (RING_M + 1) * (1 << j) - 1, cap, win_y, next);
        }
        ok = ok && add_sectors(&zs, cap, w, h, g, zone, best);
        cover = (RING_M - 1) * (1 << j) + 1;
    }
    return ok;
}

/* The levels of the bounds g's proof gives (lit_levels.h), for the cells
 * of a window (bound_tangents). */
static unsigned char *levels_of(const float *z, int w, int h, const window *win,
                                const line_geometry *g)
{
    size_t n = (size_t)w * h, all = n * SS_LIT_SECTORS;
    float *best = ss_malloc(n * g->sectors * sizeof(float)), *p[WORK_PLANES];
    int ok = best != NULL;
    for (int i = 0; i < WORK_PLANES; ++i) {
        p[i] = ss_malloc(n * sizeof(float));
        ok = ok && p[i];
    }
    unsigned char *out = ss_malloc(all);
    ok = ok && out && bound_tangents(z, w, h, win, g, best, p);
    if (ok) {
#pragma omp parallel for schedule(static)
        for (size_t i = 0; i < all; ++i) {
            /* One bound serves every sector's plane. */
            float t = best[g->sectors == 1 ? i % n : i];
            double deg = atan(t * (1.0 + ROUNDING_MARGIN) + ROUNDING_MARGIN) * (180.0 / M_PI);
            /* The first level above deg (an angle of 0 is below level 0's). */
            int k = deg < 0.0 ? 0 : (int)floor(deg / SS_LIT_STEP_DEG);
            while (k < SS_LIT_LEVELS && !(deg < ss_lit_level_deg(k)))
                ++k;
            out[i] = !isfinite(z[i % n])    ? 0
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

/* The most a line's direction turns from its azimuth: its slope is
 * rounded to 2^-17 minor cells a major step (lines.c), twice that for
 * margin, times the cells' aspect. */
static double line_turn(double cx, double cy)
{
    return 0x1p-16 * fmax(cx, cy) / fmin(cx, cy);
}

/* The geometry of interpolated lines (families 0) or of box lines of
 * `families` families on a grid of w x h cells. */
static line_geometry geometry_of(int families, int sectors, int w, int h, double cx, double cy)
{
    sectors = sectors == 1 ? 1 : SS_LIT_SECTORS;
    if (families <= 0)
        return (line_geometry){0,   cx, cy, 0.0, 0.0, 2.0 * fmax(cx, cy), line_turn(cx, cy),
                               sectors};
    double beside = 0.5 / families * fmax(cx, cy), slack = (w > h ? w : h) * hypot(cx, cy) * 0x1p-20;
    return (line_geometry){1,     cx,
                           cy,    beside,
                           slack, beside + 0.5 * hypot(cx, cy) + slack,
                           line_turn(cx, cy), sectors};
}

unsigned char *ss_lit_levels(const float *z, int w, int h, double cx, double cy, int sectors)
{
    line_geometry g = geometry_of(0, sectors, w, h, cx, cy);
    window whole = {0, NULL};
    return levels_of(z, w, h, &whole, &g);
}

unsigned char *ss_lit_levels_box(const float *z, int w, int h, double cx, double cy,
                                 int families, int sectors)
{
    line_geometry g = geometry_of(families, sectors, w, h, cx, cy);
    window whole = {0, NULL};
    return levels_of(z, w, h, &whole, &g);
}

/* ---- a DEM read in bands ------------------------------------------------------- */

/* The rows a band's window holds beyond its own on each side: every cell
 * within the reach of its own cells' near zones, local rings (levels
 * below FAR_J, (RING_M + 1) 2^(FAR_J - 1) - 1 rows) and their slope caps'
 * windows (2 more, and a row of neighbour steps), so that its own cells'
 * bounds are those of the grid's cells. */
#define LOCAL_REACH (((RING_M + 1) << (FAR_J - 1)) + 3)

struct ss_lit_bands {
    ss_ctx *ctx;
    ss_cell_store *fine; /* each sector's levels, one plane each */
    unsigned char *blocks; /* each sector's largest level per block (lit_levels.h) */
    int width, height, nbx, nby;
};

static void far_free(far_pyramid *f)
{
    for (int i = 0; i < f->n; ++i)
        free(f->level[i]);
    f->n = 0;
}

/* The far pyramid of the DEM, read band by band (rows: buf's), up to the
 * level whose ring covers the grid; *made 0 where memory is short. */
static ss_status far_pyramid_of(ss_ctx *ctx, const ss_source *src, int rows, float *buf,
                                far_pyramid *f, int *made)
{
    int w = src->width, h = src->height, s = 1 << FAR_J;
    *f = (far_pyramid){.height = h};
    *made = 0;
    int nbx = (w + s - 1) / s, nby = (h + s - 1) / s;
    float *first = ss_malloc(sizeof(float) * (size_t)nbx * nby);
    if (!first)
        return SS_OK;
    f->level[0] = first;
    f->nbx[0] = nbx;
    f->nby[0] = nby;
    f->n = 1;
    for (size_t b = 0; b < (size_t)nbx * nby; ++b)
        first[b] = -INFINITY;
    for (int r0 = 0; r0 < h; r0 += rows) {
        int n = r0 + rows < h ? rows : h - r0;
        ss_status st = ss_source_read_rows(ctx, src, r0, n, buf);
        if (st != SS_OK) {
            far_free(f);
            return st;
        }
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < w; ++x) {
                float v = buf[(size_t)y * w + x];
                float *m = &first[(size_t)((r0 + y) >> FAR_J) * nbx + (x >> FAR_J)];
                if (isfinite(v) && v > *m)
                    *m = v;
            }
    }
    int farthest = (w > h ? w : h) - 1;
    for (int j = FAR_J; (RING_M - 1) * (1 << j) + 1 < farthest && f->n < FAR_MAX; ++j) {
        int i = f->n, pw = f->nbx[i - 1], ph = f->nby[i - 1];
        f->nbx[i] = (pw + 1) / 2;
        f->nby[i] = (ph + 1) / 2;
        if (!(f->level[i] = ss_malloc(sizeof(float) * (size_t)f->nbx[i] * f->nby[i]))) {
            far_free(f);
            return SS_OK;
        }
        halve(f->level[i - 1], pw, ph, f->level[i], f->nbx[i], f->nby[i]);
        f->n++;
    }
    *made = 1;
    return SS_OK;
}

/* Band [r0, r1)'s levels, from its window's heights in buf: put in the
 * store and raised into the blocks'; *made 0 where memory is short. */
static ss_status band_levels(ss_lit_bands *lb, const ss_source *src, const line_geometry *g,
                             const far_pyramid *far, int r0, int r1, float *buf, int *made)
{
    int w = src->width, h = src->height;
    int lo = r0 - LOCAL_REACH > 0 ? r0 - LOCAL_REACH : 0;
    int hi = r1 + LOCAL_REACH < h ? r1 + LOCAL_REACH : h;
    ss_status st = ss_source_read_rows(lb->ctx, src, lo, hi - lo, buf);
    if (st != SS_OK)
        return st;
    window win = {lo, far};
    unsigned char *levels = levels_of(buf, w, hi - lo, &win, g);
    *made = levels != NULL;
    size_t plane = (size_t)(hi - lo) * w, own = (size_t)(r0 - lo) * w;
    for (int k = 0; levels && k < SS_LIT_SECTORS && st == SS_OK; ++k) {
        const unsigned char *at = levels + k * plane + own;
        st = ss_cell_store_put(lb->fine, k, r0, r1 - r0, at);
        unsigned char *blocks = lb->blocks + (size_t)k * lb->nbx * lb->nby;
        for (int y = r0; y < r1; ++y)
            for (int x = 0; x < w; ++x) {
                unsigned char v = at[(size_t)(y - r0) * w + x];
                unsigned char *m = &blocks[(size_t)(y >> SS_LIT_BLOCK_SHIFT) * lb->nbx +
                                           (x >> SS_LIT_BLOCK_SHIFT)];
                *m = v > *m ? v : *m;
            }
    }
    free(levels);
    return st;
}

int ss_lit_bands_window_rows(int band_rows, int height)
{
    int rows = band_rows > LOCAL_REACH ? band_rows : LOCAL_REACH;
    rows += 2 * LOCAL_REACH;
    return rows < height ? rows : height;
}

void ss_lit_bands_free(ss_lit_bands *lb)
{
    if (!lb)
        return;
    ss_cell_store_close(lb->fine);
    free(lb->blocks);
    free(lb);
}

ss_status ss_lit_bands_make(ss_ctx *ctx, const ss_source *src, int families, int sectors,
                            ss_lit_bands **out)
{
    *out = NULL;
    int w = src->width, h = src->height, s = 1 << SS_LIT_BLOCK_SHIFT;
    int rows = ss_source_band_rows(src);
    rows = rows > LOCAL_REACH ? rows : LOCAL_REACH; /* the windows' rows, not all halo */
    rows = rows < h ? rows : h;
    ss_lit_bands *lb = ss_calloc(1, sizeof *lb);
    int hi = rows + 2 * LOCAL_REACH < h ? rows + 2 * LOCAL_REACH : h;
    float *buf = ss_malloc(sizeof(float) * (size_t)w * hi);
    if (lb) {
        *lb = (ss_lit_bands){ctx, NULL, NULL, w, h, (w + s - 1) / s, (h + s - 1) / s};
        lb->blocks = ss_calloc((size_t)SS_LIT_SECTORS * lb->nbx * lb->nby, 1);
    }
    ss_status st = SS_OK;
    int made = lb && buf && lb->blocks;
    if (made)
        st = ss_cell_store_open(ctx, src, SS_LIT_SECTORS, 1, &lb->fine);
    line_geometry g = geometry_of(families, sectors, w, h, src->cell_x_m, src->cell_y_m);
    far_pyramid far = {.n = 0};
    if (st == SS_OK && made)
        st = far_pyramid_of(ctx, src, rows, buf, &far, &made);
    for (int r0 = 0; st == SS_OK && made && r0 < h; r0 += rows)
        st = band_levels(lb, src, &g, &far, r0, r0 + rows < h ? r0 + rows : h, buf, &made);
    far_free(&far);
    free(buf);
    if (st == SS_OK && made)
        *out = lb;
    else
        ss_lit_bands_free(lb);
    return st;
}

size_t ss_lit_bands_bytes(const ss_lit_bands *lb, int held_rows)
{
    return (size_t)SS_LIT_SECTORS * ((size_t)held_rows * lb->width + (size_t)lb->nbx * lb->nby);
}

ss_status ss_lit_bands_read(ss_lit_bands *lb, int lo, int n, unsigned char *out)
{
    size_t plane = (size_t)n * lb->width;
    ss_status st = SS_OK;
    for (int k = 0; k < SS_LIT_SECTORS && st == SS_OK; ++k)
        st = ss_cell_store_get(lb->fine, k, lo, n, out + k * plane);
    if (st == SS_OK)
        memcpy(out + SS_LIT_SECTORS * plane, lb->blocks,
               (size_t)SS_LIT_SECTORS * lb->nbx * lb->nby);
    return st;
}
