/* Trees in the sky view (doc/vegetation.md, "svf"): the share of each
 * cell's sky that crowns hide above the solid horizon.
 *
 * Trunk gaps ignored (SS_TRUNK_GAPS_IGNORE, the one treatment so far):
 * every crown is a column from the ground to its top, so in each direction
 * the crowns hide the elevations between the solid horizon (of the DSM)
 * and the canopy-top horizon (of DSM + canopy), both seen from the cell's
 * surface (the ground under its own crown, which it does not see). Each
 * horizon is the tangent from the cell to the upper convex hull of the
 * cells walked before it on the direction's digital line (the engine's
 * lines, lines.h, walked from the far end): O(log n) a cell, exact on
 * those lines, no distance limit, the earth flat. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "lines.h"
#include "products_internal.h"

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

typedef struct {
    const ss_grid *grid;
    const ss_canopy *canopy;
    ss_svf_definition definition;
    upper_hull solid, top;
    double *solid_sum, *crown_sum; /* per cell, over the directions */
} sky_walk;

/* One digital line, walked from the far end of the direction looked in. */
static void walk_line(sky_walk *s, const ss_line_set *ls, int line)
{
    s->solid.n = s->top.n = 0;
    ss_i64 b16 = ss_line_intercept16(ls, line);
    double away_major = (double)ls->along_per_step_m * ls->step,
           away_minor = (double)ls->along_per_minor_m;
    for (int k = 0; k < ls->major_len; ++k) {
        int major = ls->step > 0 ? k : ls->major_len - 1 - k;
        int minor = ss_line_minor(ls, b16, major);
        if (minor < 0 || minor >= ls->minor_len)
            continue;
        size_t i = (size_t)major * (size_t)ls->stride_major + (size_t)minor * (size_t)ls->stride_minor;
        float z = s->grid->z[i];
        if (!isfinite(z))
            continue;
        hull_point q = {major * away_major + minor * away_minor, z};
        double solid = hidden_share(s->definition, hull_rise(&s->solid, q));
        double both = hidden_share(s->definition, fmax(hull_rise(&s->solid, q),
                                                       hull_rise(&s->top, q)));
        s->solid_sum[i] += solid;
        s->crown_sum[i] += both - solid;
        hull_add(&s->solid, q);
        hull_add(&s->top, (hull_point){q.w, z + (double)s->canopy->height_m[i]});
    }
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
    if (gaps != SS_TRUNK_GAPS_IGNORE)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown treatment of trunk gaps %d", (int)gaps);
    ss_status st = ss_sweep_options_check(ctx, opt);
    if (st != SS_OK)
        return st;
    size_t n = (size_t)grid->width * (size_t)grid->height;
    size_t longest = (size_t)(grid->width > grid->height ? grid->width : grid->height);
    sky_walk s = {grid, canopy, definition, {ss_malloc(longest * sizeof(hull_point)), 0},
                  {ss_malloc(longest * sizeof(hull_point)), 0}, calloc(n, sizeof(double)),
                  calloc(n, sizeof(double))};
    if (!s.solid.p || !s.top.p || !s.solid_sum || !s.crown_sum)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the crowns' sky");
    for (int d = 0; st == SS_OK && d < opt->directions; ++d) {
        st = ss_check_cancel(ctx, "the crowns' sky");
        ss_line_set ls;
        ss_line_set_for_azimuth(&ls, grid->width, grid->height, grid->cell_x_m, grid->cell_y_m,
                                ss_direction_azimuth(opt, d), SS_LINE_MODEL_DIGITAL);
        ls.families = 1;
        for (int line = 0; st == SS_OK && line < ss_line_count(&ls); ++line)
            walk_line(&s, &ls, line);
    }
    for (size_t i = 0; st == SS_OK && i < n; ++i) {
        int valid = isfinite(grid->z[i]);
        if (solid_share)
            solid_share[i] = valid ? (float)(s.solid_sum[i] / opt->directions) : SS_NODATA;
        crown_share[i] = valid ? (float)(s.crown_sum[i] / opt->directions) : SS_NODATA;
    }
    free(s.solid.p);
    free(s.top.p);
    free(s.solid_sum);
    free(s.crown_sum);
    return st;
}
