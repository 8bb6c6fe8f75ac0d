/* The OpenCL backend: runs one work-item per line and direction of a
 * batch. A whole grid held by the caller is used with CL_MEM_USE_HOST_PTR,
 * which PoCL serves without copies. The device it runs on is found, opened
 * and built for in ocl_devices.c; insolation's cells run in ocl_cells.c. */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lit_levels.h"
#include "ocl_internal.h"
#include "ss_passes.h"

/* ---- band walks ----------------------------------------------------------- */

static size_t run_cells(const ss_band_run *run)
{
    return (size_t)run->held_rows * (size_t)run->width;
}

static size_t held_cells(const ss_backend *b)
{
    return (size_t)b->max_held_rows * (size_t)b->width;
}

/* Sets k's arguments and runs it over `items` work-items. */
ss_status ocl_run_kernel(ss_backend *b, cl_kernel k, const kernel_arg *args, int n_args,
                            size_t items, const char *what)
{
    struct ss_ocl *o = b->ctx->ocl;
    for (int i = 0; i < n_args; ++i) {
        cl_int err = clSetKernelArg(k, (cl_uint)i, args[i].size, args[i].value);
        if (err != CL_SUCCESS)
            return ocl_fail(b->ctx, err, what);
    }
    if (items == 0)
        return SS_OK;
    size_t local = o->work_group, global = (items + local - 1) / local * local;
    cl_int err = clEnqueueNDRangeKernel(o->queue, k, 1, NULL, &global, &local, 0, NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : ocl_fail(b->ctx, err, what);
}

ss_status ocl_fill(ss_backend *b, cl_mem buf, size_t bytes)
{
    if (bytes == 0)
        return SS_OK;
    float zero = 0.0f;
    cl_int err = clEnqueueFillBuffer(b->ctx->ocl->queue, buf, &zero, sizeof zero, 0, bytes, 0,
                                     NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : ocl_fail(b->ctx, err, "clEnqueueFillBuffer");
}

ss_status ocl_unmap(ss_backend *b)
{
    ocl_backend *q = b->impl;
    if (!q->mapped)
        return SS_OK;
    cl_int err = clEnqueueUnmapMemObject(b->ctx->ocl->queue, q->mapped, q->mapped_ptr, 0, NULL,
                                         NULL);
    q->mapped = NULL;
    return err == CL_SUCCESS ? SS_OK : ocl_fail(b->ctx, err, "clEnqueueUnmapMemObject");
}

/* Maps bytes of buf for the host (waiting for what is queued before). */
static ss_status map(ss_backend *b, cl_mem buf, size_t bytes, float **host)
{
    ocl_backend *q = b->impl;
    if (q->mapped != buf) {
        ss_status st = ocl_unmap(b);
        if (st != SS_OK)
            return st;
        cl_int err;
        q->mapped_ptr = clEnqueueMapBuffer(b->ctx->ocl->queue, buf, CL_TRUE,
                                           CL_MAP_READ | CL_MAP_WRITE, 0, bytes, 0, NULL, NULL,
                                           &err);
        if (err != CL_SUCCESS)
            return ocl_fail(b->ctx, err, "clEnqueueMapBuffer");
        q->mapped = buf;
    }
    *host = q->mapped_ptr;
    return SS_OK;
}

cl_mem ocl_new_buffer(ss_backend *b, cl_mem_flags flags, size_t bytes, void *host,
                         cl_int *err)
{
    if (*err != CL_SUCCESS)
        return NULL;
    return clCreateBuffer(b->ctx->ocl->context, flags, bytes ? bytes : 4, host, err);
}

ss_status ocl_upload(ss_backend *b, cl_mem buf, size_t bytes, const void *host)
{
    cl_int err = clEnqueueWriteBuffer(b->ctx->ocl->queue, buf, CL_TRUE, 0, bytes, host, 0, NULL,
                                      NULL);
    return err == CL_SUCCESS ? SS_OK : ocl_fail(b->ctx, err, "clEnqueueWriteBuffer");
}

/* Queues a batch's directions without waiting for them to be copied. */
static ss_status upload_dirs(ss_backend *b, const ss_band_dir *dirs, int n)
{
    ocl_backend *q = b->impl;
    ss_band_dir *staged = q->staged[q->stage];
    q->stage ^= 1;
    memcpy(staged, dirs, sizeof *dirs * (size_t)n);
    cl_int err = clEnqueueWriteBuffer(b->ctx->ocl->queue, q->dirs, CL_FALSE, 0,
                                      sizeof *dirs * (size_t)n, staged, 0, NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : ocl_fail(b->ctx, err, "clEnqueueWriteBuffer");
}

static ss_status ocl_load(ss_backend *b, const ss_band_run *run, const float *z, const float *grad)
{
    ocl_backend *q = b->impl;
    ss_status st = ocl_unmap(b);
    if (st != SS_OK)
        return st;
    if (b->whole_z) {
        /* The whole grid is loaded once; its gradients come with it. */
        cl_int err = CL_SUCCESS;
        if (grad && !q->grad)
            q->grad = ocl_new_buffer(b, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                 2 * run_cells(run) * sizeof(float), (void *)grad, &err);
        return err == CL_SUCCESS ? SS_OK : ocl_fail(b->ctx, err, "copying the gradients");
    }
    st = ocl_upload(b, q->z, run_cells(run) * sizeof(float), z);
    if (st == SS_OK && grad)
        st = ocl_upload(b, q->grad, 2 * run_cells(run) * sizeof(float), grad);
    if (st == SS_OK && q->lit_levels_loaded && b->walk.lit_levels)
        st = ocl_upload(b, q->lit_levels, ss_lit_bands_bytes(b->walk.lit_bands, run->held_rows),
                        b->walk.lit_levels);
    return st;
}

/* The carried rows' buffer: never empty, so that it can be filled. */
static size_t carry_floats(const ss_backend *b)
{
    size_t n = ss_backend_carry_floats(b);
    return n ? n : (size_t)b->width;
}

static ss_status ocl_pass_begin(ss_backend *b, int n_lines)
{
    ocl_backend *q = b->impl;
    ss_status st = ocl_unmap(b);
    if (st != SS_OK)
        return st;
    if (n_lines > q->lines_cap) {
        cl_mem *arrays[] = {&q->in_off, &q->in_cnt, &q->out_off, &q->out_cnt, &q->state};
        cl_int err = CL_SUCCESS;
        for (int i = 0; i < 5; ++i) {
            clReleaseMemObject(*arrays[i]);
            size_t ints = (size_t)n_lines * (i == 4 ? SS_BAND_STATE : 1);
            *arrays[i] = ocl_new_buffer(b, CL_MEM_READ_WRITE, ints * sizeof(int), NULL, &err);
        }
        if (err != CL_SUCCESS) {
            for (int i = 0; i < 5; ++i) {
                if (*arrays[i])
                    clReleaseMemObject(*arrays[i]);
                *arrays[i] = NULL;
            }
            q->lines_cap = 0;
            return ocl_fail(b->ctx, err, "allocating the per-line hull arrays");
        }
        q->lines_cap = n_lines;
    }
    st = ocl_fill(b, q->in_cnt, (size_t)n_lines * sizeof(int));
    if (st == SS_OK)
        st = ocl_fill(b, q->in_off, (size_t)n_lines * sizeof(int));
    if (st == SS_OK)
        st = ocl_fill(b, q->counters, SS_BAND_COUNTERS * sizeof(int));
    if (st == SS_OK)
        st = ocl_fill(b, q->carry, carry_floats(b) * sizeof(float));
    return st;
}

/* Rows of sums carried between bands: in to the landing rows, or out of
 * the fed rows, for n slots of `planes` planes of outs: each direction's
 * own (per_direction, the batch's directions) or the sums' one. */
static ss_status carry(ss_backend *b, const ss_band_run *run, int pass, int n, int planes,
                       int into, int per_direction, cl_mem outs)
{
    ocl_backend *q = b->impl;
    if (!b->carried)
        return SS_OK;
    kernel_arg args[] = {ARG(*run),         ARG(pass),    ARG(n),    ARG(planes), ARG(into),
                         ARG(per_direction), ARG(q->dirs), ARG(outs), ARG(q->carry)};
    return ocl_run_kernel(b, b->ctx->ocl->k_carry, args, 9, (size_t)n * planes * run->width,
                      "the carrying kernel");
}

static ss_status ocl_sums_begin(ss_backend *b, const ss_band_run *run, int pass)
{
    ocl_backend *q = b->impl;
    ss_status st = ocl_unmap(b);
    if (st == SS_OK)
        st = ocl_fill(b, q->sums, run_cells(run) * sizeof(float));
    return st == SS_OK ? carry(b, run, pass, 1, 1, 1, 0, q->sums) : st;
}

/* Makes room in hull_out for every point the walks so far will hand on,
 * keeping those already there. */
static ss_status hull_room(ss_backend *b)
{
    ocl_backend *q = b->impl;
    struct ss_ocl *o = b->ctx->ocl;
    int counters[SS_BAND_COUNTERS];
    cl_int err = clEnqueueReadBuffer(o->queue, q->counters, CL_TRUE, 0, sizeof counters, counters,
                                     0, NULL, NULL);
    if (err != CL_SUCCESS)
        return ocl_fail(b->ctx, err, "reading the hull counters");
    size_t need = (size_t)counters[SS_BAND_PENDING], used = (size_t)counters[SS_BAND_USED];
    if (need <= q->hull_cap_out)
        return SS_OK;
    size_t cap = need + need / 2 + 1024;
    cl_mem grown = ocl_new_buffer(b, CL_MEM_READ_WRITE, cap * sizeof(ss_hull_point), NULL, &err);
    if (err == CL_SUCCESS && used > 0)
        err = clEnqueueCopyBuffer(o->queue, q->hull_out, grown, 0, 0, used * sizeof(ss_hull_point),
                                  0, NULL, NULL);
    if (err != CL_SUCCESS) {
        if (grown)
            clReleaseMemObject(grown);
        return ocl_fail(b->ctx, err, "growing the hulls handed on");
    }
    clReleaseMemObject(q->hull_out);
    q->hull_out = grown;
    q->hull_cap_out = cap;
    return SS_OK;
}

/* Ends a batch: waits for the batch before it, so that at most one batch is
 * queued behind the running one. The device never idles (the next batch is
 * queued before the wait), and a cancelled run waits for two batches, not
 * for every one it had queued (an NDRange cannot be stopped once queued). */
static ss_status pace(ss_backend *b)
{
    ocl_backend *q = b->impl;
    cl_command_queue queue = b->ctx->ocl->queue;
    cl_event mark;
    cl_int err = clEnqueueMarkerWithWaitList(queue, 0, NULL, &mark);
    if (err == CL_SUCCESS)
        err = clFlush(queue);
    if (err != CL_SUCCESS)
        return ocl_fail(b->ctx, err, "queueing a batch");
    if (q->queued) {
        err = clWaitForEvents(1, &q->queued);
        clReleaseEvent(q->queued);
    }
    q->queued = mark;
    if (err != CL_SUCCESS)
        return ocl_fail(b->ctx, err, "waiting for a batch");
    return ss_check_cancel(b->ctx, "the sweep");
}

/* One round of the batch's lines, and their hulls handed on. */
static ss_status walk_round(ss_backend *b, ss_band_run run, int n, int round, cl_mem sums)
{
    ocl_backend *q = b->impl;
    struct ss_ocl *o = b->ctx->ocl;
    const ss_walk *walk = &b->walk;
    ss_status st = SS_OK;
    size_t items = (size_t)n * (size_t)run.lines;
    if (walk->term == SS_TERM_HORIZON) {
        kernel_arg args[] = {ARG(q->dirs),   ARG(run),          ARG(round),    ARG(q->z),
                             ARG(q->stacks), ARG(q->outs),      ARG(q->hull_in), ARG(q->in_off),
                             ARG(q->in_cnt), ARG(q->state),     ARG(q->counters),
                             ARG(q->lit_levels)};
        st = ocl_run_kernel(b, o->k_horizon, args, 12, items, "the horizon kernel");
    } else if (walk->radius_m > 0) {
        kernel_arg args[] = {ARG(q->dirs),   ARG(run), ARG(round),
                             ARG(q->z),      ARG(q->stacks), ARG(sums)};
        return ocl_run_kernel(b, o->k_radius, args, 6, items, "the radius-limited horizon kernel");
    } else {
        cl_mem grad = q->grad ? q->grad : q->z; /* read by the radiative term only */
        kernel_arg args[] = {ARG(q->dirs),   ARG(run),      ARG(round),      ARG(q->z),
                             ARG(grad),      ARG(q->stacks), ARG(sums),      ARG(q->hull_in),
                             ARG(q->in_off), ARG(q->in_cnt), ARG(q->state),  ARG(q->counters)};
        st = ocl_run_kernel(b, o->k_sum, args, 12, items, "the SVF kernel");
    }
    if (st != SS_OK || run.whole)
        return st;
    st = hull_room(b);
    kernel_arg args[] = {ARG(q->dirs),    ARG(run),      ARG(round),       ARG(q->z),
                         ARG(q->stacks),  ARG(q->hull_in), ARG(q->in_off), ARG(q->state),
                         ARG(q->hull_out), ARG(q->out_off), ARG(q->out_cnt), ARG(q->counters)};
    return st == SS_OK ? ocl_run_kernel(b, o->k_hand_on, args, 12, items, "the hand-on kernel") : st;
}

static ss_status ocl_walk(ss_backend *b, const ss_band_run *run, const ss_band_dir *dirs, int n)
{
    ocl_backend *q = b->impl;
    struct ss_ocl *o = b->ctx->ocl;
    int horizon = b->walk.term == SS_TERM_HORIZON;
    ss_status st = ocl_unmap(b);
    if (st == SS_OK)
        st = upload_dirs(b, dirs, n);
    /* A batch of one adds into the band's sums, as the C twin does; in a
     * larger batch each direction adds into a slot of its own, which
     * band_reduce then adds in direction order, so that the sums do not
     * depend on how directions were batched beyond the float rounding of
     * adding a direction's two rounds first (1e-7 relative). */
    int slotted = !horizon && n > 1;
    cl_mem sums = slotted ? q->parts : q->sums;
    if (st == SS_OK && horizon)
        st = ocl_fill(b, q->outs, (size_t)n * run->planes * run_cells(run) * sizeof(float));
    if (st == SS_OK && horizon)
        st = carry(b, run, dirs[0].pass, n, run->planes, 1, 1, q->outs);
    if (st == SS_OK && slotted)
        st = ocl_fill(b, q->parts, (size_t)n * run_cells(run) * sizeof(float));
    for (int round = 0; round < ss_line_rounds(&dirs[0].ls) && st == SS_OK; ++round) {
        ss_band_run r = *run;
        r.lines = 0;
        r.slots = n;
        for (int k = 0; k < n; ++k) {
            int lines = ss_round_lines(&dirs[k].ls, round);
            r.lines = lines > r.lines ? lines : r.lines;
        }
        if (r.lines > 0)
            st = walk_round(b, r, n, round, sums);
    }
    if (st == SS_OK && slotted) {
        kernel_arg args[] = {ARG(*run), ARG(n), ARG(q->parts), ARG(q->sums)};
        st = ocl_run_kernel(b, o->k_reduce, args, 4, run_cells(run), "the reducing kernel");
    }
    if (st == SS_OK && horizon)
        st = carry(b, run, dirs[0].pass, n, run->planes, 0, 1, q->outs);
    if (st == SS_OK && horizon) {
        kernel_arg args[] = {ARG(*run), ARG(n), ARG(q->outs)};
        st = ocl_run_kernel(b, o->k_finish, args, 3,
                        (size_t)n * (size_t)(run->row1 - run->row0) * run->width,
                        "the finishing kernel");
    }
    return st == SS_OK ? pace(b) : st;
}

static ss_status ocl_sums_end(ss_backend *b, const ss_band_run *run, int pass, float **own)
{
    ocl_backend *q = b->impl;
    ss_status st = carry(b, run, pass, 1, 1, 0, 0, q->sums);
    float *host = NULL;
    if (st == SS_OK)
        st = map(b, q->sums, run_cells(run) * sizeof(float), &host);
    if (st == SS_OK)
        *own = host + (size_t)(run->row0 - run->lo) * run->width;
    return st;
}

static ss_status ocl_view(ss_backend *b, const ss_band_run *run, int slot, int plane, float **own)
{
    ocl_backend *q = b->impl;
    float *host = NULL;
    ss_status st = map(b, q->outs, (size_t)b->batch * run->planes * run_cells(run) * sizeof(float),
                       &host);
    if (st == SS_OK)
        *own = ss_band_plane(host, run, slot, plane) + (size_t)(run->row0 - run->lo) * run->width;
    return st;
}

static ss_status ocl_hulls_swap(ss_backend *b, ss_band_stats *stats)
{
    ocl_backend *q = b->impl;
    int counters[SS_BAND_COUNTERS];
    ss_status st = ocl_unmap(b);
    cl_int err = st == SS_OK ? clEnqueueReadBuffer(b->ctx->ocl->queue, q->counters, CL_TRUE, 0,
                                                   sizeof counters, counters, 0, NULL, NULL)
                             : CL_SUCCESS;
    if (st != SS_OK)
        return st;
    if (err != CL_SUCCESS)
        return ocl_fail(b->ctx, err, "reading the hull counters");
    if (stats) {
        stats->handoffs += (size_t)counters[SS_BAND_HANDOFFS];
        stats->hull_points_handed_on += (size_t)counters[SS_BAND_USED];
        if ((size_t)counters[SS_BAND_HULL_MAX] > stats->max_hull_points)
            stats->max_hull_points = (size_t)counters[SS_BAND_HULL_MAX];
    }
    cl_mem t = q->hull_in;
    q->hull_in = q->hull_out;
    q->hull_out = t;
    size_t cap = q->hull_cap_in;
    q->hull_cap_in = q->hull_cap_out;
    q->hull_cap_out = cap;
    t = q->in_off;
    q->in_off = q->out_off;
    q->out_off = t;
    t = q->in_cnt;
    q->in_cnt = q->out_cnt;
    q->out_cnt = t;
    return ocl_fill(b, q->counters, sizeof counters);
}

static ss_status ocl_bare(ss_backend *b, const ss_band_run *run, const ss_band_dir *dir,
                          float **out)
{
    ocl_backend *q = b->impl;
    struct ss_ocl *o = b->ctx->ocl;
    ss_status st = ocl_unmap(b);
    if (st == SS_OK)
        st = ocl_fill(b, q->sums, run_cells(run) * sizeof(float));
    if (st == SS_OK)
        st = upload_dirs(b, dir, 1);
    for (int round = 0; round < ss_line_rounds(&dir->ls) && st == SS_OK; ++round) {
        ss_band_run r = *run;
        r.lines = ss_round_lines(&dir->ls, round);
        r.slots = 1;
        kernel_arg args[] = {ARG(q->dirs), ARG(r), ARG(round), ARG(q->z), ARG(q->sums)};
        st = ocl_run_kernel(b, o->k_bare, args, 5, (size_t)r.lines, "the bare-pass kernel");
    }
    if (st == SS_OK)
        st = map(b, q->sums, run_cells(run) * sizeof(float), out);
    return st;
}
static void ocl_close(ss_backend *b)
{
    ocl_backend *q = b->impl;
    if (!q)
        return;
    if (b->ctx->ocl) {
        ocl_unmap(b);
        clFinish(b->ctx->ocl->queue);
    }
    if (q->queued)
        clReleaseEvent(q->queued);
    cl_mem all[] = {q->z,       q->grad,    q->stacks,  q->sums,    q->parts,
                    q->outs,    q->carry,   q->dirs,    q->hull_in, q->hull_out,
                    q->in_off,  q->in_cnt,  q->out_off, q->out_cnt, q->state,
                    q->counters, q->lit_levels, q->cell_terms, q->cell_planes,
                    q->cell_stored, q->cell_step, q->lattice_at, q->lattice_nodes};
    for (size_t i = 0; i < sizeof all / sizeof all[0]; ++i)
        if (all[i])
            clReleaseMemObject(all[i]);
    free(q->staged[0]);
    free(q->staged[1]);
    for (int k = 0; q->lattice_stage && k < q->lattice_stages; ++k) {
        if (q->lattice_stage[k].written)
            clReleaseEvent(q->lattice_stage[k].written);
        free(q->lattice_stage[k].bytes);
    }
    free(q->lattice_stage);
    free(q->planes_back);
    free(q);
    b->impl = NULL;
}

static const ss_backend_ops ocl_ops = {.load = ocl_load,
                                       .pass_begin = ocl_pass_begin,
                                       .sums_begin = ocl_sums_begin,
                                       .walk = ocl_walk,
                                       .sums_end = ocl_sums_end,
                                       .view = ocl_view,
                                       .hulls_swap = ocl_hulls_swap,
                                       .bare = ocl_bare,
                                       .close = ocl_close,
                                       .cells_begin = ocl_cells_begin,
                                       .cells_step = ocl_cells_step,
                                       .cells_end = ocl_cells_end};

/* The directions a batch can hold: what was asked, within what the memory
 * plan gives the batch's buffers (memory_plan.c: within a GPU's own memory,
 * or the host's for a CPU device) and the device's largest buffer. A CPU
 * device walks one direction of a whole grid at a time unless the context
 * asks for more: a launch costs it about 0.1 ms against milliseconds of
 * work, while a batch's own sums and stack grids cost memory traffic; in
 * bands, where each round of a batch waits for its hulls' count, it takes
 * up to 4 (doc/engine.md:
 * on 2 cores, SVF of 1024^2 x 64 directions in bands of 256 rows, 0.80 s
 * with 4 against 0.90 s with 16 and 0.91 s one at a time). */
static int fit_batch(const ss_backend *b, const struct ss_ocl *o)
{
    if (o->is_cpu && b->ctx->batch == 0 && b->whole_z)
        return 1;
    if (o->is_cpu && b->ctx->batch == 0 && b->batch > 4)
        return 4;
    size_t cells = held_cells(b);
    int horizon = b->walk.term == SS_TERM_HORIZON;
    double per_slot = (double)cells * (4.0 * b->stack_per_cell +
                                       (horizon ? 4.0 * ss_walk_planes(&b->walk) : 4.0));
    int planes = horizon ? ss_walk_planes(&b->walk) : 1;
    double largest = (double)cells * 4.0 * (planes > b->stack_per_cell ? planes : b->stack_per_cell);
    double budget = ss_memory_device_bytes(b->ctx, (double)o->global_mem);
    double alloc = (double)o->max_alloc;
    int by_memory = per_slot > 0 ? (int)fmin(budget / per_slot, alloc / largest) : b->batch;
    int n = b->batch < by_memory ? b->batch : by_memory;
    return n > 0 ? n : 1;
}

ss_status ss_backend_ocl_open(ss_backend *b)
{
    ss_status st = ss_ocl_acquire(b->ctx);
    if (st != SS_OK)
        return st;
    if (b->ctx->use_reference) { /* the default device could not work here */
        /* The batch was sized for OpenCL; the C twin walks one at a time
         * (engine.c, batch_wanted) and would hold a batch's planes for nothing. */
        b->batch = b->ctx->batch > 0 ? b->ctx->batch : 1;
        return ss_backend_ref_open(b);
    }
    struct ss_ocl *o = b->ctx->ocl;
    ocl_backend *q = ss_calloc(1, sizeof *q);
    if (!q)
        return ss_fail(b->ctx, SS_ERR_MEMORY, "out of memory opening a backend");
    b->impl = q;
    b->ops = &ocl_ops;
    b->batch = fit_batch(b, o);
    b->device_cells = b->ctx->cells == SS_CELLS_DEVICE ||
                      (b->ctx->cells == SS_CELLS_AUTO && !o->is_cpu);
    size_t cells = held_cells(b), fbytes = cells * sizeof(float);
    int horizon = b->walk.term == SS_TERM_HORIZON, planes = ss_walk_planes(&b->walk);
    cl_int err = CL_SUCCESS;
    if (b->whole_z)
        q->z = ocl_new_buffer(b, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, fbytes, (void *)b->whole_z,
                          &err);
    else
        q->z = ocl_new_buffer(b, CL_MEM_READ_ONLY, fbytes, NULL, &err);
    if (!b->whole_z && b->walk.term == SS_SVF_TILTED)
        q->grad = ocl_new_buffer(b, CL_MEM_READ_ONLY, 2 * fbytes, NULL, &err);
    q->stacks = ocl_new_buffer(b, CL_MEM_READ_WRITE,
                           (size_t)b->batch * cells * b->stack_per_cell * sizeof(int), NULL, &err);
    q->sums = ocl_new_buffer(b, CL_MEM_READ_WRITE, fbytes, NULL, &err);
    if (horizon)
        q->outs = ocl_new_buffer(b, CL_MEM_READ_WRITE, (size_t)b->batch * planes * fbytes, NULL, &err);
    else if (b->batch > 1)
        q->parts = ocl_new_buffer(b, CL_MEM_READ_WRITE, (size_t)b->batch * fbytes, NULL, &err);
    q->carry = ocl_new_buffer(b, CL_MEM_READ_WRITE, carry_floats(b) * sizeof(float), NULL, &err);
    q->dirs = ocl_new_buffer(b, CL_MEM_READ_ONLY, (size_t)b->batch * sizeof(ss_band_dir), NULL, &err);
    q->counters = ocl_new_buffer(b, CL_MEM_READ_WRITE, SS_BAND_COUNTERS * sizeof(int), NULL, &err);
    for (int k = 0; k < 2 && err == CL_SUCCESS; ++k)
        if (!(q->staged[k] = ss_malloc(sizeof(ss_band_dir) * (size_t)b->batch)))
            err = CL_OUT_OF_HOST_MEMORY;
    q->lattice_stages = b->batch + 2;
    if (err == CL_SUCCESS &&
        !(q->lattice_stage = ss_calloc((size_t)q->lattice_stages, sizeof(lattice_entry))))
        err = CL_OUT_OF_HOST_MEMORY;
    /* The cells' terms, sums, stored horizons and step take their own
     * buffers, together within the device's largest and what the memory
     * plan gives the device (engine.c, cells_fit). */
    b->cells_max_bytes = (size_t)fmin((double)o->max_alloc,
                                      ss_memory_device_cells_bytes(b->ctx, (double)o->global_mem));
    /* Shadow walks stop early by the cells' bounds: the whole grid's, or a
     * band's at a time with its heights (ocl_load); else no direction reads
     * them (engine.c sets lit_level -1). */
    q->lit_levels_loaded = horizon && b->walk.lit_bands && !b->whole_z;
    if (horizon && b->walk.lit_levels && b->whole_z)
        q->lit_levels = ocl_new_buffer(b, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR,
                                       cells * SS_LIT_SECTORS, (void *)b->walk.lit_levels, &err);
    else if (q->lit_levels_loaded)
        q->lit_levels = ocl_new_buffer(b, CL_MEM_READ_ONLY,
                                       ss_lit_bands_bytes(b->walk.lit_bands, b->max_held_rows),
                                       NULL, &err);
    else
        q->lit_levels = ocl_new_buffer(b, CL_MEM_READ_ONLY, 1, NULL, &err);
    /* Valid (if empty) hull buffers, so every kernel argument is a buffer. */
    q->hull_in = ocl_new_buffer(b, CL_MEM_READ_WRITE, sizeof(ss_hull_point), NULL, &err);
    q->hull_out = ocl_new_buffer(b, CL_MEM_READ_WRITE, sizeof(ss_hull_point), NULL, &err);
    q->hull_cap_in = q->hull_cap_out = 1;
    cl_mem *lines[] = {&q->in_off, &q->in_cnt, &q->out_off, &q->out_cnt, &q->state};
    for (int i = 0; i < 5; ++i)
        *lines[i] = ocl_new_buffer(b, CL_MEM_READ_WRITE, SS_BAND_STATE * sizeof(int), NULL, &err);
    q->lines_cap = 1;
    if (err != CL_SUCCESS) {
        ocl_close(b);
        return ocl_fail(b->ctx, err, "allocating device buffers");
    }
    return SS_OK;
}
