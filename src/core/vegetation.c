/* Trees: which rays toward the sun cross a crown (doc/vegetation.md).
 *
 * Along a line toward the sun, lower every height by s tan(e), s the
 * distance along the sun's azimuth: the ray from cell i becomes the level
 * z'_i, and the crown of a cell j ahead the open interval (bottom'_j,
 * top'_j). The ray crosses a crown iff z'_i lies inside the union of the
 * intervals of the cells ahead. Walking each line from its sunny end, the
 * union is kept as a sorted array of disjoint intervals: a binary search
 * answers each cell, then its own crown is merged in. The lines are the
 * engine's (lines.h): box lines where the solid sweep takes them, crowns
 * then columns from trunk to top; else digital lines. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "box_crowns.h"
#include "crown_union.h"
#include "lines.h"
#include "products_internal.h"

ss_status ss_canopy_check(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy)
{
    ss_call_begin(ctx);
    if (!(canopy->transmissivity >= 0.0 && canopy->transmissivity <= 1.0))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "transmissivity %g is not within 0..1",
                       canopy->transmissivity);
    if (!canopy->trunk_m && !(canopy->trunk_ratio >= 0.0 && canopy->trunk_ratio <= 1.0))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "trunk ratio %g is not within 0..1",
                       canopy->trunk_ratio);
    size_t n = (size_t)grid->width * (size_t)grid->height;
    for (size_t i = 0; i < n; ++i) {
        float h = canopy->height_m[i];
        double t = trunk_of(canopy, i);
        int height_ok = h >= 0.0f && isfinite(h), trunk_ok = t >= 0.0 && t <= h;
        if (height_ok && trunk_ok)
            continue;
        int row = (int)(i / (size_t)grid->width), col = (int)(i % (size_t)grid->width);
        if (!height_ok)
            return ss_fail(ctx, SS_ERR_INPUT,
                           "canopy height %g m at column %d, row %d is not a height of 0 or more",
                           h, col, row);
        return ss_fail(ctx, SS_ERR_INPUT,
                       "trunk height %g m at column %d, row %d is not within 0..%g m (its canopy "
                       "height)",
                       t, col, row, h);
    }
    return SS_OK;
}

/* One digital line of the engine's (lines.h, the same cells and distances
 * as the solid sweep's), walked from its sunny end: a cell's level is its
 * height plus w tan(e), w the distance walked away from the sun. */
static int walk_line(const ss_grid *grid, const ss_canopy *canopy, const ss_line_set *ls,
                     int line, double t, crown_union *u, unsigned char *crossed)
{
    u->n = 0;
    ss_line_cursor c = ss_line_cursor_start(ls, line);
    while (ss_line_cursor_next(&c)) {
        size_t i = c.cell;
        float z = grid->z[i];
        if (!isfinite(z))
            continue;
        double rise = c.walked_m * t;
        crossed[i] = union_holds(u, z + rise);
        double top = canopy->height_m[i], bottom = trunk_of(canopy, i);
        if (top > bottom && union_add(u, z + bottom + rise, z + top + rise) != 0)
            return -1;
    }
    return 0;
}

/* Box crowns: each crown a flat-topped column from its trunk to its top,
 * met by exact lines (box_lines families per cell across, as the solid
 * sweep's box lines, kernels/ss_box.h); each cell takes the family whose
 * line passes nearest its centre (at most half a spacing beside it). A
 * square crossed from walked distance wa to wb holds the levels (bottom +
 * min(w t), top + max(w t)). */
typedef struct {
    const ss_grid *grid;
    const ss_canopy *canopy;
    const ss_line_set *ls;
    double t, slope;
    double away_major, away_minor; /* distance walked per +1 major / minor index */
    unsigned char *crossed;
} box_walk;

static double walked(const box_walk *b, double major, double minor)
{
    return major * b->away_major + minor * b->away_minor;
}

static size_t box_cell(const box_walk *b, int major, int minor)
{
    return (size_t)major * (size_t)b->ls->stride_major + (size_t)minor * (size_t)b->ls->stride_minor;
}

/* Merges the crown of square (major, minor), crossed from x0 to x1 along
 * the major axis by the line y = y0 + (x - major) slope. */
static int box_add(const box_walk *b, crown_union *u, int major, int minor, double x0, double x1,
                   double y_at_major)
{
    if (minor < 0 || minor >= b->ls->minor_len)
        return 0;
    size_t i = box_cell(b, major, minor);
    float z = b->grid->z[i];
    double top = b->canopy->height_m[i], bottom = trunk_of(b->canopy, i);
    if (!isfinite(z) || !(top > bottom))
        return 0;
    double wa = walked(b, x0, y_at_major + (x0 - major) * b->slope) * b->t,
           wb = walked(b, x1, y_at_major + (x1 - major) * b->slope) * b->t;
    return union_add(u, z + bottom + fmin(wa, wb), z + top + fmax(wa, wb));
}

static int walk_box_line(const box_walk *b, int line, crown_union *u)
{
    const ss_line_set *ls = b->ls;
    u->n = 0;
    ss_i64 b16 = ss_line_intercept16(ls, line);
    ss_i64 half = 32768 / ls->families; /* half a family spacing, 16.16 */
    for (int k = 0; k < ls->major_len; ++k) {
        int m = ls->step > 0 ? k : ls->major_len - 1 - k;
        ss_i64 y16 = ss_line_y16(ls, b16, m); /* + one half: floor is the nearest cell */
        double y = (double)(y16 - 32768) / 65536.0;
        int n_centre = (int)ss_floor16(y16);
        ss_i64 delta16 = y16 - (ss_i64)n_centre * 65536 - 32768;
        int answers = delta16 >= -half && delta16 < half && n_centre >= 0 &&
                      n_centre < ls->minor_len;
        /* The column's squares in walk order: from x_in to x_out. */
        double x_in = m - 0.5 * ls->step, x_out = m + 0.5 * ls->step;
        int n_in = (int)floor(y + (x_in - m) * b->slope + 0.5),
            n_out = (int)floor(y + (x_out - m) * b->slope + 0.5);
        double x_cross = n_in == n_out ? x_out
                                       : m + ((n_in + n_out) / 2.0 - y) / b->slope;
        /* The cell answered looks past the squares ahead of its centre
         * only: the first square when its centre lies in the second. */
        int centre_second = answers && n_out != n_in && n_centre == n_out;
        if (centre_second && box_add(b, u, m, n_in, x_in, x_cross, y) != 0)
            return -1;
        if (answers) {
            size_t i = box_cell(b, m, n_centre);
            if (isfinite(b->grid->z[i]))
                b->crossed[i] = union_holds(u, b->grid->z[i] + walked(b, m, n_centre) * b->t);
        }
        if (!centre_second && box_add(b, u, m, n_in, x_in, x_cross, y) != 0)
            return -1;
        if (n_out != n_in && box_add(b, u, m, n_out, x_cross, x_out, y) != 0)
            return -1;
    }
    return 0;
}

/* Box crowns by each cell's own ray (box_crowns.h). */
static ss_status crossed_by_rays(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                 double sun_grid_azimuth_deg, double sun_elevation_deg, int row0,
                                 int n_rows, const float *solid_angle, double solid_el_hi,
                                 unsigned char *crossed)
{
    ss_box_ray_counts counts;
    if (!ss_box_crowns_crossed(grid, canopy, sun_grid_azimuth_deg, sun_elevation_deg, row0,
                               n_rows, solid_angle, solid_el_hi, &ctx->cancel_requested, crossed,
                               &counts))
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns' rays");
    ctx->counters.crown_march_steps += row0 == 0; /* a sun counts once, at its first band */
    ctx->counters.crown_march_cells += counts.cells;
    ctx->counters.crown_march_marched += counts.marched;
    return ss_check_cancel(ctx, "the crowns' rays");
}

ss_status ss_canopy_crossed(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                            const ss_sweep_options *lines, double sun_grid_azimuth_deg,
                            double sun_elevation_deg, unsigned char *crossed)
{
    return ss_canopy_crossed_where_lit(ctx, grid, canopy, lines, sun_grid_azimuth_deg,
                                       sun_elevation_deg, 0, grid->height, NULL, 0.0, crossed);
}

ss_status ss_canopy_crossed_where_lit(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                      const ss_sweep_options *lines, double sun_grid_azimuth_deg,
                                      double sun_elevation_deg, int row0, int n_rows,
                                      const float *solid_angle, double solid_el_hi,
                                      unsigned char *crossed)
{
    ss_call_begin(ctx);
    if (!isfinite(sun_grid_azimuth_deg) || !(fabs(sun_elevation_deg) <= 90.0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun azimuth %g / elevation %g degrees is not a sun position",
                       sun_grid_azimuth_deg, sun_elevation_deg);
    size_t n = (size_t)grid->width * (size_t)grid->height;
    int box = lines && lines->lines == SS_LINES_BOX;
    /* The rays answer the rows asked for (and clear them) ... */
    if (box && lines->box_shadows == SS_BOX_SHADOWS_MARCH && sun_elevation_deg > 0.0 &&
        sun_elevation_deg < 90.0)
        return crossed_by_rays(ctx, grid, canopy, sun_grid_azimuth_deg, sun_elevation_deg, row0,
                               n_rows, solid_angle, solid_el_hi, crossed);
    /* ... the lines' walks every row. */
    memset(crossed, 0, n);
    if (fabs(sun_elevation_deg) >= 90.0) /* the ray rises straight up, past no cell */
        return SS_OK;
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, grid->width, grid->height, grid->cell_x_m, grid->cell_y_m,
                            sun_grid_azimuth_deg,
                            box ? SS_LINE_MODEL_BOX : SS_LINE_MODEL_DIGITAL);
    ls.families = box ? lines->box_lines : 1;
    double t = tan(sun_elevation_deg * M_PI / 180.0);
    /* Box lines: distances walked (away from the sun) per index, as lines.c. */
    double az = sun_grid_azimuth_deg * (M_PI / 180.0);
    double per_col = -sin(az) * grid->cell_x_m, per_row = cos(az) * grid->cell_y_m;
    box_walk bw = {grid, canopy, &ls, t, (double)ls.slope_fx / 4294967296.0,
                   ls.major_is_row ? per_row : per_col, ls.major_is_row ? per_col : per_row,
                   crossed};
    ss_status st = SS_OK;
    int n_lines = ss_line_count(&ls), failed = 0;
    /* The lines in blocks, on threads: each cell is answered by one line
     * (one family's, on box lines), so the lines write apart and the result
     * is the same on any number of threads. Between blocks, Ctrl-C and
     * ss_ctx_cancel reach a long sweep. */
    for (int first = 0; first < n_lines && st == SS_OK && !failed; first += 4096) {
        st = ss_check_cancel(ctx, "the crown sweep");
        int last = first + 4096 < n_lines ? first + 4096 : n_lines;
#pragma omp parallel if (st == SS_OK) reduction(| : failed)
        {
            crown_union u = {0};
#pragma omp for schedule(dynamic, 16)
            for (int line = first; line < last; ++line)
                failed |= (box ? walk_box_line(&bw, line, &u)
                               : walk_line(grid, canopy, &ls, line, t, &u, crossed)) != 0;
            free(u.span);
        }
    }
    if (st == SS_OK && failed)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns of a line");
    return st;
}

void ss_canopy_classes(const ss_canopy *canopy, size_t n, const float *sunlit,
                       const unsigned char *crossed, float *klass, float *fraction)
{
    for (size_t i = 0; i < n; ++i) {
        if (sunlit[i] == SS_NODATA) {
            klass[i] = fraction[i] = SS_NODATA;
        } else if (sunlit[i] != 1.0f) {
            klass[i] = 1.0f;
            fraction[i] = 0.0f;
        } else if (crossed[i]) {
            klass[i] = 2.0f;
            fraction[i] = (float)canopy->transmissivity;
        } else {
            klass[i] = 0.0f;
            fraction[i] = 1.0f;
        }
    }
}
