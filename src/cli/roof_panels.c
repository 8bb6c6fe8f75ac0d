/* Panel layouts on roof planes: see roof_panels.h and doc/roofs.md. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "roof_panels.h"

#define DEG (M_PI / 180.0)
/* A module covers a cell where they overlap by more than this (metres): the
 * planes' fitted aspects are a hair off the grid's axes, and a module on a
 * usable strip's edge must not be refused for touching the next cell by
 * micrometres. */
#define COVER_EPS_M 1e-3

panel_geometry panel_geometry_on(const panel_options *o, int landscape, double plane_tilt_deg,
                                 double plane_aspect_grid_deg, double equator_grid_deg)
{
    panel_geometry g = {0};
    g.racked = plane_tilt_deg < o->flat_tilt_deg;
    g.landscape = landscape;
    g.tilt_deg = g.racked ? o->rack_tilt_deg : plane_tilt_deg;
    g.facing_grid_deg = g.racked ? equator_grid_deg : plane_aspect_grid_deg;
    double along = landscape ? o->length_m : o->width_m;
    double up = landscape ? o->width_m : o->length_m; /* on the module's own plane */
    double cos_t = cos(g.tilt_deg * DEG);
    g.along_m = along;
    g.pitch_along_m = along + o->module_spacing_m;
    g.depth_m = up * cos_t;
    if (g.racked) {
        /* the gap a rack's top edge (up sin tilt high) shades on the roof
         * with the sun at the design elevation straight ahead */
        double shadow = up * sin(g.tilt_deg * DEG) / tan(o->rack_sun_elevation_deg * DEG);
        g.pitch_depth_m = g.depth_m + fmax(o->row_spacing_m, shadow);
    } else
        g.pitch_depth_m = (up + o->row_spacing_m) * cos_t;
    return g;
}

/* The plane's frame on the ground: v up the slope (away from the way the
 * modules face), u along the rows to the right looking up the slope
 * (so rows start at the lower left corner looking up it); unit vectors
 * in (east, north). */
typedef struct {
    double ux, uy, vx, vy;
} frame2;

static frame2 frame_of(double facing_grid_deg)
{
    double s = sin(facing_grid_deg * DEG), c = cos(facing_grid_deg * DEG);
    return (frame2){-c, s, -s, -c};
}

/* Range of a cell's corners projected on (ax, ay). */
static void cell_range(int c, int r, double cx, double cy, double ax, double ay, double *lo,
                       double *hi)
{
    *lo = INFINITY, *hi = -INFINITY;
    for (int k = 0; k < 4; ++k) {
        double x = (c + (k & 1)) * cx, y = -(r + (k >> 1)) * cy;
        double p = x * ax + y * ay;
        *lo = fmin(*lo, p), *hi = fmax(*hi, p);
    }
}

static int overlaps(double lo1, double hi1, double lo2, double hi2)
{
    return fmin(hi1, hi2) - fmax(lo1, lo2) > COVER_EPS_M;
}

static int push_cell(panel_layout *l, int cell)
{
    if (l->n_cells == l->cap_cells) {
        size_t cap = l->cap_cells ? 2 * l->cap_cells : 256;
        int *p = realloc(l->cells, cap * sizeof *p);
        if (!p)
            return -1;
        l->cells = p, l->cap_cells = cap;
    }
    l->cells[l->n_cells++] = cell;
    return 0;
}

/* Places the module [u0, u0 + along] x [v0, v0 + depth] where every cell it
 * overlaps is usable (separating axes: the grid's and the module's).
 * Returns 1 placed, 0 not, -1 out of memory. */
static int try_module(const panel_geometry *g, const frame2 *f, double u0, double v0,
                      const unsigned char *usable, int cols, int rows, double cx, double cy,
                      panel_layout *l)
{
    double us[4] = {u0, u0 + g->along_m, u0 + g->along_m, u0};
    double vs[4] = {v0, v0, v0 + g->depth_m, v0 + g->depth_m};
    panel_place p = {.first = l->n_cells};
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int k = 0; k < 4; ++k) {
        p.corner[k][0] = us[k] * f->ux + vs[k] * f->vx;
        p.corner[k][1] = us[k] * f->uy + vs[k] * f->vy;
        x0 = fmin(x0, p.corner[k][0]), x1 = fmax(x1, p.corner[k][0]);
        y0 = fmin(y0, p.corner[k][1]), y1 = fmax(y1, p.corner[k][1]);
    }
    int c0 = (int)floor((x0 + COVER_EPS_M) / cx), c1 = (int)floor((x1 - COVER_EPS_M) / cx);
    int r0 = (int)floor((-y1 + COVER_EPS_M) / cy), r1 = (int)floor((-y0 - COVER_EPS_M) / cy);
    if (c0 < 0 || r0 < 0 || c1 >= cols || r1 >= rows)
        return 0;
    for (int r = r0; r <= r1; ++r)
        for (int c = c0; c <= c1; ++c) {
            double lo, hi;
            cell_range(c, r, cx, cy, f->ux, f->uy, &lo, &hi);
            if (!overlaps(lo, hi, u0, u0 + g->along_m))
                continue;
            cell_range(c, r, cx, cy, f->vx, f->vy, &lo, &hi);
            if (!overlaps(lo, hi, v0, v0 + g->depth_m))
                continue;
            if (!overlaps(c * cx, (c + 1) * cx, x0, x1) ||
                !overlaps(-(r + 1) * cy, -r * cy, y0, y1))
                continue;
            if (!usable[(size_t)r * cols + c]) {
                l->n_cells = p.first;
                return 0;
            }
            if (push_cell(l, r * cols + c) < 0)
                return -1;
        }
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 64;
        panel_place *q = realloc(l->items, cap * sizeof *q);
        if (!q)
            return -1;
        l->items = q, l->cap = cap;
    }
    p.n_cells = (int)(l->n_cells - p.first);
    l->items[l->n++] = p;
    return 1;
}

int panels_lay(const panel_geometry *g, const unsigned char *usable, int cols, int rows,
               double cx, double cy, panel_layout *out)
{
    out->n = 0, out->n_cells = 0;
    frame2 f = frame_of(g->facing_grid_deg);
    double u_lo = INFINITY, u_hi = -INFINITY, v_lo = INFINITY, v_hi = -INFINITY;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            if (!usable[(size_t)r * cols + c])
                continue;
            double lo, hi;
            cell_range(c, r, cx, cy, f.ux, f.uy, &lo, &hi);
            u_lo = fmin(u_lo, lo), u_hi = fmax(u_hi, hi);
            cell_range(c, r, cx, cy, f.vx, f.vy, &lo, &hi);
            v_lo = fmin(v_lo, lo), v_hi = fmax(v_hi, hi);
        }
    if (!(u_lo < u_hi))
        return 0;
    for (int j = 0;; ++j) {
        double v0 = v_lo + j * g->pitch_depth_m;
        if (v0 + g->depth_m > v_hi + COVER_EPS_M)
            break;
        for (int i = 0;; ++i) {
            double u0 = u_lo + i * g->pitch_along_m;
            if (u0 + g->along_m > u_hi + COVER_EPS_M)
                break;
            if (try_module(g, &f, u0, v0, usable, cols, rows, cx, cy, out) < 0)
                return -1;
        }
    }
    return 0;
}

void panel_layout_free(panel_layout *l)
{
    free(l->items);
    free(l->cells);
    *l = (panel_layout){0};
}
