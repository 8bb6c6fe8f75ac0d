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

/* One end of the rises a crown hides from a cell: +1 where they begin,
 * -1 where they end. */
typedef struct {
    double rise;
    int step;
} crown_end;

/* Beer-Lambert through the hidden sky (ss_canopy_sky_through and the
 * band's): per cell, the share the crowns hide and the share of it they
 * pass, exp(-k L) in each direction, summed over the directions. */
typedef struct {
    double k;        /* extinction x leaf area density, per metre of crown */
    double run_m;    /* the direction's horizontal run through one cell of its line */
    crown_end *ends; /* one cell's, sorted */
    double *hidden_sum, *through_sum;
} crown_light;

typedef struct sky_walk sky_walk;

/* How a walk weighs the rises the crowns hide from a cell: as the sky's
 * share of the direction (sky_weight) or as the horizon band's, seen by
 * the cell's surface (band_weight). The walks over a cell's crowns
 * (crowns_share, light_add) are the same for both. */
typedef struct {
    /* how squarely cell i faces the direction walked; the sky's 1 */
    float (*facing)(const sky_walk *s, size_t i);
    /* the share of the direction that the rises (lo, hi) take */
    double (*share)(const sky_walk *s, double lo, double hi);
    /* of that share of the rises (ta, tb), 0 <= ta < tb, the part a ray
     * through a path of x sec(e) / k of crown passes */
    double (*passed)(const sky_walk *s, double ta, double tb, double x);
} span_weight;

struct sky_walk {
    const ss_grid *grid;
    const ss_canopy *canopy;
    ss_svf_definition definition;
    ss_trunk_gaps gaps;
    const span_weight *weight;
    upper_hull solid, top;
    line_crown *crowns; /* the line's, in walk order */
    size_t n_crowns;
    crown_union rises;             /* SS_TRUNK_GAPS_OPEN: those hidden from one cell */
    double *solid_sum, *crown_sum; /* per cell, over the directions (the sky; else NULL) */
    band_walk *band;               /* the horizon band instead of the sky (else NULL) */
    crown_light *light;            /* Beer-Lambert's sums besides (else NULL) */
};

/* The rises crown c hides from q above floor_rise: from its bottom (the
 * gaps open) or floor_rise (ignored: a column) to its top; 0 where it hides
 * none there, or does not lie before q. */
static int crown_rises(const sky_walk *s, const line_crown *c, hull_point q, double floor_rise,
                       double *lo, double *hi)
{
    double d = q.w - c->w;
    if (!(d > 0.0))
        return 0;
    *lo = s->gaps == SS_TRUNK_GAPS_OPEN ? fmax((c->bottom - q.z) / d, floor_rise) : floor_rise;
    *hi = (c->top - q.z) / d;
    return *hi > *lo;
}

/* SS_TRUNK_GAPS_OPEN: into s->rises, the union of the rises the crowns
 * before q hide above the solid horizon's rise ts, up to the canopy-top
 * horizon's ttop > ts; -1 when out of memory. */
static int open_gaps_union(sky_walk *s, hull_point q, double ts, double ttop)
{
    crown_union *u = &s->rises;
    u->n = 0;
    double lo, hi;
    for (size_t k = s->n_crowns; k-- > 0;) {
        if (!crown_rises(s, &s->crowns[k], q, ts, &lo, &hi))
            continue;
        if (union_add(u, lo, hi) != 0)
            return -1;
        if (u->span[0].lo <= ts && u->span[0].hi >= ttop)
            break; /* covered: crowns further back hide nothing more */
    }
    return 0;
}

/* E_3(x) = integral over t >= 1 of exp(-x t) / t^3, x >= 0: the series
 * up to 2.5, Lentz's continued fraction beyond (Numerical Recipes' expint,
 * n = 3, which splits at 1: at 2.5 each side takes at most about 30
 * terms), to 1e-14. */
static double expint3(double x)
{
    if (!(x > 0.0))
        return 0.5;
    if (x > 2.5) {
        double b = x + 3.0, c = 1e300, d = 1.0 / b, h = d;
        for (int i = 1; i < 500; ++i) {
            double a = -(double)i * (i + 2);
            b += 2.0;
            d = 1.0 / (a * d + b);
            c = b + a / c;
            h *= c * d;
            if (fabs(c * d - 1.0) < 1e-14)
                break;
        }
        return h * exp(-x);
    }
    const double euler = 0.57721566490153286061;
    double sum = 0.5, term = 1.0; /* the k = 0 term, 1 / (n - 1) */
    for (int k = 1; k < 500; ++k) {
        term *= -x / k;
        double add = k != 2 ? -term / (k - 2) : term * (-log(x) + 1.5 - euler);
        sum += add;
        if (fabs(add) < fabs(sum) * 1e-16)
            break;
    }
    return sum;
}

static float sky_facing(const sky_walk *s, size_t i)
{
    (void)s, (void)i;
    return 1.0f;
}

/* The sky's share of the rises (lo, hi) by the walk's definition. */
static double sky_share(const sky_walk *s, double lo, double hi)
{
    return hidden_share(s->definition, hi) - hidden_share(s->definition, lo);
}

/* The sky's weight of the rises (ta, tb), cosine-weighted as a horizontal
 * surface's (d sin^2 e: ss_canopy_sky_through walks the horizontal
 * definition), passed through a path of x sec(e) / k of crown: with
 * u = sec e, d sin^2 e = 2 du / u^3, and the integral of
 * 2 exp(-x u) / u^3 from ua to ub is 2 (E_3(x ua) / ua^2 - E_3(x ub) / ub^2). */
static double sky_passed(const sky_walk *s, double ta, double tb, double x)
{
    (void)s;
    double ua = sqrt(1.0 + ta * ta), ub = sqrt(1.0 + tb * tb);
    return 2.0 * (expint3(x * ua) / (ua * ua) - expint3(x * ub) / (ub * ub));
}

static const span_weight sky_weight = {sky_facing, sky_share, sky_passed};

/* The band's directions count where the cell's surface faces them. */
static float band_facing(const sky_walk *s, size_t i)
{
    const band_walk *b = s->band;
    return ss_cos_incidence_gradient(b->east, b->north, 0.0f, b->dz_de[i], b->dz_dn[i]);
}

/* The share of the band [0, band_rad] of elevations that the rises
 * (lo, hi) hide, uniform in elevation. */
static double band_share(const sky_walk *s, double lo, double hi)
{
    double band_rad = s->band->band_rad;
    double a = fmax(atan(lo), 0.0), b = fmin(atan(hi), band_rad);
    return b > a ? (b - a) / band_rad : 0.0;
}

/* The band's share of the rises (ta, tb) passed, exp(-x sec e): 8-point
 * Gauss-Legendre over at most 6.5 degrees, where sec e moves by 0.65 %
 * (exact to rounding for any x whose light is not already below 1e-300). */
static double band_passed(const sky_walk *s, double ta, double tb, double x)
{
    static const double node[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                   0.9602898564975363},
                        weight[4] = {0.3626837833783620, 0.3137066458778873,
                                     0.2223810344533745, 0.1012285362903763};
    double band_rad = s->band->band_rad;
    double a = atan(ta), b = fmin(atan(tb), band_rad);
    if (!(b > a))
        return 0.0;
    double mid = 0.5 * (a + b), half = 0.5 * (b - a), sum = 0.0;
    for (int k = 0; k < 4; ++k)
        sum += weight[k] * (exp(-x / cos(mid - half * node[k])) + exp(-x / cos(mid + half * node[k])));
    return sum * half / band_rad;
}

static const span_weight band_weight = {band_facing, band_share, band_passed};

/* The share (s->weight's) that the crowns before q hide above the solid
 * horizon's rise ts, up to the canopy-top horizon's ttop > ts: all of it
 * with the gaps ignored (the crowns columns), else the union of their
 * rises; -1 when out of memory. */
static double crowns_share(sky_walk *s, hull_point q, double ts, double ttop)
{
    if (s->gaps != SS_TRUNK_GAPS_OPEN)
        return s->weight->share(s, ts, ttop);
    if (open_gaps_union(s, q, ts, ttop) != 0)
        return -1.0;
    double share = 0.0;
    for (size_t k = 0; k < s->rises.n; ++k)
        share += s->weight->share(s, s->rises.span[k].lo, s->rises.span[k].hi);
    return share;
}

/* Cell i's band in this direction, `share` of it hidden by the crowns. */
static void band_add(sky_walk *s, size_t i, double share)
{
    band_walk *b = s->band;
    float facing = band_facing(s, i);
    if (!(facing > 0.0f))
        return;
    b->hidden[i] += facing * (float)share;
    b->weight[i] += facing;
}

static int by_rise(const void *a, const void *b)
{
    double x = ((const crown_end *)a)->rise, y = ((const crown_end *)b)->rise;
    return (x > y) - (x < y);
}

/* Beer-Lambert from q, its solid horizon's rise ts: every crown before q
 * on the line (none left out: each adds to the paths) hides the rises
 * from its bottom (the solid horizon with the gaps ignored: a column) to
 * its top, above the horizontal; between consecutive ends the ray crosses
 * `count` crowns, a path of count x run_m x sec e. */
static void light_add(sky_walk *s, size_t i, hull_point q, double ts)
{
    crown_light *l = s->light;
    const span_weight *w = s->weight;
    float facing = w->facing(s, i);
    if (!(facing > 0.0f))
        return;
    double floor_rise = fmax(ts, 0.0), lo, hi;
    size_t m = 0;
    for (size_t k = 0; k < s->n_crowns; ++k)
        if (crown_rises(s, &s->crowns[k], q, floor_rise, &lo, &hi)) {
            l->ends[m++] = (crown_end){lo, 1};
            l->ends[m++] = (crown_end){hi, -1};
        }
    qsort(l->ends, m, sizeof *l->ends, by_rise);
    double hidden = 0.0, through = 0.0;
    int count = 0;
    for (size_t k = 0; k + 1 < m; ++k) {
        count += l->ends[k].step;
        double ta = l->ends[k].rise, tb = l->ends[k + 1].rise, x = l->k * l->run_m * count;
        if (count <= 0 || !(tb > ta))
            continue;
        hidden += w->share(s, ta, tb);
        through += w->passed(s, ta, tb, x);
    }
    l->hidden_sum[i] += facing * hidden;
    l->through_sum[i] += facing * through;
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
        double crowns = ttop > ts ? crowns_share(s, q, ts, ttop) : 0.0;
        if (crowns < 0.0)
            return -1;
        if (s->band) {
            band_add(s, i, crowns);
        } else if (s->solid_sum) {
            s->solid_sum[i] += hidden_share(s->definition, ts);
            s->crown_sum[i] += crowns;
        }
        if (s->light && ttop > ts)
            light_add(s, i, q, ts);
        double top = s->canopy->height_m[i], bottom = trunk_of(s->canopy, i);
        hull_add(&s->solid, q);
        hull_add(&s->top, (hull_point){q.w, z + top});
        /* A crown as thin as nothing (trunk at its top) hides no rise with
         * the gaps open; with them ignored it is a column, as the top hull
         * takes it. */
        if (top > 0.0f)
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
    if (s->light) { /* the distance along the azimuth per step of the major axis (canopy_path.c) */
        double minor_per_major = (double)ls.slope_fx / 4294967296.0;
        double c_major = ls.major_is_row ? grid->cell_y_m : grid->cell_x_m,
               c_minor = ls.major_is_row ? grid->cell_x_m : grid->cell_y_m;
        s->light->run_m = hypot(c_major, minor_per_major * c_minor);
    }
    for (int line = 0; st == SS_OK && line < ss_line_count(&ls); ++line)
        if (walk_line(s, &ls, line) != 0)
            st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns of a line");
    return st;
}

/* Cells on the longest line of the grid's. */
static size_t longest_line(const ss_grid *grid)
{
    return (size_t)(grid->width > grid->height ? grid->width : grid->height);
}

/* A walk weighed by `weight`, with the buffers every walk takes: the
 * hulls and the crowns of the longest line (NULL where out of memory:
 * sky_walk_made). Its caller adds the sums it fills; sky_walk_free frees
 * them all. */
static sky_walk sky_walk_new(const ss_grid *grid, const ss_canopy *canopy,
                             ss_svf_definition definition, ss_trunk_gaps gaps,
                             const span_weight *weight)
{
    size_t longest = longest_line(grid);
    return (sky_walk){.grid = grid,
                      .canopy = canopy,
                      .definition = definition,
                      .gaps = gaps,
                      .weight = weight,
                      .solid = {ss_malloc(longest * sizeof(hull_point)), 0},
                      .top = {ss_malloc(longest * sizeof(hull_point)), 0},
                      .crowns = ss_malloc(longest * sizeof(line_crown))};
}

static int sky_walk_made(const sky_walk *s)
{
    return s->solid.p && s->top.p && s->crowns;
}

static void crown_light_free(crown_light *l)
{
    if (l) {
        free(l->ends);
        free(l->hidden_sum);
        free(l->through_sum);
        free(l);
    }
}

/* Frees a walk's buffers and sums (not its band's, the caller's). */
static void sky_walk_free(sky_walk *s)
{
    free(s->solid.p);
    free(s->top.p);
    free(s->crowns);
    free(s->rises.span);
    free(s->solid_sum);
    free(s->crown_sum);
    crown_light_free(s->light);
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
    sky_walk s = sky_walk_new(grid, canopy, definition, gaps, &sky_weight);
    s.solid_sum = calloc(n, sizeof(double));
    s.crown_sum = calloc(n, sizeof(double));
    if (!sky_walk_made(&s) || !s.solid_sum || !s.crown_sum)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns' sky");
    for (int d = 0; st == SS_OK && d < opt->directions; ++d)
        st = walk_direction(ctx, &s, ss_direction_azimuth(opt, d));
    for (size_t i = 0; st == SS_OK && i < n; ++i) {
        int valid = isfinite(grid->z[i]);
        if (solid_share)
            solid_share[i] = valid ? (float)(s.solid_sum[i] / opt->directions) : SS_NODATA;
        crown_share[i] = valid ? (float)(s.crown_sum[i] / opt->directions) : SS_NODATA;
    }
    sky_walk_free(&s);
    return st;
}

/* Beer-Lambert's sums for n cells, ends for the longest line (NULL where
 * k is 0: the constant model); *failed where out of memory. */
static crown_light *crown_light_new(double k, size_t n, size_t longest, int *failed)
{
    if (!(k > 0.0))
        return NULL;
    crown_light *l = ss_malloc(sizeof *l);
    if (l)
        *l = (crown_light){k, 0.0, ss_malloc(2 * longest * sizeof(crown_end)),
                           calloc(n, sizeof(double)), calloc(n, sizeof(double))};
    *failed = !l || !l->ends || !l->hidden_sum || !l->through_sum;
    return l;
}

/* The mean of exp(-k L) over the sky the crowns hide, per cell: 1 where
 * they hide none, SS_NODATA at nodata. */
static void crown_light_mean(const crown_light *l, const ss_grid *grid, float *through)
{
    size_t n = (size_t)grid->width * (size_t)grid->height;
    for (size_t i = 0; i < n; ++i)
        through[i] = !isfinite(grid->z[i])     ? SS_NODATA
                     : l->hidden_sum[i] > 0.0 ? (float)(l->through_sum[i] / l->hidden_sum[i])
                                               : 1.0f;
}

ss_status ss_canopy_sky_through(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                const ss_sweep_options *opt, ss_trunk_gaps gaps,
                                double per_m, float *through)
{
    if (!(per_m > 0.0 && isfinite(per_m)))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "the crowns' extinction per metre %g is not above 0",
                       per_m);
    size_t n = (size_t)grid->width * (size_t)grid->height;
    int failed = 0;
    sky_walk s = sky_walk_new(grid, canopy, SS_SVF_DEF_HORIZONTAL, gaps, &sky_weight);
    s.light = crown_light_new(per_m, n, longest_line(grid), &failed);
    ss_status st = SS_OK;
    if (!sky_walk_made(&s) || !s.light || failed)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the light through the crowns' sky");
    /* ss_canopy_sky's directions, so that the sky hidden is its. */
    for (int d = 0; st == SS_OK && d < opt->directions; ++d)
        st = walk_direction(ctx, &s, ss_direction_azimuth(opt, d));
    if (st == SS_OK)
        crown_light_mean(s.light, grid, through);
    sky_walk_free(&s);
    return st;
}

ss_status ss_canopy_band_hidden(ss_ctx *ctx, const ss_grid *grid, const ss_canopy *canopy,
                                const ss_sweep_options *opt, ss_trunk_gaps gaps, double band_deg,
                                const float *dz_de, const float *dz_dn, double per_m,
                                float *hidden, float *through)
{
    size_t n = (size_t)grid->width * (size_t)grid->height;
    band_walk b = {dz_de, dz_dn, 0.0f, 0.0f, band_deg * (M_PI / 180.0), hidden,
                   ss_malloc(n * sizeof(float))};
    int failed = 0;
    sky_walk s = sky_walk_new(grid, canopy, SS_SVF_DEF_HORIZONTAL, gaps, &band_weight);
    s.band = &b;
    if (through)
        s.light = crown_light_new(per_m, n, longest_line(grid), &failed);
    ss_status st = SS_OK;
    if (!sky_walk_made(&s) || !b.weight || failed || (through && !s.light))
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
    if (st == SS_OK && s.light)
        crown_light_mean(s.light, grid, through);
    free(b.weight);
    sky_walk_free(&s);
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
    upper_hull tops = {ss_malloc(longest_line(grid) * sizeof(hull_point)), 0};
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
