/* The one sweep driver (engine.h): bands, passes, groups and batches.
 *
 * A run visits every band of the DEM. With one band (the whole grid) that is
 * one visit walking every direction in order. In bands, a direction's lines
 * meet the bands downward or upward (its pass, kernels/ss_band.h), so the
 * directions go in groups, each walked in a down pass over the bands and
 * then an up pass: a band is visited twice per group, and what a visit
 * leaves in the consumer's planes waits in a temporary file until the next
 * adds to it; the last visit hands the planes over complete. Within a
 * visit, consecutive walked directions are walked together in batches of
 * the backend's size, and each direction reaches the consumer in its turn. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "engine.h"
#include "lines.h"
#include "lit_levels.h"
#include "products_internal.h"
#include "scratch.h"
#include "ss_passes.h"

/* The kernels take the directions from a buffer: no padding may differ. */
_Static_assert(sizeof(ss_band_dir) == 112, "ss_band_dir layout");

ss_status ss_backend_open(ss_backend *b)
{
    return b->ctx->use_reference ? ss_backend_ref_open(b) : ss_backend_ocl_open(b);
}

struct ss_engine_device {
    ss_backend *b;
    const ss_band_run *run; /* the band visited */
    int begun;              /* its cells are on the device */
    int stored_planes;      /* the consumer's device_stored */
};

/* What one run keeps besides the backend. */
typedef struct {
    ss_ctx *ctx;
    const ss_source *src;
    const ss_sweep_options *opt;
    const ss_engine_job *job;
    ss_backend b;
    int band_rows, n_bands, halo, banded;
    float *z;         /* held rows (bands, or the whole grid negated) */
    int any_height;   /* a valid height was read */
    float *grad;      /* their gradients (the radiative SVF) */
    unsigned char *lit_levels; /* the held rows' bounds (walk.lit_bands), else NULL */
    float *planes;    /* the consumer's planes (horizon walks and no walk) */
    float *loaded;    /* a band's planes as earlier visits left them */
    ss_scratch partial; /* planes between visits, whole rows (file NULL: none) */
    ss_band_dir *dirs;      /* every direction's lines; walk order in `order` */
    int *order, n_order;    /* the current group's directions, down pass first */
    int n_down;             /* how many of them walk downward */
    ss_band_dir *batch;
    int *batch_index;       /* what the consumer is told of each slot of the batch */
    int batch_now;          /* directions walked at once now (adapt_batch) */
    int visits, visits_done;
    int delivered;          /* directions handed to the consumer (whole grid) */
    ss_band_stats stats;
    ss_engine_device device; /* the visit's, where the consumer's steps run on the device */
} engine_run;

static int is_sums(const engine_run *e)
{
    return e->job->walk.term != SS_TERM_HORIZON && e->job->walk.term != SS_TERM_NONE;
}

static int walks(const engine_run *e)
{
    return e->job->walk.term != SS_TERM_NONE;
}

/* Reads the band's held rows [lo, lo + n) into e->z, negated where asked,
 * with their gradients for the radiative SVF. */
static ss_status read_band(engine_run *e, int lo, int n)
{
    const ss_source *src = e->src;
    size_t w = (size_t)src->width, cells = (size_t)n * w;
    ss_status st = ss_source_read_rows(e->ctx, src, lo, n, e->z);
    if (st != SS_OK)
        return st;
    for (size_t c = 0; !e->any_height && c < cells; ++c)
        e->any_height = SS_ISFINITE(e->z[c]);
    if (e->job->walk.negate)
        for (size_t c = 0; c < cells; ++c)
            e->z[c] = -e->z[c];
    if (e->grad) {
        ss_grid held = {src->width, n, src->cell_x_m, src->cell_y_m, 0.0, e->z};
        ss_gradient_grid(&held, e->grad);
    }
    return st;
}

/* The walk's term, curvature and cell sizes for a band [row0, row1). */
static ss_band_run band_run_of(const engine_run *e, int row0, int row1)
{
    const ss_walk *walk = &e->job->walk;
    int h = e->src->height;
    ss_band_run run = {0};
    run.row0 = row0;
    run.row1 = row1;
    run.lo = row0 - e->halo > 0 ? row0 - e->halo : 0;
    run.held_rows = (row1 + e->halo < h ? row1 + e->halo : h) - run.lo;
    run.height = h;
    run.width = e->src->width;
    run.whole = !e->banded;
    run.term = walk->term;
    run.want = walk->want;
    run.planes = ss_walk_planes(walk);
    run.curv_k = ss_curvature_k(e->opt);
    run.none_deg = walk->none_deg;
    run.radius_m = (float)walk->radius_m;
    run.cell_x_m = (float)e->src->cell_x_m;
    run.cell_y_m = (float)e->src->cell_y_m;
    run.stack_per_cell = e->b.stack_per_cell;
    return run;
}

/* Stores (write) or loads a band's planes in the temporary file. */
static ss_status partial_rows(engine_run *e, int row0, int n_rows, float *data, int write)
{
    size_t per_row = (size_t)e->src->width * (size_t)e->job->consumer->planes;
    size_t n = per_row * (size_t)n_rows;
    return ss_scratch_move(e->ctx, &e->partial, (off_t)((size_t)row0 * per_row * sizeof(float)),
                           data, n * sizeof(float), write);
}

/* A batch slot's rows, read to the host. */
static ss_status read_rows(ss_backend *b, const ss_band_run *run, ss_dir_rows *rows)
{
    double t0 = ss_seconds_now(); /* the device's rows come back here */
    ss_status st = b->ops->view(b, run, rows->slot, 0, &rows->angle);
    if (st == SS_OK && run->planes > 2)
        st = b->ops->view(b, run, rows->slot, 2, &rows->dist);
    if (st == SS_OK && run->planes > 3)
        st = b->ops->view(b, run, rows->slot, 3, &rows->cast);
    b->ctx->counters.sweep_seconds += ss_seconds_now() - t0;
    return st;
}

ss_status ss_engine_device_rows(ss_engine_device *d, ss_dir_rows *rows)
{
    return read_rows(d->b, d->run, rows);
}

ss_status ss_engine_cells_begin(ss_engine_device *d, const ss_cell_terms *terms, int planes,
                                const int16_t *stored, size_t stored_stride)
{
    ss_status st = d->b->ops->cells_begin(d->b, d->run, terms, planes, stored,
                                          stored ? d->stored_planes : 0, stored_stride);
    d->begun = st == SS_OK;
    return st;
}

ss_status ss_engine_cells_step(ss_engine_device *d, const ss_dir_rows *rows,
                               const ss_cells_step *step, const ss_sun_lattice *lattice,
                               float *step_out)
{
    if (!d->begun)
        return ss_fail(d->b->ctx, SS_ERR_INTERNAL, "a step sent to the device before its cells");
    return d->b->ops->cells_step(d->b, d->run, rows ? rows->slot : -1, step, lattice, step_out);
}

/* Whether a band's cell buffers (terms, sums, stored horizons and a
 * step's global) fit the device together: else the consumer's steps stay
 * on the host for the band, as on a CPU device. */
static int cells_fit(const ss_backend *b, const ss_band_run *run, const ss_consumer *c)
{
    size_t own = (size_t)(run->row1 - run->row0) * (size_t)run->width;
    size_t per_cell = sizeof(ss_cell_terms) + (size_t)c->planes * sizeof(float) +
                      (size_t)c->device_stored * sizeof(int16_t) + sizeof(float);
    return own <= b->cells_max_bytes / per_cell;
}

/* Hands slots [0, n) of the batch just walked to the consumer, in order:
 * their rows read to the host, or left on the device for it. */
static ss_status deliver(engine_run *e, const ss_band_run *run, const ss_band_view *view, int n,
                         float *planes)
{
    const ss_consumer *c = e->job->consumer;
    ss_status st = SS_OK;
    for (int k = 0; k < n && st == SS_OK; ++k) {
        ss_dir_rows rows = {NULL, NULL, NULL, k};
        if (!view->device)
            st = read_rows(&e->b, run, &rows);
        if (st == SS_OK && c->direction)
            st = c->direction(e->job->user, e->batch_index[k], view, &rows, planes);
    }
    return st;
}

static ss_status progress_direction(engine_run *e)
{
    e->delivered++;
    if (e->banded)
        return SS_OK;
    return ss_progress(e->ctx, (double)e->delivered / e->job->n_dirs, e->job->what);
}

/* A batch that runs long keeps a cancelled run waiting (what is queued on
 * a device cannot be stopped): the next batch is halved past a quarter of a
 * second and doubled below a sixteenth, within the backend's batch. The
 * results do not depend on the batch. */
static void adapt_batch(engine_run *e, double seconds)
{
    if (e->ctx->batch > 0)
        return;
    if (seconds > 0.25 && e->batch_now > 1)
        e->batch_now /= 2;
    else if (seconds < 0.0625 && e->batch_now < e->b.batch)
        e->batch_now = 2 * e->batch_now < e->b.batch ? 2 * e->batch_now : e->b.batch;
}

/* Walks the current group's directions of one pass [first, last) of
 * e->order through the band, batch by batch, each direction reaching the
 * consumer in its turn; summed walks add into the backend's sums. */
static ss_status walk_directions(engine_run *e, const ss_band_run *run, const ss_band_view *view,
                                 int first, int last, float *planes)
{
    const ss_engine_job *job = e->job;
    ss_status st = SS_OK;
    int n = 0;
    for (int k = first; k <= last && st == SS_OK; ++k) {
        int d = k < last ? e->order[k] : -1;
        int walked = d >= 0 && job->dirs[d].walk && walks(e);
        if (walked) {
            e->batch[n] = e->dirs[d];
            e->batch[n].ls = ss_band_lines_of(&e->dirs[d].ls, run->lo);
            e->batch[n].slot = n;
            e->batch[n].carry = k;
            e->batch_index[n++] = job->dirs[d].index;
        }
        /* A full batch, or one ended by a direction without a walk or by the
         * pass's end: walked, then handed over. */
        if (n > 0 && (n == e->batch_now || !walked)) {
            double t0 = ss_seconds_now();
            st = e->b.ops->walk(&e->b, run, e->batch, n);
            double seconds = ss_seconds_now() - t0;
            e->ctx->counters.sweep_seconds += seconds;
            adapt_batch(e, seconds);
            if (st == SS_OK && !is_sums(e))
                st = deliver(e, run, view, n, planes);
            for (int j = 0; j < n && st == SS_OK; ++j)
                st = progress_direction(e);
            n = 0;
        }
        if (st == SS_OK && d >= 0 && !walked) {
            if (job->consumer->direction)
                st = job->consumer->direction(job->user, job->dirs[d].index, view, NULL, planes);
            if (st == SS_OK)
                st = progress_direction(e);
        }
    }
    return st;
}

/* One visit of band [row0, row1) in a pass (+1, -1; 0 for the whole grid)
 * for directions [first, last) of e->order. */
static ss_status visit_band(engine_run *e, int row0, int row1, int pass, int first, int last,
                            int first_visit, int last_visit)
{
    const ss_consumer *c = e->job->consumer;
    ss_band_run run = band_run_of(e, row0, row1);
    ss_status st = SS_OK;
    if (e->banded || !e->b.whole_z)
        st = read_band(e, run.lo, run.held_rows);
    const float *z = e->b.whole_z ? e->b.whole_z : e->z;
    e->device = (ss_engine_device){&e->b, &run, 0, c->device_stored};
    int on_device = c->device_cells && walks(e) && e->b.device_cells && cells_fit(&e->b, &run, c);
    ss_band_view view = {row0,      row1 - row0, run.lo, run.held_rows,
                         run.width, run.height,  z,      z + (size_t)(row0 - run.lo) * run.width,
                         on_device ? &e->device : NULL};
    if (st == SS_OK && e->lit_levels && e->banded) {
        st = ss_lit_bands_read(e->job->walk.lit_bands, run.lo, run.held_rows, e->lit_levels);
        e->b.walk.lit_levels = e->lit_levels;
    }
    if (st == SS_OK && walks(e))
        st = e->b.ops->load(&e->b, &run, z, e->grad);
    if (st == SS_OK && c->visit)
        st = c->visit(e->job->user, &view);
    size_t own = (size_t)(row1 - row0) * run.width;
    float *planes = e->planes;
    if (st == SS_OK && is_sums(e))
        st = e->b.ops->sums_begin(&e->b, &run, pass);
    else if (planes)
        memset(planes, 0, sizeof(float) * own * c->planes);
    if (st == SS_OK)
        st = walk_directions(e, &run, &view, first, last, planes);
    if (st == SS_OK && e->device.begun) { /* waits for the device's last steps */
        double t0 = ss_seconds_now();
        st = e->b.ops->cells_end(&e->b, &run, planes);
        e->ctx->counters.sweep_seconds += ss_seconds_now() - t0;
    }
    if (st == SS_OK && is_sums(e)) {
        double t0 = ss_seconds_now(); /* waits for the device's last batch */
        st = e->b.ops->sums_end(&e->b, &run, pass, &planes);
        e->ctx->counters.sweep_seconds += ss_seconds_now() - t0;
    }
    /* What earlier visits left is added in (a + b = b + a in floats, so the
     * order of the two does not matter), and kept for the next. */
    size_t n = own * (size_t)c->planes;
    if (st == SS_OK && e->partial.file && !first_visit) {
        st = partial_rows(e, row0, row1 - row0, e->loaded, 0);
        for (size_t k = 0; st == SS_OK && k < n; ++k)
            planes[k] = e->loaded[k] + planes[k];
    }
    if (st == SS_OK && e->partial.file && !last_visit)
        st = partial_rows(e, row0, row1 - row0, planes, 1);
    if (st == SS_OK && last_visit && c->finish)
        st = c->finish(e->job->user, &view, planes);
    if (st == SS_OK && e->banded && walks(e))
        st = e->b.ops->hulls_swap(&e->b, &e->stats);
    if (st == SS_OK && e->banded) {
        e->visits_done++;
        st = ss_progress(e->ctx, (double)e->visits_done / e->visits, e->job->what);
    }
    return st;
}

/* Orders the group [g0, g1) of the job's directions: down pass first, each
 * pass in index order. */
static void order_group(engine_run *e, int g0, int g1)
{
    e->n_order = 0;
    int by_pass = e->banded && walks(e);
    for (int down = 1; down >= 0; --down)
        for (int d = g0; d < g1; ++d)
            if (by_pass ? (e->dirs[d].pass > 0) == down : down)
                e->order[e->n_order++] = d;
    e->n_down = 0;
    for (int k = 0; k < e->n_order; ++k)
        e->n_down += !by_pass || e->dirs[e->order[k]].pass > 0;
}

/* The hull arrays' line bases of the walked directions [first, last) of
 * the order (those of one pass); returns the total of lines. */
static int line_bases(engine_run *e, int first, int last)
{
    int lines = 0;
    for (int k = first; k < last; ++k) {
        ss_band_dir *d = &e->dirs[e->order[k]];
        d->line_base = lines;
        if (e->job->dirs[e->order[k]].walk)
            lines += ss_line_count(&d->ls);
    }
    return lines;
}

/* The directions [first, last) of e->order that pass p of a group holds
 * (of `passes`; two in bands, down then up). */
static void pass_range(const engine_run *e, int passes, int p, int *first, int *last)
{
    *first = passes == 2 && p == 1 ? e->n_down : 0;
    *last = passes == 2 && p == 0 ? e->n_down : e->n_order;
}

static int is_last_pass(int n_groups, int passes, int g, int p)
{
    return g == n_groups - 1 && p == passes - 1;
}

static ss_status run_groups(engine_run *e)
{
    const ss_engine_job *job = e->job;
    int group = e->banded && job->group > 0 ? job->group : job->n_dirs;
    int n_groups = job->n_dirs > 0 ? (job->n_dirs + group - 1) / group : 1;
    int passes = e->banded && walks(e) ? 2 : 1;
    /* A pass that holds no direction is not visited (a single shadow
     * direction walks one way only), except the run's last: every run then
     * finishes its bands in the same order, which processes adding their
     * band sums in turn (MPI) rely on. */
    int runs = 0;
    for (int g = 0; g < n_groups; ++g) {
        int g0 = g * group, g1 = g0 + group < job->n_dirs ? g0 + group : job->n_dirs;
        order_group(e, g0, g1);
        for (int p = 0; p < passes; ++p) {
            int first, last;
            pass_range(e, passes, p, &first, &last);
            runs += last > first || is_last_pass(n_groups, passes, g, p);
        }
    }
    e->visits = runs * e->n_bands;
    ss_status st = SS_OK;
    int first_visit = 1;
    for (int g = 0; g < n_groups && st == SS_OK; ++g) {
        int g0 = g * group, g1 = g0 + group < job->n_dirs ? g0 + group : job->n_dirs;
        order_group(e, g0, g1);
        for (int p = 0; p < passes && st == SS_OK; ++p) {
            int pass = passes == 2 ? (p == 0 ? 1 : -1) : 0;
            int first, last;
            pass_range(e, passes, p, &first, &last);
            if (last == first && !is_last_pass(n_groups, passes, g, p))
                continue;
            /* Each pass's lines start with empty hulls at its first band. */
            int lines = line_bases(e, first, last);
            if (e->banded && walks(e))
                st = e->b.ops->pass_begin(&e->b, lines);
            for (int k = 0; k < e->n_bands && st == SS_OK; ++k) {
                int band = p == 0 ? k : e->n_bands - 1 - k;
                int row0 = band * e->band_rows;
                int row1 = row0 + e->band_rows < e->src->height ? row0 + e->band_rows
                                                                 : e->src->height;
                st = visit_band(e, row0, row1, pass, first, last, first_visit,
                                is_last_pass(n_groups, passes, g, p));
            }
            first_visit = 0;
        }
    }
    return st;
}

/* The job's directions: their whole-grid lines and passes. */
static ss_status make_directions(engine_run *e)
{
    const ss_engine_job *job = e->job;
    ss_grid dims = {e->src->width, e->src->height, e->src->cell_x_m, e->src->cell_y_m, 0.0, NULL};
    for (int i = 0; i < job->n_dirs; ++i) {
        if (!isfinite(job->dirs[i].azimuth_deg))
            return ss_fail(e->ctx, SS_ERR_ARGUMENT, "azimuth %d is not a number", i);
        ss_band_dir *d = &e->dirs[i];
        double az = ss_product_lines_at(&dims, e->opt, job->dirs[i].azimuth_deg, &d->ls);
        d->sin_az = (float)sin(az);
        d->cos_az = (float)cos(az);
        d->pass = ss_band_pass_of(&d->ls);
        d->lit_level = job->walk.lit_levels || e->lit_levels ? job->dirs[i].lit_level : -1;
        d->lit_sector = ss_lit_sector(job->dirs[i].azimuth_deg - e->opt->grid_north_deg);
    }
    return SS_OK;
}

/* The directions walked in the largest pass of a group: the batch asked of
 * the backend unless the context sets one. */
static int batch_wanted(const engine_run *e)
{
    if (e->ctx->batch > 0)
        return e->ctx->batch;
    if (e->ctx->use_reference)
        return 1; /* the C twin walks a batch one direction after the other */
    int walked = 0;
    for (int i = 0; i < e->job->n_dirs; ++i)
        walked += e->job->dirs[i].walk != 0;
    int group = e->banded && e->job->group > 0 ? e->job->group : walked;
    int n = walked < group ? walked : group;
    return n > 0 ? n : 1;
}

/* What box lines need: stack slots indexed by int (SS_BOX_EVENTS per held
 * cell), and cells of a shape they take (ss_box_lines_take_cells). */
static ss_status box_lines_check(const engine_run *e)
{
    const ss_source *src = e->src;
    double rows = e->n_bands > 1 ? e->band_rows + 2.0 * e->halo : src->height;
    if ((double)SS_BOX_EVENTS * rows * src->width >= 2147483647.0)
        return ss_fail(e->ctx, SS_ERR_MEMORY,
                       "box lines hold %d hull slots per cell, too many for %.0f cells at once: "
                       "give --memory a smaller budget, so that the DEM is swept in bands",
                       SS_BOX_EVENTS, rows * src->width);
    if (!ss_box_lines_take_cells(src->cell_x_m, src->cell_y_m))
        return ss_fail(e->ctx, SS_ERR_ARGUMENT,
                       "box lines need cells at most twice as long as wide, not %.4g x %.4g m",
                       src->cell_x_m, src->cell_y_m);
    return SS_OK;
}

static ss_status open_run(engine_run *e)
{
    const ss_source *src = e->src;
    const ss_engine_job *job = e->job;
    int h = src->height, w = src->width;
    e->band_rows = ss_source_band_rows(src);
    e->n_bands = (h + e->band_rows - 1) / e->band_rows;
    e->banded = e->n_bands > 1;
    e->halo = SS_BAND_HALO;
    if (e->opt->lines == SS_LINES_BOX) {
        ss_status st = box_lines_check(e);
        if (st != SS_OK)
            return st;
    }
    if (job->walk.radius_m > 0 && e->opt->lines == SS_LINES_BOX)
        return ss_fail(e->ctx, SS_ERR_ARGUMENT,
                       "radius-limited horizons take interpolated or digital lines, not box lines");
    if (job->walk.radius_m > 0) { /* a radius walk looks back this far: no hulls */
        double rows = ceil(job->walk.radius_m / src->cell_y_m);
        e->halo += rows < h ? (int)rows : h; /* a halo past the grid's height holds no more */
    }
    int max_held = e->banded ? (e->band_rows + 2 * e->halo < h ? e->band_rows + 2 * e->halo : h)
                             : h;
    size_t held = (size_t)max_held * (size_t)w;
    int whole_in_place = !e->banded && src->z && !job->walk.negate;
    /* Bounds made band by band: read once for one band, else per band. */
    if (job->walk.lit_bands &&
        !(e->lit_levels = ss_malloc(ss_lit_bands_bytes(job->walk.lit_bands, max_held))))
        return ss_fail(e->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB for a band's bounds",
                       ss_lit_bands_bytes(job->walk.lit_bands, max_held) >> 20);
    e->dirs = ss_calloc((size_t)(job->n_dirs > 0 ? job->n_dirs : 1), sizeof *e->dirs);
    e->order = ss_malloc(sizeof(int) * (size_t)(job->n_dirs > 0 ? job->n_dirs : 1));
    if (!e->dirs || !e->order)
        return ss_fail(e->ctx, SS_ERR_MEMORY, "out of memory for %d directions", job->n_dirs);
    ss_status st = make_directions(e);
    if (st != SS_OK)
        return st;
    if (!whole_in_place && !(e->z = ss_alloc_grid(held * sizeof(float))))
        return ss_fail(e->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB for a band of heights",
                       (held * sizeof(float)) >> 20);
    if (job->walk.term == SS_SVF_TILTED && !(e->grad = ss_alloc_grid(2 * held * sizeof(float))))
        return ss_fail(e->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB of surface gradients",
                       (2 * held * sizeof(float)) >> 20);
    int planes = job->consumer->planes;
    size_t own = (size_t)e->band_rows * (size_t)w * (size_t)planes;
    if (!is_sums(e) && planes > 0 && !(e->planes = ss_calloc(own, sizeof(float))))
        return ss_fail(e->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB for a band's sums",
                       (own * sizeof(float)) >> 20);
    if (e->banded && planes > 0) {
        if (!(e->loaded = ss_malloc(own * sizeof(float))))
            return ss_fail(e->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB for a band's sums",
                           (own * sizeof(float)) >> 20);
        if ((st = ss_scratch_open(e->ctx, &e->partial)) != SS_OK)
            return st;
    }
    /* The whole grid is read (or negated) once, and its gradients made once. */
    if (!e->banded && !whole_in_place) {
        st = read_band(e, 0, h);
        if (st != SS_OK)
            return st;
    } else if (!e->banded && e->grad) {
        ss_grid whole = {w, h, src->cell_x_m, src->cell_y_m, 0.0, (float *)src->z};
        ss_gradient_grid(&whole, e->grad);
    }
    e->b.ctx = e->ctx;
    e->b.walk = job->walk;
    if (e->lit_levels && !e->banded) {
        st = ss_lit_bands_read(job->walk.lit_bands, 0, h, e->lit_levels);
        e->b.walk.lit_levels = e->lit_levels;
        if (st != SS_OK)
            return st;
    }
    e->b.width = w;
    e->b.max_held_rows = max_held;
    int radius_hulls = job->walk.radius_m > 0 &&
                       ss_radius_takes_hulls((float)job->walk.radius_m, (float)src->cell_x_m,
                                             (float)src->cell_y_m);
    e->b.stack_per_cell = e->opt->lines == SS_LINES_BOX ? SS_BOX_EVENTS
                          : radius_hulls               ? SS_RADIUS_SLOTS
                                                       : 1;
    e->b.batch = batch_wanted(e);
    int group = job->group > 0 && job->group < job->n_dirs ? job->group : job->n_dirs;
    e->b.carried = !e->banded ? 0 : is_sums(e) ? 1 : (group > 0 ? group : 1);
    e->b.whole_z = e->banded ? NULL : whole_in_place ? src->z : e->z;
    if (!walks(e))
        return SS_OK;
    st = ss_backend_open(&e->b);
    if (st == SS_OK && (!(e->batch = ss_calloc((size_t)e->b.batch, sizeof *e->batch)) ||
                        !(e->batch_index = ss_calloc((size_t)e->b.batch, sizeof(int)))))
        st = ss_fail(e->ctx, SS_ERR_MEMORY, "out of memory for a batch");
    /* A batch the context sets is kept; the device's choice starts small. */
    e->batch_now = e->ctx->batch > 0 || e->b.batch < 8 ? e->b.batch : 8;
    return st;
}

static void close_run(engine_run *e)
{
    if (e->b.impl)
        e->b.ops->close(&e->b);
    free(e->z);
    free(e->grad);
    free(e->lit_levels);
    free(e->planes);
    free(e->loaded);
    ss_scratch_close(&e->partial);
    free(e->dirs);
    free(e->order);
    free(e->batch);
    free(e->batch_index);
}

ss_status ss_engine_run(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                        const ss_engine_job *job)
{
    engine_run e = {0};
    e.ctx = ctx;
    e.src = src;
    e.opt = opt;
    e.job = job;
    ss_status st = open_run(&e);
    if (st == SS_OK)
        st = run_groups(&e);
    if (st == SS_OK && !src->z && !e.any_height)
        st = ss_fail(ctx, SS_ERR_INPUT, "the DEM holds no valid height: every cell is nodata");
    int walked = 0;
    for (int i = 0; i < job->n_dirs; ++i)
        walked += job->dirs[i].walk != 0;
    ctx->counters.sweeps += (uint64_t)walked;
    ctx->counters.cells_swept += (uint64_t)walked * (uint64_t)src->width * (uint64_t)src->height;
    if (src->stats) { /* a product may run the engine more than once */
        src->stats->handoffs += e.stats.handoffs;
        src->stats->hull_points_handed_on += e.stats.hull_points_handed_on;
        if (e.stats.max_hull_points > src->stats->max_hull_points)
            src->stats->max_hull_points = e.stats.max_hull_points;
    }
    close_run(&e);
    return st;
}
