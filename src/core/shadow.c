/* Cast shadows: one exact sweep along the sun's azimuth, not an
 * interpolation between stored directions. A cell is sunlit when the sun
 * stands above its terrain horizon in that azimuth; where no terrain lies
 * ahead inside the grid the horizon is taken as the horizontal, so a sun
 * below 0 degrees lights nothing there. A cell beside the grid's edge or
 * a hole whose two samples disagree takes the mean of those with terrain
 * ahead, never a mix with the horizontal (doc/model.md, Edges). */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "products_internal.h"

typedef struct {
    ss_ctx *ctx;
    const ss_source *src;
    /* ss_cast_shadow: the sun, and where the rows go */
    double sun_elevation_deg;
    const float *sun_per_cell; /* whole grid */
    float *sunlit, *horizon;
    /* ss_shadow_rows */
    ss_sun_rows_fn sun_rows;
    void *sun_user;
    float *facing, *light; /* a band's rows */
    ss_rows_sink sink;
    void *user;
} shadow_run;

static int sun_position_ok(double azimuth_deg, double elevation_deg)
{
    return isfinite(azimuth_deg) && isfinite(elevation_deg) && fabs(elevation_deg) <= 90.0;
}

/* One horizon walk along azimuth_deg (the horizontal where nothing lies
 * ahead) handed to direction. */
static ss_status shadow_walk(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                             double azimuth_deg,
                             ss_status (*direction)(void *, int, const ss_band_view *,
                                                    const ss_dir_rows *, float *),
                             shadow_run *s)
{
    ss_engine_dir dir = {azimuth_deg, 1, 0, -1};
    ss_consumer consumer = {.planes = 0, .direction = direction};
    ss_engine_job job = {.walk = {.term = SS_TERM_HORIZON, .none_deg = 0.0f},
                         .dirs = &dir,
                         .n_dirs = 1,
                         .consumer = &consumer,
                         .user = s,
                         .what = "shadow"};
    return ss_engine_run(ctx, src, opt, &job);
}

/* The lowest and highest of a per-cell sun (where the grid has heights). */
static void sun_range(const ss_grid *grid, const float *sun_deg, double *lo, double *hi)
{
    *lo = INFINITY;
    *hi = -INFINITY;
    for (size_t c = 0; c < (size_t)grid->width * grid->height; ++c)
        if (isfinite(grid->z[c]) && isfinite(sun_deg[c])) {
            *lo = fmin(*lo, sun_deg[c]);
            *hi = fmax(*hi, sun_deg[c]);
        }
}

static ss_status cast_rows(void *user, int index, const ss_band_view *band,
                           const ss_dir_rows *rows, float *planes)
{
    (void)index, (void)planes;
    shadow_run *s = user;
    size_t n = (size_t)band->n_rows * band->width, at = (size_t)band->row0 * band->width;
    for (size_t c = 0; c < n; ++c) {
        float h = rows->angle[c];
        if (!isfinite(band->own_z[c])) {
            s->sunlit[at + c] = SS_NODATA;
            if (s->horizon)
                s->horizon[at + c] = SS_NODATA;
            continue;
        }
        double sun = s->sun_per_cell ? s->sun_per_cell[at + c] : s->sun_elevation_deg;
        s->sunlit[at + c] = sun > h ? 1.0f : 0.0f;
        if (s->horizon)
            s->horizon[at + c] = h;
    }
    return SS_OK;
}

ss_status ss_cast_shadow(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                         double sun_azimuth_deg, double sun_elevation_deg,
                         const float *sun_elevation_per_cell_deg, float *sunlit,
                         float *horizon_deg)
{
    ss_call_begin(ctx);
    if (!sun_position_ok(sun_azimuth_deg, sun_elevation_deg))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun azimuth %g / elevation %g degrees is not a sun position",
                       sun_azimuth_deg, sun_elevation_deg);
    ss_status st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK)
        st = ss_grid_check(ctx, grid, NULL);
    if (st != SS_OK)
        return st;
    ss_source src = ss_source_of_grid(grid);
    shadow_run s = {.ctx = ctx,
                    .src = &src,
                    .sun_elevation_deg = sun_elevation_deg,
                    .sun_per_cell = sun_elevation_per_cell_deg,
                    .sunlit = sunlit,
                    .horizon = horizon_deg};
    /* The march's horizons tell lit from shaded, not the horizon's angle. */
    if (!horizon_deg && ss_box_shadows_marched(opt)) {
        double lo = sun_elevation_deg, hi = sun_elevation_deg;
        if (sun_elevation_per_cell_deg)
            sun_range(grid, sun_elevation_per_cell_deg, &lo, &hi);
        return ss_box_shadow_march(ctx, &src, opt, sun_azimuth_deg, lo, hi, cast_rows, &s);
    }
    return shadow_walk(ctx, &src, opt, sun_azimuth_deg, cast_rows, &s);
}

/* A band's sunlit, facing and light rows: the cast shadows against each
 * cell's apparent sun, and Horn's incidence from the held rows. */
static ss_status shade_rows(void *user, int index, const ss_band_view *band,
                            const ss_dir_rows *rows, float *planes)
{
    (void)index, (void)planes;
    shadow_run *s = user;
    ss_sun_step sun;
    ss_status st = s->sun_rows(s->ctx, 0, band->row0, band->n_rows, &sun, s->sun_user);
    if (st != SS_OK)
        return st;
    ss_grid held = ss_band_grid(band, s->src);
    int first = band->row0 - band->lo;
    ss_incidence_rows(&held, first, first + band->n_rows, sun.grid_azimuth_deg,
                      sun.apparent_elevation_deg, sun.grid_azimuth_per_cell,
                      sun.apparent_per_cell, s->light);
    size_t n = (size_t)band->n_rows * band->width;
    float *sunlit = rows->angle; /* each cell's horizon becomes its verdict */
    for (size_t c = 0; c < n; ++c) {
        if (!isfinite(band->own_z[c])) {
            sunlit[c] = s->facing[c] = s->light[c] = SS_NODATA;
            continue;
        }
        double el = sun.apparent_per_cell ? sun.apparent_per_cell[c]
                                          : sun.apparent_elevation_deg;
        sunlit[c] = el > sunlit[c] ? 1.0f : 0.0f;
        s->facing[c] = s->light[c] > 0.0f ? 1.0f : 0.0f;
        s->light[c] = s->light[c] > 0.0f ? s->light[c] * sunlit[c] : 0.0f;
    }
    st = s->sink(s->user, SS_OUT_SUNLIT, 0, band->row0, band->n_rows, sunlit);
    if (st == SS_OK)
        st = s->sink(s->user, SS_OUT_FACING, 0, band->row0, band->n_rows, s->facing);
    if (st == SS_OK)
        st = s->sink(s->user, SS_OUT_LIGHT, 0, band->row0, band->n_rows, s->light);
    return st;
}

ss_status ss_shadow_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                         ss_sun_rows_fn sun_rows, void *sun_user, ss_rows_sink sink, void *user)
{
    ss_call_begin(ctx);
    ss_sun_step centre;
    ss_status st = ss_rows_begin(ctx, src, opt, NULL);
    if (st == SS_OK)
        st = sun_rows(ctx, 0, 0, 0, &centre, sun_user);
    if (st != SS_OK)
        return st;
    if (!sun_position_ok(centre.azimuth_deg, centre.apparent_elevation_deg))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "sun azimuth %g / elevation %g degrees is not a sun position",
                       centre.azimuth_deg, centre.apparent_elevation_deg);
    int rows = ss_source_band_rows(src);
    size_t n = (size_t)rows * (size_t)src->width;
    shadow_run s = {.ctx = ctx,
                    .src = src,
                    .sun_rows = sun_rows,
                    .sun_user = sun_user,
                    .facing = ss_malloc(n * sizeof(float)),
                    .light = ss_malloc(n * sizeof(float)),
                    .sink = sink,
                    .user = user};
    if (!s.facing || !s.light)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of shadows");
    else if (ss_box_shadows_marched(opt))
        st = ss_box_shadow_march(ctx, src, opt, centre.azimuth_deg,
                                 centre.apparent_elevation_deg - centre.spread_deg,
                                 centre.apparent_elevation_deg + centre.spread_deg, shade_rows,
                                 &s);
    else
        st = shadow_walk(ctx, src, opt, centre.azimuth_deg, shade_rows, &s);
    free(s.facing);
    free(s.light);
    return st;
}
