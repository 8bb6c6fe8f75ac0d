/* The banded sweep: SVF and openness of a DEM that is never held whole.
 *
 * The grid is cut into bands of whole rows, read one at a time (with one
 * halo row above and below). A direction's lines cross the bands in one
 * order: downward for the directions whose lines walk toward growing rows,
 * upward for the others. So the directions run in two passes, each visiting
 * every band once in its order, and each line's walk stops at the band's
 * edge and resumes in the next band with its hull handed on as whole
 * points (ss_walker_resume; the hull is exact, so the result is the
 * whole-grid sweep's, up to the order of float additions).
 *
 * Which band walks a sample: the one holding its "owner" row. Every row a
 * sample touches is the owner or next to it, and owners only grow along a
 * walk in the down pass (shrink in the up pass):
 *   - lines along columns (one row per step): the step's row;
 *   - lines along rows, down pass: the row at or above the line (minor0),
 *     which may also feed the row below, the next band's first row;
 *   - lines along rows, up pass: the row below (minor0 + 1), which may also
 *     feed the row above, the next band's last row.
 * A band therefore holds its rows plus halo rows on each side (two: the
 * radiative SVF's slope at a halo cell reads one row further), and what
 * its samples add into the first halo row is carried into the next band.
 *
 * The down pass's sums wait in a temporary file, band by band, until the
 * up pass completes the same rows; then the finished rows go to the
 * caller (or their sums, for processes that share the directions).
 * Memory: three (rows + 4) x width grids (heights, hull stack
 * slots, sums), two more for the radiative SVF's gradients, and the
 * handed-on hulls, whose sizes are counted. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ctx_internal.h"
#include "lines.h"
#include "products_internal.h"
#include "band_walk.h"
#include "session.h"

#define HALO SS_BAND_HALO

typedef struct {
    ss_line_set ls;          /* whole-grid line set */
    float sin_az, cos_az;    /* for the radiative term */
    ss_carried_hull *hulls;  /* one per line */
} band_direction;

typedef struct {
    ss_band_grid grid;      /* heights and hull stack slots of the band */
    const ss_band_io *io;
    const ss_sweep_options *opt;
    ss_sky_term sky;
    int term;               /* the kernels' SS_SVF_* or SS_TERM_ELEVATION */
    float curv_k;
    int width, band_rows;
    float *acc;             /* sums, (band_rows + 2 HALO) x width like the grid */
    float *grad;            /* radiative SVF: the band's surface gradients, 2 floats a cell */
    FILE *partial;          /* the down pass's sums, whole rows */
    ss_band_stats stats;
} band_run;

/* The SVF or openness term of a line's steps in the band. */
typedef struct {
    const band_run *b;
    const band_direction *dir;
    int rows_held;
} sky_steps;

static void add_sky_steps(void *user, ss_walker *wk, const ss_line_set *ls, int s_lo, int s_hi,
                          int flags)
{
    const sky_steps *k = user;
    const band_run *b = k->b;
    ss_svf_steps(wk, ls, s_lo, s_hi, b->term, b->curv_k, k->dir->sin_az, k->dir->cos_az,
                 (float)b->io->cell_x_m, (float)b->io->cell_y_m, k->rows_held, b->grid.z, b->grad,
                 b->grid.stack, b->acc, flags);
}

/* Walks, for one direction, every line's steps owned by rows [row0, row1). */
static ss_status walk_band(band_run *b, band_direction *dir, int row0, int row1, int pass)
{
    sky_steps k = {b, dir, row1 - row0 + 2 * HALO};
    return ss_band_walk(&b->grid, &dir->ls, dir->hulls, row0, row1, pass, b->curv_k,
                        add_sky_steps, &k, &b->stats);
}

static ss_status store_partial(band_run *b, int row0, int rows, int load)
{
    size_t w = (size_t)b->width, n = (size_t)rows * w;
    if (fseeko(b->partial, (off_t)((size_t)row0 * w * sizeof(float)), SEEK_SET) != 0)
        return ss_fail(b->grid.ctx, SS_ERR_OUTPUT, "temporary file: cannot seek");
    float *rows_acc = b->acc + HALO * w; /* the band's own rows, after the halo */
    if (!load)
        return fwrite(rows_acc, sizeof(float), n, b->partial) == n
                   ? SS_OK
                   : ss_fail(b->grid.ctx, SS_ERR_OUTPUT,
                             "temporary file: write failed (disk full?)");
    float *tmp = (float *)b->grid.stack; /* the stack grid is free by now */
    if (fread(tmp, sizeof(float), n, b->partial) != n)
        return ss_fail(b->grid.ctx, SS_ERR_OUTPUT, "temporary file: read failed");
    for (size_t c = 0; c < n; ++c)
        rows_acc[c] += tmp[c];
    return SS_OK;
}

/* One pass over the bands in its order; the up pass finishes the rows. */
static ss_status run_pass(band_run *b, band_direction *dirs, int n_dirs, int pass,
                          double *progress, double progress_per_band)
{
    int h = b->io->height, w = b->width, bands = (h + b->band_rows - 1) / b->band_rows;
    size_t held = (size_t)(b->band_rows + 2 * HALO) * w;
    memset(b->acc, 0, held * sizeof(float));
    ss_status st = SS_OK;
    for (int k = 0; k < bands && st == SS_OK; ++k) {
        int band = pass > 0 ? k : bands - 1 - k;
        int row0 = band * b->band_rows;
        int row1 = row0 + b->band_rows < h ? row0 + b->band_rows : h, rows = row1 - row0;
        st = ss_band_read(&b->grid, row0, rows);
        if (st == SS_OK && b->grad) {
            /* The band's rows as a grid: the same Horn gradients that each
             * sample would compute on the spot, once per cell. */
            ss_grid rows_held = {w, rows + 2 * HALO, b->io->cell_x_m, b->io->cell_y_m, 0.0,
                                 b->grid.z};
            ss_gradient_grid(&rows_held, b->grad);
        }
        for (int d = 0; d < n_dirs && st == SS_OK; ++d)
            st = walk_band(b, &dirs[d], row0, row1, pass);
        if (st == SS_OK && pass > 0)
            st = store_partial(b, row0, rows, 0);
        if (st == SS_OK && pass < 0) {
            st = store_partial(b, row0, rows, 1);
            float *out = b->acc + HALO * w;
            const float *z = b->grid.z + HALO * w;
            for (size_t c = 0; st == SS_OK && c < (size_t)rows * w; ++c)
                out[c] = !SS_ISFINITE(z[c])      ? (b->io->write_sums ? NAN : SS_NODATA)
                         : b->io->write_sums ? out[c]
                                             : ss_sky_value(b->sky, out[c], b->opt->directions);
            if (st == SS_OK)
                st = b->io->write(b->io->user, row0, rows, out);
        }
        /* What went into the next band's nearest row (row1 going down, row0
         * - 1 going up) is carried into it: its first own row going down,
         * its last going up (bands above the last are full). */
        float *fed = b->acc + (size_t)(pass > 0 ? HALO + rows : HALO - 1) * w;
        float *keep = (float *)b->grid.stack; /* scratch: the stack grid is rebuilt per band */
        memcpy(keep, fed, (size_t)w * sizeof(float));
        memset(b->acc, 0, held * sizeof(float));
        float *dest = b->acc + (size_t)(pass > 0 ? HALO : HALO + b->band_rows - 1) * w;
        memcpy(dest, keep, (size_t)w * sizeof(float));
        *progress += progress_per_band;
        if (st == SS_OK)
            st = ss_progress(b->grid.ctx, *progress, "banded sweep");
    }
    return st;
}

static ss_status banded(ss_ctx *ctx, const ss_band_io *io, const ss_sweep_options *opt,
                        ss_sky_term term)
{
    ss_status st = SS_OK;
    if (!io || !io->read || !io->write || io->width < 2 || io->height < 2 ||
        io->band_rows < 1 || !(io->cell_x_m > 0) || !(io->cell_y_m > 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "banded sweep needs a grid of at least 2 x 2 cells with positive cell "
                       "sizes, a reader, a writer and at least one row per band");
    band_run b = {0};
    b.grid = (ss_band_grid){ctx, io->read, io->user, io->width, io->height,
                            io->band_rows < io->height ? io->band_rows : io->height,
                            term == SS_SKY_OPENNESS_NEGATIVE, NULL, NULL};
    b.io = io;
    b.opt = opt;
    b.sky = term;
    b.term = term <= SS_SKY_SVF_TILTED ? (int)term : SS_TERM_ELEVATION;
    b.curv_k = ss_curvature_k(opt);
    b.width = io->width;
    b.band_rows = b.grid.band_rows;
    st = ss_band_grid_alloc(&b.grid);
    b.acc = ss_malloc(ss_band_held_cells(&b.grid) * sizeof(float));
    if (term == SS_SKY_SVF_TILTED && !(b.grad = ss_malloc(2 * ss_band_held_cells(&b.grid) *
                                                       sizeof(float))))
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of %d rows", b.band_rows);
    band_direction *dirs = ss_calloc((size_t)opt->directions, sizeof *dirs);
    if (st == SS_OK && (!b.acc || !dirs))
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of %d rows", b.band_rows);
    if (st == SS_OK && !(b.partial = tmpfile()))
        st = ss_fail(ctx, SS_ERR_OUTPUT, "cannot create a temporary file for the banded sweep");
    ss_grid dims = {io->width, io->height, io->cell_x_m, io->cell_y_m, 0.0, NULL};
    /* This process's share of the directions, down-pass ones first. */
    int n_dirs = 0, n_down = 0;
    for (int i = io->first; i < opt->directions && st == SS_OK; i += io->stride) {
        n_dirs++;
        ss_line_set ls;
        ss_product_lines(&dims, opt, i, &ls);
        n_down += ss_band_pass_of(&ls) > 0;
    }
    /* Down-pass directions first in dirs, then the up-pass ones. */
    int next[2] = {0, n_down};
    for (int i = io->first; i < opt->directions && st == SS_OK; i += io->stride) {
        ss_line_set ls;
        double az = ss_product_lines(&dims, opt, i, &ls);
        band_direction *d = &dirs[next[ss_band_pass_of(&ls) > 0 ? 0 : 1]++];
        d->ls = ls;
        d->sin_az = (float)sin(az);
        d->cos_az = (float)cos(az);
        d->hulls = ss_calloc((size_t)ls.n_lines, sizeof *d->hulls);
        if (!d->hulls)
            st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for the lines of a direction");
    }
    double t0 = ss_seconds_now(), progress = 0;
    int bands = (io->height + b.band_rows - 1) / b.band_rows;
    if (st == SS_OK)
        st = run_pass(&b, dirs, n_down, 1, &progress, 0.5 / bands);
    if (st == SS_OK)
        st = run_pass(&b, dirs + n_down, n_dirs - n_down, -1, &progress, 0.5 / bands);
    ctx->counters.sweep_seconds += ss_seconds_now() - t0;
    ctx->counters.sweeps += (uint64_t)n_dirs;
    ctx->counters.cells_swept += (uint64_t)n_dirs * (uint64_t)io->width * (uint64_t)io->height;
    if (io->stats)
        *io->stats = b.stats;
    for (int i = 0; dirs && i < n_dirs; ++i)
        ss_carried_hulls_free(dirs[i].hulls, dirs[i].ls.n_lines);
    free(dirs);
    if (b.partial)
        fclose(b.partial);
    ss_band_grid_free(&b.grid);
    free(b.acc);
    free(b.grad);
    return st;
}

size_t ss_band_bytes(int width, int band_rows)
{
    return (size_t)(band_rows + 2 * HALO) * (size_t)width * (2 * sizeof(float) + sizeof(int));
}

double ss_sky_band_cell_bytes(ss_sky_term term)
{
    /* Heights, stack slots and sums; the radiative SVF's gradients. */
    return (double)(ss_band_bytes(1, 1) / (1 + 2 * HALO)) +
           (term == SS_SKY_SVF_TILTED ? 2.0 * sizeof(float) : 0.0);
}

/* A whole-grid SVF or openness holds at most 24 bytes a cell: heights,
 * hull stack slots, sums and the product, and either an inverted copy
 * (negative openness) or the surface gradients (radiative SVF, 8 bytes);
 * besides the sweep's grids a run needs buffers for reading and writing
 * (GDAL's block cache, capped at 16 MiB by the CLI in banded runs). */
#define WHOLE_BYTES_PER_CELL 24.0
#define FIXED_BYTES (48.0 * 1048576.0)

double ss_whole_sweep_bytes(int width, int height)
{
    return (double)width * (double)height * WHOLE_BYTES_PER_CELL + FIXED_BYTES;
}

int ss_band_rows_for(int width, int height, int directions, double budget_bytes)
{
    return ss_band_rows_within(width, height, directions, budget_bytes,
                               (double)ss_band_bytes(1, 1) / (1 + 2 * HALO), 0.0);
}

/* What a banded run holds besides its band's rows: fixed buffers, the
 * hulls handed on (about 8 points of 16 bytes per line and direction on
 * terrain, doc/scale.md measures them) and what it carries per column and
 * direction between bands. */
static double band_overhead_bytes(int width, int height, int directions, double column_bytes)
{
    int dirs = directions > 0 ? directions : 64;
    double hulls = ((double)width + height) * dirs * 8.0 * 16.0;
    double carried = (double)width * dirs * column_bytes;
    return FIXED_BYTES + hulls + carried;
}

int ss_band_rows_within(int width, int height, int directions, double budget_bytes,
                        double band_cell_bytes, double column_bytes)
{
    if (ss_whole_sweep_bytes(width, height) <= budget_bytes)
        return 0;
    double per_row = band_cell_bytes * width;
    double rows = (budget_bytes - band_overhead_bytes(width, height, directions, column_bytes)) /
                      per_row -
                  2 * HALO;
    if (rows < 1)
        return -1;
    /* Whole 256-row strips keep GeoTIFF tiles from being written twice. */
    int r = rows >= 256 ? 256 * (int)(rows / 256) : (int)rows;
    return r < height ? r : height;
}

double ss_band_min_budget(int width, int height, int directions, double band_cell_bytes,
                          double column_bytes)
{
    double one_band = band_overhead_bytes(width, height, directions, column_bytes) +
                      band_cell_bytes * width * (1 + 2 * HALO);
    double whole = ss_whole_sweep_bytes(width, height);
    return one_band < whole ? one_band : whole;
}

ss_status ss_sky_banded(ss_ctx *ctx, const ss_band_io *io, const ss_sweep_options *opt,
                        ss_sky_term term)
{
    ss_status st = ss_sweep_options_check(ctx, opt);
    if (st == SS_OK && io)
        st = ss_sky_check(ctx, term, 0.0, io->first, io->stride, opt->directions);
    if (st != SS_OK)
        return st;
    return banded(ctx, io, opt, term);
}
