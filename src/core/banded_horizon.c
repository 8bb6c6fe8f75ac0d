/* The banded horizon: one grid of horizon angles (and distances, casting
 * heights) per direction, for a DEM that is never held whole.
 *
 * The bands, passes, owner rows and hulls handed on are the sum sweep's
 * (banded.c). What differs: a direction's horizon is not summed with the
 * others', so each direction has its own sums (weighted angles, weights,
 * and the casters) while a band is walked, and the band's rows are
 * finished as soon as its lines have walked them: every sample feeding
 * them is owned by this band or, for the first row in the pass's order,
 * the band before it, whose share is carried over as one row of sums per
 * direction. So the rows go to the caller per direction and band, and no
 * temporary file is needed. Each direction in turn uses the same band
 * buffers; the carried rows are the only per-direction state besides the
 * hulls. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "band_walk.h"
#include "products_internal.h"

#define HALO SS_BAND_HALO
#define N_SUMS 4 /* weighted angles, weights, distances, casting heights */

typedef struct {
    ss_line_set ls;         /* whole-grid line set */
    int index;              /* in the caller's azimuths */
    ss_carried_hull *hulls; /* one per line */
    float *carried;         /* N_SUMS rows of sums fed into the next band */
} horizon_direction;

typedef struct {
    ss_band_grid grid;
    const ss_horizon_band_io *io;
    int want;  /* SS_HORIZON_WANT_* bits for the walk */
    int asked; /* the caller's SS_HORIZON_* bits */
    float curv_k;
    float *sums[N_SUMS]; /* held cells each, like the grid */
    ss_band_stats stats;
} horizon_run;

double ss_horizon_band_cell_bytes(int want)
{
    /* Heights, stack slots, weighted angles and weights; distances, which
     * casting heights need too; casting heights. */
    int want_cast = (want & SS_HORIZON_CAST_HEIGHT) != 0;
    int grids = 4 + (want_cast || (want & SS_HORIZON_DISTANCE)) + want_cast;
    return 4.0 * grids;
}

double ss_horizon_column_bytes(void)
{
    return N_SUMS * sizeof(float);
}

/* The row of sums the band's walk fed into the next band: the row after
 * the band going down, before it going up. */
static size_t fed_row(int pass, int rows, int width)
{
    return (size_t)(pass > 0 ? HALO + rows : HALO - 1) * (size_t)width;
}

/* Where the carried row goes in the next band: its first own row going
 * down, its last going up (the bands above the last are full). */
static size_t landing_row(int pass, int band_rows, int width)
{
    return (size_t)(pass > 0 ? HALO : HALO + band_rows - 1) * (size_t)width;
}

/* The horizon sums of a line's steps in the band. */
static void add_horizon_steps(void *user, ss_walker *wk, const ss_line_set *ls, int s_lo,
                              int s_hi, int flags)
{
    const horizon_run *h = user;
    float *const *s = h->sums;
    ss_horizon_steps(wk, ls, s_lo, s_hi, h->curv_k, h->grid.z, h->grid.stack, s[0], s[1], s[2],
                     s[3], h->want, flags);
}

/* One direction in one band: its carried sums in, the walk, the sums fed
 * into the next band out, and the band's own rows finished and written. */
static ss_status direction_in_band(horizon_run *h, horizon_direction *dir, int row0, int rows,
                                   int pass)
{
    size_t w = (size_t)h->grid.width, held = ss_band_held_cells(&h->grid);
    for (int k = 0; k < N_SUMS; ++k)
        if (h->sums[k]) {
            memset(h->sums[k], 0, held * sizeof(float));
            memcpy(h->sums[k] + landing_row(pass, h->grid.band_rows, (int)w), dir->carried + k * w,
                   w * sizeof(float));
        }
    ss_status st = ss_band_walk(&h->grid, &dir->ls, dir->hulls, row0, row0 + rows, pass,
                                h->curv_k, add_horizon_steps, h, &h->stats);
    for (int k = 0; st == SS_OK && k < N_SUMS; ++k)
        if (h->sums[k])
            memcpy(dir->carried + k * w, h->sums[k] + fed_row(pass, rows, (int)w),
                   w * sizeof(float));
    if (st != SS_OK)
        return st;
    size_t own = (size_t)HALO * w, n = (size_t)rows * w;
    float *angle = h->sums[0] + own, *weight = h->sums[1] + own;
    float *dist = h->sums[2] ? h->sums[2] + own : NULL;
    float *cast = h->sums[3] ? h->sums[3] + own : NULL;
    const float *z = h->grid.z + own;
    for (size_t c = 0; c < n; ++c) {
        ss_pass_horizon_finish((int)c, h->io->none_deg, angle, weight);
        int no_height = !SS_ISFINITE(z[c]);
        if (no_height)
            angle[c] = SS_NODATA;
        if (cast && (no_height || dist[c] == 0.0f))
            cast[c] = SS_NODATA;
        if (dist && no_height)
            dist[c] = SS_NODATA;
    }
    int want_dist = (h->asked & SS_HORIZON_DISTANCE) != 0;
    return h->io->write(h->io->user, dir->index, row0, rows, angle, want_dist ? dist : NULL, cast);
}

static ss_status run_pass(horizon_run *h, horizon_direction *dirs, int n_dirs, int pass,
                          double *progress, double progress_per_band)
{
    int height = h->io->height, band_rows = h->grid.band_rows;
    int bands = (height + band_rows - 1) / band_rows;
    ss_status st = SS_OK;
    for (int k = 0; k < bands && st == SS_OK && (n_dirs > 0 || h->io->band_done); ++k) {
        int band = pass > 0 ? k : bands - 1 - k;
        int row0 = band * band_rows, rows = row0 + band_rows < height ? band_rows : height - row0;
        if (n_dirs > 0)
            st = ss_band_read(&h->grid, row0, rows);
        for (int d = 0; d < n_dirs && st == SS_OK; ++d)
            st = direction_in_band(h, &dirs[d], row0, rows, pass);
        if (st == SS_OK && h->io->band_done)
            st = h->io->band_done(h->io->user, pass > 0 ? 0 : 1, row0, rows);
        *progress += progress_per_band;
        if (st == SS_OK)
            st = ss_progress(h->grid.ctx, *progress, "banded horizon");
    }
    return st;
}

static ss_status check_io(ss_ctx *ctx, const ss_horizon_band_io *io)
{
    if (!io || !io->read || !io->write || io->width < 2 || io->height < 2 || io->band_rows < 1 ||
        !(io->cell_x_m > 0) || !(io->cell_y_m > 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "banded horizon needs a grid of at least 2 x 2 cells with positive cell "
                       "sizes, a reader, a writer and at least one row per band");
    if (io->n_azimuths < 0 || (io->n_azimuths > 0 && !io->azimuths_deg))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "banded horizon: %d azimuths without a list",
                       io->n_azimuths);
    for (int i = 0; i < io->n_azimuths; ++i)
        if (!isfinite(io->azimuths_deg[i]))
            return ss_fail(ctx, SS_ERR_ARGUMENT, "azimuth %d is not a number", i);
    return SS_OK;
}

ss_status ss_horizon_banded(ss_ctx *ctx, const ss_horizon_band_io *io, const ss_sweep_options *opt,
                            int want)
{
    ss_status st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK)
        st = check_io(ctx, io);
    if (st != SS_OK)
        return st;
    horizon_run h = {0};
    h.io = io;
    h.grid = (ss_band_grid){
        ctx,       io->read,   io->user,
        io->width, io->height, io->band_rows < io->height ? io->band_rows : io->height,
        0,         NULL,       NULL};
    /* Casting heights ride on the distances (ss_horizon_caster). */
    int want_cast = (want & SS_HORIZON_CAST_HEIGHT) != 0;
    int want_dist = want_cast || (want & SS_HORIZON_DISTANCE);
    h.want = (want_dist ? SS_HORIZON_WANT_DIST : 0) | (want_cast ? SS_HORIZON_WANT_CAST : 0);
    h.asked = want;
    h.curv_k = ss_curvature_k(opt);
    int n_dirs = io->n_azimuths > 0 ? io->n_azimuths : opt->directions;
    size_t held = 0, w = (size_t)io->width;
    st = ss_band_grid_alloc(&h.grid);
    if (st == SS_OK)
        held = ss_band_held_cells(&h.grid);
    for (int k = 0; st == SS_OK && k < N_SUMS; ++k)
        if (k < 2 || (k == 2 && want_dist) || (k == 3 && want_cast))
            if (!(h.sums[k] = ss_malloc(held * sizeof(float))))
                st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of %d rows",
                             h.grid.band_rows);
    horizon_direction *dirs = st == SS_OK ? ss_calloc((size_t)n_dirs, sizeof *dirs) : NULL;
    if (st == SS_OK && !dirs)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for %d directions", n_dirs);
    ss_grid dims = {io->width, io->height, io->cell_x_m, io->cell_y_m, 0.0, NULL};
    /* Down-pass directions first, then the up-pass ones. */
    int n_down = 0;
    for (int i = 0; st == SS_OK && i < n_dirs; ++i) {
        ss_line_set ls;
        ss_product_lines_at(&dims, opt,
                            io->n_azimuths > 0 ? io->azimuths_deg[i] : ss_direction_azimuth(opt, i),
                            &ls);
        n_down += ss_band_pass_of(&ls) > 0;
    }
    int next[2] = {0, n_down};
    for (int i = 0; st == SS_OK && i < n_dirs; ++i) {
        ss_line_set ls;
        ss_product_lines_at(&dims, opt,
                            io->n_azimuths > 0 ? io->azimuths_deg[i] : ss_direction_azimuth(opt, i),
                            &ls);
        horizon_direction *d = &dirs[next[ss_band_pass_of(&ls) > 0 ? 0 : 1]++];
        d->ls = ls;
        d->index = i;
        d->hulls = ss_calloc((size_t)ls.n_lines, sizeof *d->hulls);
        d->carried = ss_calloc(N_SUMS * w, sizeof(float));
        if (!d->hulls || !d->carried)
            st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the lines of a direction");
    }
    double t0 = ss_seconds_now(), progress = 0;
    int bands = (io->height + h.grid.band_rows - 1) / h.grid.band_rows;
    if (st == SS_OK)
        st = run_pass(&h, dirs, n_down, 1, &progress, 0.5 / bands);
    if (st == SS_OK)
        st = run_pass(&h, dirs + n_down, n_dirs - n_down, -1, &progress, 0.5 / bands);
    ctx->counters.sweep_seconds += ss_seconds_now() - t0;
    ctx->counters.sweeps += (uint64_t)n_dirs;
    ctx->counters.cells_swept += (uint64_t)n_dirs * (uint64_t)io->width * (uint64_t)io->height;
    if (io->stats)
        *io->stats = h.stats;
    for (int i = 0; dirs && i < n_dirs; ++i) {
        ss_carried_hulls_free(dirs[i].hulls, dirs[i].ls.n_lines);
        free(dirs[i].carried);
    }
    free(dirs);
    for (int k = 0; k < N_SUMS; ++k)
        free(h.sums[k]);
    ss_band_grid_free(&h.grid);
    return st;
}
