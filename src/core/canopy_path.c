/* Trees, Beer-Lambert (doc/vegetation.md): how far the ray toward the sun
 * runs inside crowns.
 *
 * The levels are vegetation.c's: along a digital line walked from its
 * sunny end, lower every height by w tan(e), w the distance walked away
 * from the sun; the ray from cell i becomes the level z'_i and the crown
 * of a cell j ahead the open interval (bottom'_j, top'_j). The ray passes
 * inside crown j iff z'_i lies in j's interval, so the crowns it passes
 * are counted by the intervals ahead that hold z'_i: those whose bottom
 * lies below it less those whose top lies at or below it (every bottom
 * lies below its top). Two Fenwick trees over the line's sorted interval
 * ends keep both counts as the walk adds each cell's crown after
 * answering the cell: O(log n) a cell.
 *
 * Each crown cell passed counts the ray's horizontal run through one cell
 * of the line, the distance along the azimuth per step of the major axis,
 * hypot(c_major, m c_minor) (m the minor cells per major step), and the
 * slant path is that over cos(e). */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "crown_union.h"
#include "lines.h"
#include "products_internal.h"

typedef struct {
    double *ends;            /* the line's crown bottoms and tops, sorted */
    int *below, *at_or_below; /* Fenwick trees over ends: bottoms added, tops added */
    size_t n;
} interval_counts;

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The number of ends below z (strict) or at or below z. */
static size_t ends_before(const interval_counts *c, double z, int inclusive)
{
    size_t a = 0, b = c->n;
    while (a < b) {
        size_t m = a + (b - a) / 2;
        if (c->ends[m] < z || (inclusive && c->ends[m] == z))
            a = m + 1;
        else
            b = m;
    }
    return a;
}

static void fenwick_add(int *tree, size_t n, size_t at)
{
    for (size_t k = at + 1; k <= n; k += k & (~k + 1))
        ++tree[k - 1];
}

static int fenwick_prefix(const int *tree, size_t count)
{
    int sum = 0;
    for (size_t k = count; k > 0; k -= k & (~k + 1))
        sum += tree[k - 1];
    return sum;
}

/* One digital line: first its crowns' interval ends, then the walk. */
static void walk_line(const ss_grid *grid, const ss_canopy *canopy, const ss_line_set *ls,
                      int line, double t, double slant_per_cell_m, interval_counts *c,
                      float *path_m)
{
    c->n = 0;
    ss_line_cursor cur = ss_line_cursor_start(ls, line);
    while (ss_line_cursor_next(&cur)) {
        size_t i = cur.cell;
        double top = canopy->height_m[i], bottom = trunk_of(canopy, i);
        if (!isfinite(grid->z[i]) || !(top > bottom))
            continue;
        double rise = cur.walked_m * t;
        c->ends[c->n++] = grid->z[i] + bottom + rise;
        c->ends[c->n++] = grid->z[i] + top + rise;
    }
    if (c->n == 0)
        return; /* no crown: path_m stays 0 */
    qsort(c->ends, c->n, sizeof *c->ends, by_value);
    memset(c->below, 0, c->n * sizeof *c->below);
    memset(c->at_or_below, 0, c->n * sizeof *c->at_or_below);
    cur = ss_line_cursor_start(ls, line);
    while (ss_line_cursor_next(&cur)) {
        size_t i = cur.cell;
        float z = grid->z[i];
        if (!isfinite(z))
            continue;
        double rise = cur.walked_m * t, level = z + rise;
        int inside = fenwick_prefix(c->below, ends_before(c, level, 0)) -
                     fenwick_prefix(c->at_or_below, ends_before(c, level, 1));
        path_m[i] = (float)(inside * slant_per_cell_m);
        double top = canopy->height_m[i], bottom = trunk_of(canopy, i);
        if (top > bottom) {
            /* The ends were stored from these same sums: found exactly. */
            fenwick_add(c->below, c->n, ends_before(c, z + bottom + rise, 0));
            fenwick_add(c->at_or_below, c->n, ends_before(c, z + top + rise, 0));
        }
    }
}

ss_status ss_canopy_path(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                         double sun_grid_azimuth_deg, double sun_elevation_deg, float *path_m)
{
    ss_call_begin(ctx);
    if (!isfinite(sun_grid_azimuth_deg) || !(fabs(sun_elevation_deg) <= 90.0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun azimuth %g / elevation %g degrees is not a sun position",
                       sun_grid_azimuth_deg, sun_elevation_deg);
    size_t n = (size_t)grid->width * (size_t)grid->height;
    for (size_t i = 0; i < n; ++i)
        path_m[i] = isfinite(grid->z[i]) ? 0.0f : SS_NODATA;
    if (fabs(sun_elevation_deg) >= 90.0) /* the ray rises straight up, past no cell */
        return SS_OK;
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, grid->width, grid->height, grid->cell_x_m, grid->cell_y_m,
                            sun_grid_azimuth_deg, SS_LINE_MODEL_DIGITAL);
    ls.families = 1;
    double e = sun_elevation_deg * (M_PI / 180.0);
    double minor_per_major = (double)ls.slope_fx / 4294967296.0;
    double c_major = ls.major_is_row ? grid->cell_y_m : grid->cell_x_m,
           c_minor = ls.major_is_row ? grid->cell_x_m : grid->cell_y_m;
    double slant_per_cell_m = hypot(c_major, minor_per_major * c_minor) / cos(e);
    size_t longest = 2 * (size_t)ls.major_len;
    interval_counts c = {ss_malloc(longest * sizeof(double)), ss_malloc(longest * sizeof(int)),
                         ss_malloc(longest * sizeof(int)), 0};
    ss_status st = SS_OK;
    if (!c.ends || !c.below || !c.at_or_below)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns' paths");
    for (int line = 0; st == SS_OK && line < ss_line_count(&ls); ++line) {
        if (line % 256 == 0) /* Ctrl-C and ss_ctx_cancel reach a long sweep */
            st = ss_check_cancel(ctx, "the crowns' paths");
        if (st == SS_OK)
            walk_line(grid, canopy, &ls, line, tan(e), slant_per_cell_m, &c, path_m);
    }
    free(c.ends);
    free(c.below);
    free(c.at_or_below);
    return st;
}

ss_status ss_canopy_path_fraction(ss_ctx *ctx, double extinction, double leaf_area_density,
                                  size_t n, const float *path_m, float *fraction)
{
    ss_call_begin(ctx);
    if (!(extinction > 0.0 && extinction <= 1.0) ||
        !(leaf_area_density > 0.0 && leaf_area_density <= 20.0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "Beer-Lambert crowns need an extinction coefficient in (0, 1] and a leaf "
                       "area density in (0, 20] m2/m3 (got %g, %g)",
                       extinction, leaf_area_density);
    for (size_t i = 0; i < n; ++i)
        fraction[i] = path_m[i] == SS_NODATA
                          ? SS_NODATA
                          : (float)exp(-extinction * leaf_area_density * path_m[i]);
    return SS_OK;
}
