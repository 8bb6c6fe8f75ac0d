/* Horizon angles: a horizon walk, each direction's rows handed on as soon
 * as a band has them, so that only one batch of directions is held. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "products_internal.h"
#include "ss_passes.h"

typedef struct {
    ss_ctx *ctx;
    int want;             /* SS_HORIZON_* bits asked for */
    const ss_source *src; /* the heights' origin, read once a band has been read */
    const double *azimuths; /* per direction (the whole-grid sink's) */
    /* Where finished rows go: a rows sink, or the whole-grid call's sink. */
    ss_rows_sink sink;
    void *user;
    ss_horizon_sink whole;
} horizon_run;

/* Marks nodata (and casting heights without a caster), puts the casting
 * heights on the DEM's datum, and hands the rows on. */
static ss_status horizon_rows(void *user, int index, const ss_band_view *band,
                              const ss_dir_rows *rows, float *planes)
{
    (void)planes;
    horizon_run *h = user;
    size_t n = (size_t)band->n_rows * (size_t)band->width;
    float *angle = rows->angle, *dist = rows->dist, *cast = rows->cast;
    double origin = ss_source_origin(h->src);
    for (size_t c = 0; c < n; ++c) {
        int no_height = !isfinite(band->own_z[c]);
        if (no_height)
            angle[c] = SS_NODATA;
        if (cast)
            cast[c] = no_height || dist[c] == 0.0f ? SS_NODATA
                                                   : (float)(origin + (double)cast[c]);
        if (dist && no_height)
            dist[c] = SS_NODATA;
    }
    float *wanted_dist = h->want & SS_HORIZON_DISTANCE ? dist : NULL;
    if (h->whole)
        return h->whole(index, h->azimuths[index], angle, wanted_dist, cast, h->user)
                   ? SS_OK
                   : ss_fail(h->ctx, SS_ERR_CANCELLED, "stopped while storing direction %d",
                             index);
    ss_status st = h->sink(h->user, SS_OUT_HORIZON_ANGLE, index, band->row0, band->n_rows, angle);
    if (st == SS_OK && wanted_dist)
        st = h->sink(h->user, SS_OUT_HORIZON_DISTANCE, index, band->row0, band->n_rows, dist);
    if (st == SS_OK && cast)
        st = h->sink(h->user, SS_OUT_HORIZON_CAST_HEIGHT, index, band->row0, band->n_rows, cast);
    return st;
}

static ss_status run_horizon(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                             horizon_run *h)
{
    int n = opt->directions;
    ss_engine_dir *dirs = ss_malloc(sizeof *dirs * (size_t)n);
    double *azimuths = ss_malloc(sizeof *azimuths * (size_t)n);
    if (!dirs || !azimuths) {
        free(dirs);
        free(azimuths);
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory for %d directions", n);
    }
    for (int i = 0; i < n; ++i) {
        azimuths[i] = ss_direction_azimuth(opt, i);
        dirs[i] = (ss_engine_dir){azimuths[i], 1, i, -1};
    }
    h->azimuths = azimuths;
    /* Casting heights ride on the distances (ss_horizon_caster). */
    int want_cast = (h->want & SS_HORIZON_CAST_HEIGHT) != 0;
    int want_dist = want_cast || (h->want & SS_HORIZON_DISTANCE);
    ss_consumer consumer = {.planes = 0, .direction = horizon_rows};
    ss_engine_job job = {
        .walk = {.term = SS_TERM_HORIZON,
                 .want = (want_dist ? SS_HORIZON_WANT_DIST : 0) |
                         (want_cast ? SS_HORIZON_WANT_CAST : 0),
                 .none_deg = -90.0f},
        .dirs = dirs,
        .n_dirs = n,
        .consumer = &consumer,
        .user = h,
        .what = "horizon"};
    ss_status st = ss_horizon_walk(ctx, src, opt, &job);
    free(dirs);
    free(azimuths);
    return st;
}

ss_status ss_horizon_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                          int want, ss_rows_sink sink, void *user)
{
    ss_call_begin(ctx);
    ss_status st = ss_rows_begin(ctx, src, opt, NULL);
    if (st != SS_OK)
        return st;
    horizon_run h = {ctx, want, src, NULL, sink, user, NULL};
    return run_horizon(ctx, src, opt, &h);
}

ss_status ss_horizon(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt, int want,
                     ss_horizon_sink sink, void *user)
{
    ss_call_begin(ctx);
    ss_status st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK)
        st = ss_grid_check(ctx, grid, NULL);
    if (st != SS_OK)
        return st;
    ss_source src = ss_source_of_grid(grid);
    horizon_run h = {ctx, want, &src, NULL, NULL, user, sink};
    return run_horizon(ctx, &src, opt, &h);
}

ss_status ss_bare_pass(ss_ctx *ctx, const ss_grid *grid, double azimuth_deg,
                       ss_line_model lines, float *out)
{
    ss_call_begin(ctx);
    if (lines == SS_LINES_BOX) /* its lines read every cell once per family */
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "the bare pass takes interpolated or digital lines, not box lines");
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.lines = lines;
    opt.directions = 1;
    opt.offset_deg = isfinite(azimuth_deg) ? fmod(azimuth_deg, 360.0) : azimuth_deg;
    ss_status st = ss_sweep_options_check(ctx, &opt);
    if (st == SS_OK)
        st = ss_grid_check(ctx, grid, NULL);
    if (st != SS_OK)
        return st;
    ss_backend b = {.ctx = ctx,
                    .walk = {.term = SS_SVF_GEOMETRIC},
                    .width = grid->width,
                    .max_held_rows = grid->height,
                    .batch = 1,
                    .whole_z = grid->z};
    st = ss_backend_open(&b);
    ss_band_dir d = {0};
    ss_product_lines(grid, &opt, 0, &d.ls);
    ss_band_run run = {.row1 = grid->height,
                       .held_rows = grid->height,
                       .height = grid->height,
                       .width = grid->width,
                       .whole = 1};
    float *host = NULL;
    if (st == SS_OK)
        st = b.ops->load(&b, &run, grid->z, NULL);
    if (st == SS_OK)
        st = b.ops->bare(&b, &run, &d, &host);
    if (st == SS_OK)
        for (size_t c = 0; c < (size_t)grid->width * (size_t)grid->height; ++c)
            out[c] += host[c];
    if (b.impl)
        b.ops->close(&b);
    return st;
}
