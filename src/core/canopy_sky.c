/* Trees in the sky view (doc/vegetation.md, "svf"): the share of each
 * cell's sky that crowns hide above the solid horizon.
 *
 * Both horizons, seen from the cell's surface (the ground under its own
 * crown, which it does not see), are tangents from the cell to the upper
 * convex hull of the cells walked before it on the direction's digital
 * line (the engine's lines, lines.h, walked from the far end): the solid
 * horizon of the DSM, and the canopy-top horizon of DSM + canopy. O(log n)
 * a cell, exact on those lines, no distance limit, the earth flat.
 *
 * Trunk gaps ignored (SS_TRUNK_GAPS_IGNORE): every crown is a column from
 * the ground to its top, so the crowns hide the elevations between the two
 * horizons. Open (SS_TRUNK_GAPS_OPEN): the crowns hide the union of their
 * rises, (bottom - z) / d to (top - z) / d for each crown cell d before
 * the cell, above the solid horizon; the crowns are taken nearest first,
 * and the walk back stops once the union covers everything from the solid
 * horizon to the canopy-top horizon (at once under a closed canopy).
 *
 * ss_canopy_top_horizon gives the crowns' part of the canopy-top horizon
 * alone, per direction: the same walk with a hull of the crown tops. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "crown_union.h"
#include "lines.h"
#include "products_internal.h"
#include "ss_sun.h"

typedef struct {
    double w, z; /* distance walked, height */
} hull_point;

/* The upper convex hull of the points walked so far on a line, their w
 * rising. */
typedef struct {
    hull_point *p;
    size_t n;
} upper_hull;

/* (b - a) x (c - a) >= 0: b lies on or below the chord a-c, so it leaves
 * the upper hull. */
static int not_above_chord(hull_point a, hull_point b, hull_point c)
{
    return (b.w - a.w) * (c.z - a.z) - (b.z - a.z) * (c.w - a.w) >= 0.0;
}

static void hull_add(upper_hull *h, hull_point q)
{
    while (h->n > 0 && h->p[h->n - 1].w >= q.w) { /* the same distance: the higher stays */
        if (h->p[h->n - 1].z >= q.z)
            return;
        --h->n;
    }
    while (h->n >= 2 && not_above_chord(h->p[h->n - 2], h->p[h->n - 1], q))
        --h->n;
    h->p[h->n++] = q;
}

/* The steepest rise (dz / dw) from q back to the hull's points, q beyond
 * them all; -HUGE_VAL where the hull is empty. Along an upper hull the
 * rise is unimodal: a binary search for its peak. */
static double hull_rise(const upper_hull *h, hull_point q)
{
    if (h->n == 0)
        return -HUGE_VAL;
    size_t a = 0, b = h->n - 1;
    while (a < b) {
        size_t m = a + (b - a) / 2;
        hull_point p0 = h->p[m], p1 = h->p[m + 1];
        /* rise to p1 >= rise to p0, the denominators (q.w - p.w) > 0 */
        if ((p1.z - q.z) * (q.w - p0.w) >= (p0.z - q.z) * (q.w - p1.w))
            a = m + 1;
        else
            b = m;
    }
    return (h->p[a].z - q.z) / (q.w - h->p[a].w);
}

/* The share of one direction's sky that a horizon of rise t (tan of its
 * elevation) hides, clipped at the horizontal: sin h (geometric) or
 * 1 - cos^2 h (horizontal), as the SVF's terms (kernels/ss_terms.h). */
static double hidden_share(ss_svf_definition definition, double t)
{
    if (!(t > 0.0))
        return 0.0;
    return definition == SS_SVF_DEF_GEOMETRIC ? t / sqrt(1.0 + t * t) : t * t / (1.0 + t * t);
}

/* A crown walked on the line: where, and its bottom and top heights. */
typedef struct {
    double w, bottom, top;
} line_crown;

/* ss_canopy_band_hidden's sums: the share of the horizon band crowns hide
 * in each direction, weighted by how squarely the cell's surface faces it. */
typedef struct {
    const float *dz_de, *dz_dn; /* each cell's surface gradient, grid frame */
    float east, north;          /* the direction looked in, grid frame */
    double band_rad;            /* the band: 0 to this elevation */
    float *hidden, *weight;     /* per cell: sums over the directions */
} band_walk;

typedef struct {
    const ss_grid *grid;
    const ss_canopy *canopy;
    ss_svf_definition definition;
    ss_trunk_gaps gaps;
    upper_hull solid, top;
    line_crown *crowns; /* the line's, in walk order */
    size_t n_crowns;
    crown_union rises;             /* SS_TRUNK_GAPS_OPEN: those hidden from one cell */
    double *solid_sum, *crown_sum; /* per cell, over the directions (the sky) */
    band_walk *band;               /* the horizon band instead of the sky (else NULL) */
} sky_walk;

/* SS_TRUNK_GAPS_OPEN: the share the crowns before q hide above the solid
 * horizon's rise ts, up to the canopy-top horizon's ttop > ts; -1 when
 * out of memory. */
static double open_gaps_share(sky_walk *s, hull_point q, double ts, double ttop)
{
    crown_union *u = &s->rises;
    u->n = 0;
    for (size_t k = s->n_crowns; k-- > 0;) {
        const line_crown *c = &s->crowns[k];
        double d = q.w - c->w;
        if (!(d > 0.0))
            continue;
        double lo = fmax((c->bottom - q.z) / d, ts), hi = (c->top - q.z) / d;
        if (!(hi > lo))
            continue;
        if (union_add(u, lo, hi) != 0)
            return -1.0;
        if (u->span[0].lo <= ts && u->span[0].hi >= ttop)
            break; /* covered: crowns further back hide nothing more */
    }
    double share = 0.0;
    for (size_t k = 0; k < u->n; ++k)
        share +=
            hidden_share(s->definition, u->span[k].hi) - hidden_share(s->definition, u->span[k].lo);
    return share;
}

/* The share of the band [0, band_rad] of elevations that the rises
 * (lo, hi) hide. */
static double band_share_of(double lo, double hi, double band_rad)
{
    double a = fmax(atan(lo), 0.0), b = fmin(atan(hi), band_rad);
    return b > a ? (b - a) / band_rad : 0.0;
}

/* Cell i's band in this direction: the crowns hide the rises from ts to
 * ttop (columns) or, with the gaps open, the union open_gaps_share left
 * in s->rises; they count where the cell's surface faces the direction. */
static void band_add(sky_walk *s, size_t i, double ts, double ttop, int hides)
{
    band_walk *b = s->band;
    float facing = ss_cos_incidence_gradient(b->east, b->north, 0.0f, b->dz_de[i], b->dz_dn[i]);
    if (!(facing > 0.0f))
        return;
    double share = 0.0;
    if (hides && s->gaps == SS_TRUNK_GAPS_OPEN)
        for (size_t k = 0; k < s->rises.n; ++k)
            share += band_share_of(s->rises.span[k].lo, s->rises.span[k].hi, b->band_rad);
    else if (hides)
        share = band_share_of(ts, ttop, b->band_rad);
    b->hidden[i] += facing * (float)share;
    b->weight[i] += facing;
}

/* One digital line, walked from the far end of the direction looked in;
 * -1 when out of memory. */
static int walk_line(sky_walk *s, const ss_line_set *ls, int line)
{
    s->solid.n = s->top.n = 0;
    s->n_crowns = 0;
    ss_line_cursor c = ss_line_cursor_start(ls, line);
    while (ss_line_cursor_next(&c)) {
        size_t i = c.cell;
        float z = s->grid->z[i];
        if (!isfinite(z))
            continue;
        hull_point q = {c.walked_m, z};
        double ts = hull_rise(&s->solid, q), ttop = hull_rise(&s->top, q);
        double solid = hidden_share(s->definition, ts), crowns = 0.0;
        if (ttop > ts && s->gaps == SS_TRUNK_GAPS_OPEN)
            crowns = open_gaps_share(s, q, ts, ttop);
        else if (ttop > ts)
            crowns = hidden_share(s->definition, ttop) - solid;
        if (crowns < 0.0)
            return -1;
        if (s->band) {
            band_add(s, i, ts, ttop, ttop > ts);
        } else {
            s->solid_sum[i] += solid;
            s->crown_sum[i] += crowns;
        }
        double top = s->canopy->height_m[i], bottom = trunk_of(s->canopy, i);
        hull_add(&s->solid, q);
        hull_add(&s->top, (hull_point){q.w, z + top});
        if (top > bottom)
            s->crowns[s->n_crowns++] = (line_crown){q.w, z + bottom, z + top};
    }
    return 0;
}

/* Every digital line of one direction (grid azimuth, degrees). */
static ss_status walk_direction(ss_ctx *ctx, sky_walk *s, double grid_azimuth_deg)
{
    ss_status st = ss_check_cancel(ctx, "the crowns' sky");
    const ss_grid *grid = s->grid;
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, grid->width, grid->height, grid->cell_x_m, grid->cell_y_m,
                            grid_azimuth_deg, SS_LINE_MODEL_DIGITAL);
    ls.families = 1;
    for (int line = 0; st == SS_OK && line < ss_line_count(&ls); ++line)
        if (walk_line(s, &ls, line) != 0)
            st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns of a line");
    return st;
}

ss_status ss_canopy_sky(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                        const ss_sweep_options *opt, ss_svf_definition definition,
                        ss_trunk_gaps gaps, float *solid_share, float *crown_share)
{
    ss_call_begin(ctx);
    if (definition != SS_SVF_DEF_GEOMETRIC && definition != SS_SVF_DEF_HORIZONTAL)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "trees in the SVF take the geometric or horizontal definition, not %d",
                       (int)definition);
    if (gaps != SS_TRUNK_GAPS_IGNORE && gaps != SS_TRUNK_GAPS_OPEN)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown treatment of trunk gaps %d", (int)gaps);
    ss_status st = ss_sweep_options_check(ctx, opt);
    if (st != SS_OK)
        return st;
    size_t n = (size_t)grid->width * (size_t)grid->height;
    size_t longest = (size_t)(grid->width > grid->height ? grid->width : grid->height);
    sky_walk s = {grid,
                  canopy,
                  definition,
                  gaps,
                  {ss_malloc(longest * sizeof(hull_point)), 0},
                  {ss_malloc(longest * sizeof(hull_point)), 0},
                  ss_malloc(longest * sizeof(line_crown)),
                  0,
                  {0},
                  calloc(n, sizeof(double)),
                  calloc(n, sizeof(double)),
                  NULL};
    if (!s.solid.p || !s.top.p || !s.crowns || !s.solid_sum || !s.crown_sum)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns' sky");
    for (int d = 0; st == SS_OK && d < opt->directions; ++d)
        st = walk_direction(ctx, &s, ss_direction_azimuth(opt, d));
    for (size_t i = 0; st == SS_OK && i < n; ++i) {
        int valid = isfinite(grid->z[i]);
        if (solid_share)
            solid_share[i] = valid ? (float)(s.solid_sum[i] / opt->directions) : SS_NODATA;
        crown_share[i] = valid ? (float)(s.crown_sum[i] / opt->directions) : SS_NODATA;
    }
    free(s.solid.p);
    free(s.top.p);
    free(s.crowns);
    free(s.rises.span);
    free(s.solid_sum);
    free(s.crown_sum);
    return st;
}

ss_status ss_canopy_band_hidden(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                const ss_sweep_options *opt, ss_trunk_gaps gaps, double band_deg,
                                const float *dz_de, const float *dz_dn, float *hidden)
{
    size_t n = (size_t)grid->width * (size_t)grid->height;
    size_t longest = (size_t)(grid->width > grid->height ? grid->width : grid->height);
    band_walk b = {dz_de, dz_dn, 0.0f, 0.0f, band_deg * (M_PI / 180.0), hidden,
                   ss_malloc(n * sizeof(float))};
    sky_walk s = {grid,
                  canopy,
                  SS_SVF_DEF_HORIZONTAL,
                  gaps,
                  {ss_malloc(longest * sizeof(hull_point)), 0},
                  {ss_malloc(longest * sizeof(hull_point)), 0},
                  ss_malloc(longest * sizeof(line_crown)),
                  0,
                  {0},
                  NULL,
                  NULL,
                  &b};
    ss_status st = SS_OK;
    if (!s.solid.p || !s.top.p || !s.crowns || !b.weight)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns' horizon band");
    for (size_t i = 0; st == SS_OK && i < n; ++i)
        hidden[i] = b.weight[i] = 0.0f;
    for (int d = 0; st == SS_OK && d < opt->directions; ++d) {
        /* The engine's lines for the options' direction d (products_common.c). */
        double az = ss_direction_azimuth(opt, d) - opt->grid_north_deg;
        b.east = (float)sin(az * (M_PI / 180.0));
        b.north = (float)cos(az * (M_PI / 180.0));
        st = walk_direction(ctx, &s, az);
    }
    for (size_t i = 0; st == SS_OK && i < n; ++i)
        hidden[i] = !isfinite(grid->z[i]) ? SS_NODATA
                    : b.weight[i] > 0.0f  ? hidden[i] / b.weight[i]
                                          : 0.0f;
    free(s.solid.p);
    free(s.top.p);
    free(s.crowns);
    free(s.rises.span);
    free(b.weight);
    return st;
}

void ss_canopy_svf_bands(size_t n, const float *svf, const float *crown_share,
                         double transmissivity, float *svfveg, float *svfbuveg)
{
    double lost = 1.0 - transmissivity;
    for (size_t i = 0; i < n; ++i) {
        if (svf[i] == SS_NODATA) {
            svfveg[i] = svfbuveg[i] = SS_NODATA;
            continue;
        }
        /* The solid horizon of crown_share is the digital lines'
         * (ss_canopy_sky): never hide more than svf sees. */
        double hidden = fmin(crown_share[i], svf[i]);
        svfveg[i] = (float)(1.0 - hidden);
        svfbuveg[i] = (float)(svf[i] - hidden * lost);
    }
}

/* The crowns' top horizon on one digital line, walked from the far end of
 * the direction looked in: the hull of the crown tops walked before each
 * cell. */
static void crown_top_line(const ss_grid *grid, const ss_canopy *canopy, const ss_line_set *ls,
                           int line, upper_hull *tops, float *crown_deg)
{
    tops->n = 0;
    ss_line_cursor c = ss_line_cursor_start(ls, line);
    while (ss_line_cursor_next(&c)) {
        size_t i = c.cell;
        float z = grid->z[i];
        if (!isfinite(z))
            continue;
        hull_point q = {c.walked_m, z};
        double t = hull_rise(tops, q);
        crown_deg[i] = t == -HUGE_VAL ? -90.0f : (float)(atan(t) * (180.0 / M_PI));
        if (canopy->height_m[i] > 0.0f)
            hull_add(tops, (hull_point){q.w, z + canopy->height_m[i]});
    }
}

ss_status ss_canopy_top_horizon(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                double grid_azimuth_deg, float *crown_deg)
{
    ss_call_begin(ctx);
    if (!isfinite(grid_azimuth_deg))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "azimuth %g is not a direction", grid_azimuth_deg);
    size_t n = (size_t)grid->width * (size_t)grid->height;
    size_t longest = (size_t)(grid->width > grid->height ? grid->width : grid->height);
    upper_hull tops = {ss_malloc(longest * sizeof(hull_point)), 0};
    if (!tops.p)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns' horizon");
    for (size_t i = 0; i < n; ++i)
        crown_deg[i] = SS_NODATA;
    ss_line_set ls;
    ss_line_set_for_azimuth(&ls, grid->width, grid->height, grid->cell_x_m, grid->cell_y_m,
                            grid_azimuth_deg, SS_LINE_MODEL_DIGITAL);
    ls.families = 1;
    ss_status st = SS_OK;
    for (int line = 0; st == SS_OK && line < ss_line_count(&ls); ++line) {
        if (line % 256 == 0) /* Ctrl-C and ss_ctx_cancel reach a long sweep */
            st = ss_check_cancel(ctx, "the crowns' horizon");
        if (st == SS_OK)
            crown_top_line(grid, canopy, &ls, line, &tops, crown_deg);
    }
    free(tops.p);
    return st;
}
