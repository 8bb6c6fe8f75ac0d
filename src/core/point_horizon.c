/* Point horizons (skysweep_sites.h). For each direction, the line samples
 * that feed the site's cells in the sweep are found, and each one's horizon
 * is the largest elevation over the occluding samples ahead of it on its
 * line: what the sweep's hull gives it (kernels/ss_sweep.h), found here by
 * walking the line outward from the sample. Block maxima of the heights
 * bound what a stretch of line can cast, so most of a long line is skipped
 * after one look-up per block. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "skysweep_sites.h"
#include "products_internal.h"
#include "ss_sweep.h"

/* Maxima of the heights over square blocks, in levels of 8, 32, 128, 512
 * and 2048 cells a side: a stretch of line that one block holds along the
 * major axis lies within 1 to 3 blocks of that level across it. Together
 * the levels take 1/60 of the grid's memory. (On the Kilauea DEM blocks of
 * 8 to 2048 left a fifth fewer samples to evaluate than 16 to 1024 and ran
 * about 25 % faster; blocks of 4 cost more look-ups than they saved.) */
#define SS_BLOCK_LOG2 3
#define SS_LEVELS 5
#define SS_LEVEL_LOG2(level) (SS_BLOCK_LOG2 + 2 * (level))

/* Bilinear cells and line samples feeding one site. */
#define SS_SITE_CELLS 4
#define SS_SITE_SAMPLES (2 * SS_SITE_CELLS)

struct ss_point_grid {
    const ss_grid *grid;
    float *block_max[SS_LEVELS]; /* highest height per block, -INFINITY where all nodata */
    int blocks_x[SS_LEVELS], blocks_y[SS_LEVELS];
};

typedef struct {
    int col, row;
    double weight;
} site_cell;

/* One direction's geometry, shared by the walks of all samples. */
typedef struct {
    ss_line_set ls;
    double per_major_m, per_minor_m; /* distance walked per +1 major / minor index */
    ss_i64 dy16_per_major;           /* line position change per +1 major index, 16.16 */
    ss_i64 y16_lo, y16_hi;           /* positions of samples that may occlude */
    int digital;
    double curv_k; /* 1 / (2 R_eff), 0 without curvature */
} direction;

/* A sample's horizon: the best curved slope (dz - k d^2) / d over the
 * occluders ahead, and which sample gave it (k = steps ahead, 0: none). */
typedef struct {
    int major;
    ss_i64 y16;
    double weight;
    double z_view; /* viewpoint height (grid frame): the sample's + observer's */
    double slope;
    int best_k;
    double best_z;
} sample_walk;

ss_status ss_point_grid_new(ss_ctx *ctx, const ss_grid *grid, ss_point_grid **out)
{
    ss_call_begin(ctx);
    *out = NULL;
    ss_status st = ss_grid_check(ctx, grid, NULL);
    if (st != SS_OK)
        return st;
    ss_point_grid *pg = ss_calloc(1, sizeof *pg);
    if (!pg)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory preparing point horizons");
    pg->grid = grid;
    for (int l = 0; l < SS_LEVELS; ++l) {
        int side = 1 << SS_LEVEL_LOG2(l);
        pg->blocks_x[l] = (grid->width + side - 1) >> SS_LEVEL_LOG2(l);
        pg->blocks_y[l] = (grid->height + side - 1) >> SS_LEVEL_LOG2(l);
        size_t n = (size_t)pg->blocks_x[l] * (size_t)pg->blocks_y[l];
        pg->block_max[l] = ss_malloc(sizeof(float) * n);
        if (!pg->block_max[l]) {
            ss_point_grid_free(pg);
            return ss_fail(ctx, SS_ERR_MEMORY, "out of memory preparing point horizons");
        }
        for (size_t i = 0; i < n; ++i)
            pg->block_max[l][i] = -INFINITY;
    }
    float *bm = pg->block_max[0];
    for (int r = 0; r < grid->height; ++r) {
        const float *zr = grid->z + (size_t)r * grid->width;
        float *bmr = bm + (size_t)(r >> SS_BLOCK_LOG2) * pg->blocks_x[0];
        for (int c = 0; c < grid->width; ++c)
            if (zr[c] > bmr[c >> SS_BLOCK_LOG2]) /* false for NaN: nodata drops out */
                bmr[c >> SS_BLOCK_LOG2] = zr[c];
    }
    for (int l = 1; l < SS_LEVELS; ++l)
        for (int by = 0; by < pg->blocks_y[l - 1]; ++by)
            for (int bx = 0; bx < pg->blocks_x[l - 1]; ++bx) {
                float b = pg->block_max[l - 1][(size_t)by * pg->blocks_x[l - 1] + bx];
                float *up = &pg->block_max[l][(size_t)(by >> 2) * pg->blocks_x[l] + (bx >> 2)];
                *up = b > *up ? b : *up;
            }
    *out = pg;
    return SS_OK;
}

void ss_point_grid_free(ss_point_grid *pg)
{
    if (pg) {
        for (int l = 0; l < SS_LEVELS; ++l)
            free(pg->block_max[l]);
        free(pg);
    }
}

/* The bilinear cells around a site that have heights, weights summing to 1.
 * Returns their number, or 0 after recording why the site is refused. */
static int site_cells(ss_ctx *ctx, const ss_grid *g, double col, double row,
                      site_cell cells[SS_SITE_CELLS])
{
    if (!(col >= -0.5 && col <= g->width - 0.5 && row >= -0.5 && row <= g->height - 0.5)) {
        ss_fail(ctx, SS_ERR_ARGUMENT,
                "site at column %g, row %g lies outside the %d x %d grid (cell centres are "
                "whole numbers; edges at -0.5 and size - 0.5)",
                col, row, g->width, g->height);
        return 0;
    }
    /* The site's own cell (whose square holds it) must have a height: a
     * horizon over nodata (sea, a void) would be made up from neighbours. */
    int own_c = (int)floor(col + 0.5), own_r = (int)floor(row + 0.5);
    own_c = own_c < g->width ? own_c : g->width - 1;
    own_r = own_r < g->height ? own_r : g->height - 1;
    if (!isfinite(g->z[(size_t)own_r * g->width + own_c])) {
        ss_fail(ctx, SS_ERR_ARGUMENT, "site at column %g, row %g lies on a nodata cell", col, row);
        return 0;
    }
    int c0 = (int)floor(col), r0 = (int)floor(row);
    double fc = col - c0, fr = row - r0, total = 0.0;
    int n = 0;
    for (int i = 0; i < 4; ++i) {
        int c = c0 + (i & 1), r = r0 + (i >> 1);
        double w = ((i & 1) ? fc : 1.0 - fc) * ((i >> 1) ? fr : 1.0 - fr);
        if (w <= 0.0 || c < 0 || r < 0 || c >= g->width || r >= g->height ||
            !isfinite(g->z[(size_t)r * g->width + c]))
            continue;
        cells[n].col = c;
        cells[n].row = r;
        cells[n].weight = w;
        total += w;
        n++;
    }
    for (int i = 0; i < n; ++i)
        cells[i].weight /= total;
    return n;
}

ss_status ss_point_ground_height(ss_ctx *ctx, const ss_point_grid *pg, double col, double row,
                                 double *height_m)
{
    ss_call_begin(ctx);
    site_cell cells[SS_SITE_CELLS];
    const ss_grid *g = pg->grid;
    int n = site_cells(ctx, g, col, row, cells);
    if (n == 0)
        return SS_ERR_ARGUMENT;
    double z = 0.0;
    for (int i = 0; i < n; ++i)
        z += cells[i].weight * g->z[(size_t)cells[i].row * g->width + cells[i].col];
    *height_m = z + g->z_origin_m;
    return SS_OK;
}

static void direction_open(const ss_grid *g, const ss_sweep_options *opt, double azimuth_deg,
                           double grid_north_deg, direction *dir)
{
    ss_sweep_options o = *opt;
    o.grid_north_deg = grid_north_deg;
    /* The sweep's own line set for this azimuth, so samples coincide. */
    double az_rad = ss_product_lines_at(g, &o, azimuth_deg, &dir->ls);
    /* Distance walked (away from the azimuth) per +1 column and +1 row, as
     * the sample positions of tests/testlib.c's brute force. */
    double per_col = -sin(az_rad) * g->cell_x_m, per_row = cos(az_rad) * g->cell_y_m;
    const ss_line_set *ls = &dir->ls;
    dir->per_major_m = ls->major_is_row ? per_row : per_col;
    dir->per_minor_m = ls->major_is_row ? per_col : per_row;
    dir->dy16_per_major = ls->slope_fx / 65536;
    dir->digital = ls->model == SS_LINE_MODEL_DIGITAL;
    /* An occluder needs every cell with a positive weight inside the grid
     * (ss_sample_cells): position 0 .. minor_len - 1 exactly on
     * interpolated lines, the nearest cell inside on digital ones. */
    dir->y16_lo = 0;
    dir->y16_hi =
        dir->digital ? (ss_i64)ls->minor_len * 65536 - 1 : (ss_i64)(ls->minor_len - 1) * 65536;
    dir->curv_k = ss_curvature_k(opt);
}

/* Position along the walk, metres: the exact point on interpolated lines,
 * the cell centre on digital ones (ss_hull_x). */
static inline double walk_pos_m(const direction *dir, int major, ss_i64 y16)
{
    double minor = dir->digital ? (double)ss_floor16(y16) : (double)y16 / 65536.0;
    return major * dir->per_major_m + minor * dir->per_minor_m;
}

static inline ss_i64 floor_div(ss_i64 a, ss_i64 b)
{
    ss_i64 q = a / b;
    return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

static inline ss_i64 ceil_div(ss_i64 a, ss_i64 b)
{
    return -floor_div(-a, b);
}

/* Steps ahead [*k_lo, *k_hi] whose samples may occlude: inside the grid
 * along the major axis, positions within [y16_lo, y16_hi] (monotone in k). */
static void occluder_range(const direction *dir, const sample_walk *v, ss_i64 *k_lo, ss_i64 *k_hi)
{
    const ss_line_set *ls = &dir->ls;
    ss_i64 lo = 1, hi = ls->step > 0 ? v->major : ls->major_len - 1 - v->major;
    ss_i64 rise = -(ss_i64)ls->step * dir->dy16_per_major; /* y16 change per step ahead */
    if (rise > 0) {
        ss_i64 a = ceil_div(dir->y16_lo - v->y16, rise), b = floor_div(dir->y16_hi - v->y16, rise);
        lo = a > lo ? a : lo;
        hi = b < hi ? b : hi;
    } else if (rise < 0) {
        ss_i64 a = ceil_div(v->y16 - dir->y16_hi, -rise),
               b = floor_div(v->y16 - dir->y16_lo, -rise);
        lo = a > lo ? a : lo;
        hi = b < hi ? b : hi;
    } else if (v->y16 < dir->y16_lo || v->y16 > dir->y16_hi) {
        hi = 0;
    }
    *k_lo = lo;
    *k_hi = hi;
}

/* Highest height of the level's blocks that samples at steps [ka, kb] of
 * v's line (within one block along the major axis) may read. */
static float stretch_max(const ss_point_grid *pg, int level, const direction *dir,
                         const sample_walk *v, ss_i64 ka, ss_i64 kb)
{
    const ss_line_set *ls = &dir->ls;
    ss_i64 rise = -(ss_i64)ls->step * dir->dy16_per_major;
    ss_i64 fa = ss_floor16(v->y16 + ka * rise), fb = ss_floor16(v->y16 + kb * rise);
    ss_i64 lo = fa < fb ? fa : fb, hi = (fa > fb ? fa : fb) + (dir->digital ? 0 : 1);
    lo = lo > 0 ? lo : 0;
    hi = hi < ls->minor_len - 1 ? hi : ls->minor_len - 1;
    int shift = SS_LEVEL_LOG2(level);
    int major_block = (int)((v->major - ka * ls->step) >> shift);
    const float *bm = pg->block_max[level];
    float m = -INFINITY;
    for (int nb = (int)(lo >> shift); nb <= (int)(hi >> shift); ++nb) {
        int bx = ls->major_is_row ? nb : major_block, by = ls->major_is_row ? major_block : nb;
        float b = bm[(size_t)by * pg->blocks_x[level] + bx];
        m = b > m ? b : m;
    }
    return m;
}

/* Walks v's line outward and keeps the best curved slope; on ties the
 * farther sample wins, as the hull keeps the farthest of equal horizons.
 * Stretches that no block maximum lets beat the best are skipped; after a
 * skip the next try is one level larger, after a failed try one smaller,
 * so long low stretches go by in a few look-ups. */
static void walk_sample(const ss_point_grid *pg, const direction *dir, sample_walk *v)
{
    const ss_line_set *ls = &dir->ls;
    const float *z = pg->grid->z;
    v->slope = -INFINITY;
    v->best_k = 0;
    ss_i64 k_lo, k_hi;
    occluder_range(dir, v, &k_lo, &k_hi);
    ss_i64 rise = -(ss_i64)ls->step * dir->dy16_per_major;
    double pos_v = walk_pos_m(dir, v->major, v->y16), k_curv = dir->curv_k;
    int level = 0;
    for (ss_i64 ka = k_lo; ka <= k_hi;) {
        /* The stretch: the steps whose major index stays in one block. */
        int major_a = (int)(v->major - ka * ls->step);
        int mask = (1 << SS_LEVEL_LOG2(level)) - 1;
        int left = ls->step > 0 ? (major_a & mask) : mask - (major_a & mask);
        ss_i64 kb = ka + left < k_hi ? ka + left : k_hi;
        double top = stretch_max(pg, level, dir, v, ka, kb) - v->z_view;
        double d_near = pos_v - walk_pos_m(dir, major_a, v->y16 + ka * rise);
        double d_far = pos_v - walk_pos_m(dir, (int)(v->major - kb * ls->step), v->y16 + kb * rise);
        /* No sample of the stretch rises above top, so none beats this. */
        double bound = top / (top >= 0.0 ? d_near : d_far) - k_curv * d_near;
        if (bound < v->slope) {
            ka = kb + 1;
            level += level < SS_LEVELS - 1;
            continue;
        }
        if (level > 0) {
            level--;
            continue;
        }
        for (ss_i64 k = ka; k <= kb; ++k) {
            int major = (int)(v->major - k * ls->step);
            ss_i64 y16 = v->y16 + k * rise, minor0 = ss_floor16(y16);
            float w1 = (float)(int)(y16 - minor0 * 65536) * ls->weight_per_frac;
            size_t cell = (size_t)major * ls->stride_major + (size_t)minor0 * ls->stride_minor;
            double zt = z[cell];
            if (w1 > 0.0f)
                zt += (double)w1 * ((double)z[cell + ls->stride_minor] - zt);
            if (!isfinite(zt)) /* a nodata cell: no full interpolation, no occluder */
                continue;
            double d = pos_v - walk_pos_m(dir, major, y16);
            double slope = (zt - v->z_view) / d - k_curv * d;
            if (slope >= v->slope) {
                v->slope = slope;
                v->best_k = (int)k;
                v->best_z = zt;
            }
        }
        ka = kb + 1;
    }
}

/* Which samples feed one of the site's cells, with their sample weights
 * (not multiplied by the cell's): the cell's horizon is their mean over
 * those with terrain ahead, as the sweep gives it (ss_pass_horizon_walk). */
typedef struct {
    int n;
    int sample[2];
    double weight[2];
} cell_feed;

/* The samples feeding the site's cells in this direction (two per cell on
 * interpolated lines, where the cell is cell0 of one sample and cell1 of
 * the next line's), merged where cells share one; feed[i] lists cell i's. */
static int site_samples(const ss_grid *g, const direction *dir, const site_cell *cells, int n_cells,
                        double observer_height_m, sample_walk *out, cell_feed *feed)
{
    const ss_line_set *ls = &dir->ls;
    int n = 0;
    for (int i = 0; i < n_cells; ++i) {
        int major = ls->major_is_row ? cells[i].row : cells[i].col;
        int minor = ls->major_is_row ? cells[i].col : cells[i].row;
        ss_i64 y0 = ss_line_y16(ls, 0, major);
        ss_i64 frac = y0 - ss_floor16(y0) * 65536;
        float w1 = (float)(int)frac * ls->weight_per_frac;
        feed[i].n = w1 > 0.0f ? 2 : 1;
        for (int s = 0; s < feed[i].n; ++s) {
            ss_i64 y16 = (ss_i64)(minor - s) * 65536 + frac;
            double sw = s == 0 ? 1.0 - (double)w1 : (double)w1;
            double w = cells[i].weight * sw;
            int j = 0;
            while (j < n && !(out[j].major == major && out[j].y16 == y16))
                j++;
            feed[i].sample[s] = j;
            feed[i].weight[s] = sw;
            if (j < n) {
                out[j].weight += w;
                continue;
            }
            float base, offset;
            ss_line_sample p = ss_line_sample_y16(ls, major, y16);
            ss_sample_cells(ls, p, g->z, &base, &offset);
            out[n].major = major;
            out[n].y16 = y16;
            out[n].weight = w;
            out[n].z_view = (double)base + (double)offset + observer_height_m;
            n++;
        }
    }
    return n;
}

/* Each cell's horizon as the sweep gives it (the mean over its samples
 * with terrain ahead, none where none has), mixed over the cells that have
 * one with their bilinear weights renormalised, as cells outside the grid
 * or nodata drop out: -90 only where no cell sees terrain ahead. */
static double site_elevation(const sample_walk *smp, const site_cell *cells,
                             const cell_feed *feed, int n_cells)
{
    double sum_deg = 0.0, sum_w = 0.0;
    for (int i = 0; i < n_cells; ++i) {
        double cell_deg = 0.0, cell_w = 0.0;
        for (int s = 0; s < feed[i].n; ++s) {
            const sample_walk *v = &smp[feed[i].sample[s]];
            if (v->best_k == 0)
                continue;
            cell_deg += feed[i].weight[s] * atan(v->slope) * (180.0 / M_PI);
            cell_w += feed[i].weight[s];
        }
        if (cell_w > 0.0) {
            sum_deg += cells[i].weight * (cell_deg / cell_w);
            sum_w += cells[i].weight;
        }
    }
    return sum_w > 0.0 ? sum_deg / sum_w : -90.0;
}

static void point_direction(const ss_point_grid *pg, const ss_sweep_options *opt,
                            const ss_point_site *site, const site_cell *cells, int n_cells,
                            double azimuth_deg, ss_point_horizon_result *res)
{
    const ss_grid *g = pg->grid;
    direction dir;
    direction_open(g, opt, azimuth_deg, site->grid_north_deg, &dir);
    sample_walk smp[SS_SITE_SAMPLES];
    cell_feed feed[SS_SITE_CELLS];
    int n = site_samples(g, &dir, cells, n_cells, site->observer_height_m, smp, feed);
    int dominant = 0;
    for (int j = 0; j < n; ++j) {
        walk_sample(pg, &dir, &smp[j]);
        /* The largest weight among samples with terrain ahead, if any;
         * strictly larger: at equal weights the first (the cell's own
         * line) wins, as in the sweep. */
        int ahead = smp[j].best_k != 0, ahead_dominant = smp[dominant].best_k != 0;
        if (ahead > ahead_dominant ||
            (ahead == ahead_dominant && smp[j].weight > smp[dominant].weight))
            dominant = j;
    }
    res->azimuth_deg = azimuth_deg;
    res->elevation_deg = site_elevation(smp, cells, feed, n_cells);
    /* The casting point is the one of the sample with the largest weight
     * among those with terrain ahead: the mixed elevation has no single
     * caster. */
    const sample_walk *v = &smp[dominant];
    if (v->best_k == 0) {
        res->distance_m = 0.0;
        res->cast_col = res->cast_row = res->cast_height_m = NAN;
        return;
    }
    const ss_line_set *ls = &dir.ls;
    int major = v->major - v->best_k * ls->step;
    ss_i64 y16 = v->y16 - (ss_i64)v->best_k * ls->step * dir.dy16_per_major;
    double minor = dir.digital ? (double)ss_floor16(y16) : (double)y16 / 65536.0;
    res->cast_col = ls->major_is_row ? minor : major;
    res->cast_row = ls->major_is_row ? major : minor;
    res->cast_height_m = v->best_z + g->z_origin_m;
    res->distance_m =
        hypot((res->cast_col - site->col) * g->cell_x_m, (res->cast_row - site->row) * g->cell_y_m);
}

/* Sweep options that point horizons can take: their lines are walked
 * from the site itself, which box lines do not model. */
static ss_status point_options_check(ss_ctx *ctx, const ss_sweep_options *opt)
{
    ss_status st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK && opt->lines == SS_LINES_BOX)
        st = ss_fail(ctx, SS_ERR_ARGUMENT,
                     "site horizons take interpolated or digital lines, not box lines");
    return st;
}

/* Checks a site and finds its bilinear cells; 0 after a failure. */
static int site_prepare(ss_ctx *ctx, const ss_point_grid *pg, const ss_point_site *site,
                        site_cell cells[SS_SITE_CELLS])
{
    if (!(site->observer_height_m >= 0.0 && site->observer_height_m <= 1e6)) {
        ss_fail(ctx, SS_ERR_ARGUMENT, "observer height must be 0 to 1e6 m, not %g",
                site->observer_height_m);
        return 0;
    }
    if (!isfinite(site->grid_north_deg) || fabs(site->grid_north_deg) > 360.0) {
        ss_fail(ctx, SS_ERR_ARGUMENT, "grid north must be within -360..360 degrees, not %g",
                site->grid_north_deg);
        return 0;
    }
    return site_cells(ctx, pg->grid, site->col, site->row, cells);
}

ss_status ss_point_horizon(ss_ctx *ctx, const ss_point_grid *pg, const ss_sweep_options *opt,
                           const ss_point_site *site, ss_point_horizon_result *out)
{
    ss_call_begin(ctx);
    ss_status st = point_options_check(ctx, opt);
    if (st != SS_OK)
        return st;
    site_cell cells[SS_SITE_CELLS];
    int n_cells = site_prepare(ctx, pg, site, cells);
    if (n_cells == 0)
        return SS_ERR_ARGUMENT;
    int n = opt->directions;
#pragma omp parallel for schedule(dynamic, 4) if (n > 8)
    for (int i = 0; i < n; ++i)
        point_direction(pg, opt, site, cells, n_cells, ss_direction_azimuth(opt, i), &out[i]);
    return SS_OK;
}

/* Sites computed together in one parallel loop over their directions: one
 * fork and join per batch instead of per site, which matters when cores are
 * shared (a late thread holds every join). */
#define SS_SITE_BATCH 32

ss_status ss_point_horizons(ss_ctx *ctx, const ss_point_grid *pg, const ss_sweep_options *opt,
                            const ss_point_site *sites, int n_sites, ss_point_sink sink, void *user)
{
    ss_call_begin(ctx);
    ss_status st = point_options_check(ctx, opt);
    if (st != SS_OK)
        return st;
    int n_dir = opt->directions;
    ss_point_horizon_result *res = ss_malloc(sizeof *res * (size_t)n_dir * SS_SITE_BATCH);
    site_cell(*cells)[SS_SITE_CELLS] = ss_malloc(sizeof *cells * SS_SITE_BATCH);
    int n_cells[SS_SITE_BATCH];
    if (!res || !cells)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for profiles of %d directions", n_dir);
    for (int first = 0; first < n_sites && st == SS_OK; first += SS_SITE_BATCH) {
        int batch = n_sites - first < SS_SITE_BATCH ? n_sites - first : SS_SITE_BATCH;
        for (int b = 0; b < batch && st == SS_OK; ++b)
            if ((n_cells[b] = site_prepare(ctx, pg, &sites[first + b], cells[b])) == 0)
                st = SS_ERR_ARGUMENT;
        if (st != SS_OK)
            break;
        long long n = (long long)batch * n_dir;
#pragma omp parallel for schedule(dynamic, 8)
        for (long long j = 0; j < n; ++j) {
            int b = (int)(j / n_dir), i = (int)(j % n_dir);
            point_direction(pg, opt, &sites[first + b], cells[b], n_cells[b],
                            ss_direction_azimuth(opt, i), &res[j]);
        }
        for (int b = 0; b < batch && st == SS_OK; ++b) {
            if (!sink(first + b, res + (size_t)b * n_dir, user))
                st = ss_fail(ctx, SS_ERR_CANCELLED, "stopped while storing site %d", first + b + 1);
            if (st == SS_OK)
                st = ss_progress(ctx, (double)(first + b + 1) / n_sites, "point horizons");
        }
    }
    free(res);
    free(cells);
    return st;
}
