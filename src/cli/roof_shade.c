/* Shade over time on roof planes: see roof_shade.h and doc/roofs.md. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "roof_shade.h"
#include "skysweep_sun.h"

int roof_shade_add_plane(roof_shade *s, double tilt_deg, double aspect_grid_deg,
                         const int *cells, int n_cells)
{
    if (s->n_planes == s->cap_planes) {
        size_t cap = s->cap_planes ? 2 * s->cap_planes : 64;
        shade_plane *p = realloc(s->planes, cap * sizeof *p);
        if (!p)
            return -1;
        s->planes = p, s->cap_planes = cap;
    }
    if (s->n_cells + (size_t)n_cells > s->cap_cells) {
        size_t cap = 2 * (s->n_cells + (size_t)n_cells) + 256;
        int *c = realloc(s->cells, cap * sizeof *c);
        if (!c)
            return -1;
        s->cells = c, s->cap_cells = cap;
    }
    for (int i = 0; i < n_cells; ++i)
        s->cells[s->n_cells + (size_t)i] = cells[i];
    s->planes[s->n_planes++] = (shade_plane){s->n_cells, n_cells, tilt_deg, aspect_grid_deg};
    s->n_cells += (size_t)n_cells;
    return 0;
}

/* The month (0..11) x hour slot of an instant in local standard time, and
 * its day of the month. */
static int slot_of(double unix_s, double utc_offset_h, int *day)
{
    ss_civil_time local;
    /* the step's instant comes from the sun's Julian day (UT1, within a
     * second of UTC): rounded back to the record's second */
    ss_civil_from_unix(floor(unix_s + 0.5) + utc_offset_h * 3600.0, &local);
    *day = local.day;
    return (local.month - 1) * 24 + local.hour;
}

/* Adds one record's sunlit shares of every plane (lit: its cells sunlit)
 * to its slot. */
static void add_shares(roof_shade *s, const ss_sun_step *step, double sun_grid_az, const int *lit,
                       int slot)
{
    for (size_t k = 0; k < s->n_planes; ++k) {
        const shade_plane *p = &s->planes[k];
        if (p->n_cells == 0 ||
            ss_sun_incidence_deg(90.0 - step->elevation_deg, sun_grid_az, p->tilt_deg,
                                 p->aspect_grid_deg) >= 90.0)
            continue; /* the sun behind the plane: no cell in direct sun */
        s->lit[k * SHADE_SLOTS + (size_t)slot] += (double)lit[k] / p->n_cells;
    }
}

/* One record's sun for ss_shadow_rows (one sun for the grid), and what its
 * sunlit rows add to as each band of them comes: the planes' counts of
 * sunlit cells, and the masks' bits (no row of the grid is held beyond its
 * band). */
typedef struct {
    ss_sun_step sun;
    const roof_shade *s;
    int *lit;       /* per plane: its cells sunlit */
    uint32_t *mask; /* the record's slot of the masks, or NULL */
    uint32_t bit;   /* the record's day's */
    int width;
} shade_step;

static ss_status step_sun(ss_ctx *ctx, int index, int row0, int n_rows, ss_sun_step *step,
                          void *user)
{
    (void)ctx, (void)index, (void)row0, (void)n_rows;
    *step = ((const shade_step *)user)->sun;
    return SS_OK;
}

static ss_status keep_sunlit(void *user, int output, int index, int row0, int n_rows,
                             const float *values)
{
    (void)index;
    shade_step *t = user;
    if (output != SS_OUT_SUNLIT)
        return SS_OK;
    const roof_shade *s = t->s;
    size_t first = (size_t)row0 * (size_t)t->width, end = first + (size_t)n_rows * (size_t)t->width;
    for (size_t k = 0; k < s->n_planes; ++k)
        for (int i = 0; i < s->planes[k].n_cells; ++i) {
            size_t c = (size_t)s->cells[s->planes[k].first + (size_t)i];
            if (c >= first && c < end)
                t->lit[k] += values[c - first] == 1.0f;
        }
    for (size_t c = first; t->mask && c < end; ++c)
        if (values[c - first] == 1.0f)
            t->mask[c] |= t->bit;
    return SS_OK;
}

ss_status roof_shade_sweep(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                           double grid_north_deg, const ss_sun_step *steps, int n_steps,
                           double utc_offset_h, roof_shade *s)
{
    size_t cells = (size_t)src->width * (size_t)src->height;
    s->lit = calloc(s->n_planes * SHADE_SLOTS + 1, sizeof *s->lit);
    int *lit = malloc(sizeof(int) * (s->n_planes + 1));
    ss_status st = s->lit && lit ? SS_OK
                                 : ss_ctx_error(ctx, SS_ERR_MEMORY,
                                                "out of memory for the planes' shade table");
    /* Box shadows by each cell's own ray read the heights whole: once for
     * every record, not once a record (a DSM read in bands; counted by
     * run_march_cell_bytes). */
    ss_source held = *src;
    float *owned = NULL;
    if (st == SS_OK && !src->z && opt->lines == SS_LINES_BOX &&
        opt->box_shadows == SS_BOX_SHADOWS_MARCH)
        st = ss_source_heights(ctx, src, &owned, &held.z);
    for (int i = 0; st == SS_OK && i < n_steps; ++i) {
        const ss_sun_step *step = &steps[i];
        int day, slot = slot_of(step->unix_s, utc_offset_h, &day);
        s->records[slot]++;
        if (!(step->apparent_elevation_deg > 0))
            continue; /* night: nothing in direct sun */
        double sun_grid_az = step->azimuth_deg - grid_north_deg; /* steps' azimuths are true */
        /* the shadow product's own sweep (ss_shadow_rows), so that a cell's
         * verdict is what `skysweep shadow` gives for that instant */
        shade_step t = {.sun = {.azimuth_deg = sun_grid_az + opt->grid_north_deg,
                                .grid_azimuth_deg = sun_grid_az,
                                .elevation_deg = step->elevation_deg,
                                .apparent_elevation_deg = step->apparent_elevation_deg},
                        .s = s,
                        .lit = lit,
                        .mask = s->masks ? s->masks + (size_t)slot * cells : NULL,
                        .bit = (uint32_t)1 << (day - 1),
                        .width = src->width};
        memset(lit, 0, sizeof(int) * (s->n_planes + 1));
        st = ss_shadow_rows(ctx, &held, opt, step_sun, &t, keep_sunlit, &t);
        if (st == SS_OK)
            add_shares(s, step, sun_grid_az, lit, slot);
        s->sweeps++;
    }
    free(owned);
    free(lit);
    return st;
}

double roof_shade_fraction(const roof_shade *s, size_t k, int month, int hour)
{
    int slot = month * 24 + hour;
    return s->records[slot] ? s->lit[k * SHADE_SLOTS + (size_t)slot] / s->records[slot] : NAN;
}

void roof_shade_free(roof_shade *s)
{
    free(s->planes);
    free(s->cells);
    free(s->lit);
    free(s->masks);
    *s = (roof_shade){0};
}
