/* Trees in insolation's steps (insolation_trees.h). */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "insolation_trees.h"
#include "skysweep_sun.h"

ss_status ss_insolation_trees_check(ss_ctx *ctx, const ss_insolation_options *io,
                                    const ss_source *src)
{
    const ss_insolation_trees *t = io->trees;
    if (!t->ground || !t->canopy || t->ground->width != src->width ||
        t->ground->height != src->height)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "insolation's trees need the DSM and a canopy on the run's grid");
    if (!(t->transmissivity_leaf_off >= 0 && t->transmissivity_leaf_off <= 1))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "the leaf-off transmissivity %g is outside 0..1",
                       t->transmissivity_leaf_off);
    if (t->leaf_area_density != 0.0 && io->shadow_mode == SS_SHADOW_CUMULATIVE)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "the cumulative sky takes the constant crowns' light, not Beer-Lambert: "
                       "use exact or interpolated shadows with it");
    if (t->leaf_area_density != 0.0 &&
        (!(t->extinction > 0.0 && t->extinction <= 1.0) ||
         !(t->leaf_area_density > 0.0 && t->leaf_area_density <= 20.0)))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "Beer-Lambert crowns need an extinction coefficient in (0, 1] and a leaf "
                       "area density in (0, 20] m2/m3 (got %g, %g)",
                       t->extinction, t->leaf_area_density);
    return ss_canopy_check(ctx, t->ground, t->canopy);
}

float ss_insolation_trees_transmissivity(const ss_insolation_trees *t, int k)
{
    return (float)(t->leaf_off && t->leaf_off[k] ? t->transmissivity_leaf_off
                                                 : t->canopy->transmissivity);
}

void ss_insolation_trees_terms(const ss_insolation_job *job, const ss_band_view *band, float T,
                               int beer_lambert, const ss_cell_terms *in, ss_cell_terms *out)
{
    const ss_insolation_trees *t = job->io->trees;
    const float *band_hidden = job->trees_band_hidden;
    const float *sky_T = beer_lambert ? job->trees_sky_through : NULL,
                *band_T = beer_lambert ? job->trees_band_through : NULL;
    size_t n = (size_t)band->n_rows * band->width, at = (size_t)band->row0 * band->width;
    for (size_t c = 0; c < n; ++c) {
        out[c] = in[c];
        float hidden = t->sky_hidden ? t->sky_hidden[at + c] : 0.0f;
        if (hidden > 0.0f && hidden != SS_NODATA)
            out[c].sky_view =
                fmaxf(in[c].sky_view - hidden * (1.0f - (sky_T ? sky_T[at + c] : T)), 0.0f);
        float band_off = band_hidden ? band_hidden[at + c] : 0.0f;
        if (band_off > 0.0f && band_off != SS_NODATA)
            out[c].band_seen =
                fmaxf(in[c].band_seen - band_off * (1.0f - (band_T ? band_T[at + c] : T)), 0.0f);
    }
}

ss_status ss_insolation_trees_sky(ss_insolation_job *job)
{
    const ss_insolation_trees *t = job->io->trees;
    if (!(t->leaf_area_density > 0.0) || !t->sky_hidden)
        return SS_OK;
    size_t n = (size_t)t->ground->width * (size_t)t->ground->height;
    job->trees_sky_through = ss_malloc(n * sizeof(float));
    if (!job->trees_sky_through)
        return ss_fail(job->ctx, SS_ERR_MEMORY, "out of memory for the light through crowns");
    return ss_canopy_sky_through(job->ctx, t->ground, t->canopy, job->opt, t->trunk_gaps,
                                 t->extinction * t->leaf_area_density, job->trees_sky_through);
}

ss_status ss_insolation_trees_band(ss_insolation_job *job)
{
    const ss_insolation_trees *t = job->io->trees;
    const ss_grid *g = t->ground;
    size_t n = (size_t)g->width * (size_t)g->height;
    float *de = ss_malloc(n * sizeof(float)), *dn = ss_malloc(n * sizeof(float));
    job->trees_band_hidden = ss_malloc(n * sizeof(float));
    int beer_lambert = t->leaf_area_density > 0.0;
    if (beer_lambert)
        job->trees_band_through = ss_malloc(n * sizeof(float));
    ss_status st = SS_OK;
    if (!de || !dn || !job->trees_band_hidden || (beer_lambert && !job->trees_band_through))
        st = ss_fail(job->ctx, SS_ERR_MEMORY, "out of memory for the crowns' horizon band");
    /* The surfaces insolation_terms.c weighs the band on: the cell's own
     * slope (Horn's) or the fixed surface. */
    float fixed_de, fixed_dn;
    ss_insolation_surface_gradient(&job->io->surface, job->opt, &fixed_de, &fixed_dn);
    int own = job->io->surface.kind == SS_SURFACE_CELL;
    for (int r = 0; st == SS_OK && r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            size_t i = (size_t)r * g->width + c;
            de[i] = fixed_de;
            dn[i] = fixed_dn;
            if (own && isfinite(g->z[i]))
                ss_gradient_horn(g->z, g->width, g->height, c, r, (float)g->cell_x_m,
                                 (float)g->cell_y_m, &de[i], &dn[i]);
        }
    if (st == SS_OK)
        st = ss_canopy_band_hidden(job->ctx, g, t->canopy, job->opt, t->trunk_gaps,
                                   SS_PEREZ_BAND_DEG, de, dn,
                                   t->extinction * t->leaf_area_density, job->trees_band_hidden,
                                   job->trees_band_through);
    free(de);
    free(dn);
    return st;
}

/* The lines the crowns are met on: the run's, or digital ones where the
 * run asks for them or Beer-Lambert's paths must lie where crowns are
 * crossed. */
static ss_sweep_options crown_lines(const ss_insolation_trees *t, const ss_sweep_options *opt)
{
    ss_sweep_options lines = *opt;
    if (t->digital_lines || t->leaf_area_density > 0.0)
        lines.lines = SS_LINES_DIGITAL;
    return lines;
}

ss_status ss_insolation_trees_crossed(ss_ctx *ctx, const ss_insolation_trees *t,
                                      const ss_sweep_options *opt, const ss_sun_step *sun,
                                      int row0, int n_rows, const float *solid_angle,
                                      unsigned char *crossed)
{
    ss_sweep_options lines = crown_lines(t, opt);
    return ss_canopy_crossed_where_lit(ctx, t->ground, t->canopy, &lines, sun->grid_azimuth_deg,
                                       sun->apparent_elevation_deg, row0, n_rows, solid_angle,
                                       sun->apparent_elevation_deg + sun->spread_deg, crossed);
}

int ss_insolation_trees_beer_lambert(const ss_insolation_trees *t, int k)
{
    return t->leaf_area_density > 0.0 && !(t->leaf_off && t->leaf_off[k]);
}

ss_status ss_insolation_trees_through(ss_ctx *ctx, const ss_insolation_trees *t,
                                      const ss_sun_step *sun, float *through)
{
    size_t n = (size_t)t->ground->width * (size_t)t->ground->height;
    ss_status st = ss_canopy_path(ctx, t->ground, t->canopy, sun->grid_azimuth_deg,
                                  sun->apparent_elevation_deg, through);
    return st == SS_OK ? ss_canopy_path_fraction(ctx, t->extinction, t->leaf_area_density, n,
                                                 through, through)
                       : st;
}

ss_status ss_insolation_trees_crossed_at(ss_ctx *ctx, const ss_insolation_trees *t,
                                         const ss_sweep_options *opt, double grid_azimuth_deg,
                                         double apparent_elevation_deg, unsigned char *crossed)
{
    ss_sweep_options lines = crown_lines(t, opt);
    return ss_canopy_crossed(ctx, t->ground, t->canopy, &lines, grid_azimuth_deg,
                             apparent_elevation_deg, crossed);
}

/* ---- the leaf season -------------------------------------------------------- */

/* UMEP/SOLWEIG's leaf season: firstdayleaf 97 and lastdayleaf 300, leaves
 * on strictly between them, that is from day 98 up to day 299. */
#define LEAF_ON_DAY 98
#define LEAF_OFF_DAY 300
/* The southern hemisphere's: half a year (183 days) later. */
#define HALF_YEAR_DAYS 183

/* A leaf date: a day of the year (1-366) into *day, or MM-DD into *month
 * and *day_of_month (*day 0). Returns 0 where it is neither. */
static int leaf_date(const char *text, int *day, int *month, int *day_of_month)
{
    static const int days_in[12] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    int a, b, used = 0;
    *day = *month = *day_of_month = 0;
    if (sscanf(text, "%d-%d%n", &a, &b, &used) == 2 && text[used] == '\0' &&
        strlen(text) == 5 && a >= 1 && a <= 12 && b >= 1 && b <= days_in[a - 1]) {
        *month = a;
        *day_of_month = b;
        return 1;
    }
    used = 0;
    if (sscanf(text, "%d%n", &a, &used) == 1 && text[used] == '\0' && a >= 1 && a <= 366 &&
        strspn(text, "0123456789") == strlen(text)) {
        *day = a;
        return 1;
    }
    return 0;
}

int ss_leaf_date_valid(const char *text)
{
    int day, month, day_of_month;
    return text && leaf_date(text, &day, &month, &day_of_month);
}

/* A leaf date's day of the year in `year`. */
static int day_in_year(const char *text, int fallback, long long year)
{
    int day, month, dom;
    if (!text || !leaf_date(text, &day, &month, &dom))
        return fallback;
    if (day)
        return day;
    return (int)((ss_unix_from_civil(year, month, dom, 0, 0, 0) -
                  ss_unix_from_civil(year, 1, 1, 0, 0, 0)) /
                     86400.0 +
                 0.5) +
           1;
}

/* Leaves are on from the leaf-on day up to the day before the leaf-off
 * day, over the new year where leaf-on comes later in the year. */
static int leaves_off(int day, int on, int off)
{
    int on_season = on <= off ? day >= on && day < off : day >= on || day < off;
    return !on_season;
}

/* Mean solar time at the longitude differs from the weather's zone by at
 * most hours, at night. */
void ss_leaf_seasons(const char *leaf_on, const char *leaf_off, double latitude_deg,
                     double longitude_deg, const double *mid_s, int n,
                     unsigned char *leaf_off_out, ss_leaf_season *season)
{
    double shift_s = longitude_deg / 15.0 * 3600.0;
    int south = latitude_deg < 0.0 ? HALF_YEAR_DAYS : 0;
    int on_default = (LEAF_ON_DAY - 1 + south) % 365 + 1;
    int off_default = (LEAF_OFF_DAY - 1 + south) % 365 + 1;
    season->south = south != 0;
    season->on_day = day_in_year(leaf_on, on_default, 2001);
    season->off_day = day_in_year(leaf_off, off_default, 2001);
    season->leaf_off_steps = 0;
    for (int k = 0; k < n; ++k) {
        ss_civil_time t;
        double local = mid_s[k] + shift_s;
        ss_civil_from_unix(local, &t);
        int day = (int)((local - ss_unix_from_civil(t.year, 1, 1, 0, 0, 0)) / 86400.0) + 1;
        int on = day_in_year(leaf_on, on_default, t.year);
        int off = day_in_year(leaf_off, off_default, t.year);
        leaf_off_out[k] = (unsigned char)leaves_off(day, on, off);
        season->leaf_off_steps += leaf_off_out[k];
    }
}
