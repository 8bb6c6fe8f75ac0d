/* Insolation's steps on an OpenCL device (ss_backend_ops.cells_*): the
 * band's own cells' terms, sums and stored horizons in device buffers, each
 * step's sun lattice staged for the device, and the sums read back into
 * the host's. */
#include "config.h"

#include <stdlib.h>
#include <string.h>

#include "ocl_internal.h"

/* A device buffer of at least `bytes` (at least 16), grown as needed;
 * what it held is not kept. */
static ss_status room(ss_backend *b, cl_mem *buf, size_t *cap, size_t bytes, const char *what)
{
    if (bytes < 16)
        bytes = 16;
    if (*buf && *cap >= bytes)
        return SS_OK;
    if (*buf)
        clReleaseMemObject(*buf);
    cl_int err = CL_SUCCESS;
    *buf = ocl_new_buffer(b, CL_MEM_READ_WRITE, bytes, NULL, &err);
    *cap = err == CL_SUCCESS ? bytes : 0;
    return err == CL_SUCCESS ? SS_OK : ocl_fail(b->ctx, err, what);
}

static size_t own_cells(const ss_band_run *run)
{
    return (size_t)(run->row1 - run->row0) * (size_t)run->width;
}

/* Interpolated shadows' stored horizons, `planes` planes of n own cells
 * that lie `stride` cells apart on the host, into the device's: in one
 * copy where they lie together, else plane by plane. */
static ss_status upload_stored(ss_backend *b, const int16_t *stored, int planes, size_t n,
                               size_t stride)
{
    ocl_backend *q = b->impl;
    int together = stride == n;
    int copies = together && planes > 0 ? 1 : planes;
    size_t bytes = n * sizeof(int16_t) * (size_t)(together ? planes : 1);
    for (int d = 0; d < copies; ++d) {
        cl_int err = clEnqueueWriteBuffer(b->ctx->ocl->queue, q->cell_stored, CL_TRUE,
                                          (size_t)d * bytes, bytes, stored + (size_t)d * stride,
                                          0, NULL, NULL);
        if (err != CL_SUCCESS)
            return ocl_fail(b->ctx, err, "copying the stored horizons");
    }
    return SS_OK;
}

ss_status ocl_cells_begin(ss_backend *b, const ss_band_run *run,
                                 const ss_cell_terms *terms, int planes, const int16_t *stored,
                                 int stored_planes, size_t stored_stride)
{
    ocl_backend *q = b->impl;
    size_t own = own_cells(run);
    ss_status st = ocl_unmap(b);
    if (st == SS_OK)
        st = room(b, &q->cell_terms, &q->cell_terms_cap, own * sizeof(ss_cell_terms),
                  "allocating the cells' terms");
    if (st == SS_OK)
        st = room(b, &q->cell_planes, &q->cell_planes_cap, own * (size_t)planes * sizeof(float),
                  "allocating the cells' sums");
    if (st == SS_OK)
        st = room(b, &q->cell_stored, &q->cell_stored_cap,
                  own * (size_t)stored_planes * sizeof(int16_t),
                  "allocating the stored horizons");
    if (st == SS_OK)
        st = ocl_upload(b, q->cell_terms, own * sizeof(ss_cell_terms), terms);
    if (st == SS_OK)
        st = upload_stored(b, stored, stored_planes, own, stored_stride);
    if (st == SS_OK)
        st = ocl_fill(b, q->cell_planes, own * (size_t)planes * sizeof(float));
    q->cell_planes_n = st == SS_OK ? planes : 0;
    return st;
}

/* A step's lattice in the next staging entry, as the device reads it
 * (none: no nodes, zero air). */
static ss_status stage_lattice(ss_backend *b, const ss_sun_lattice *l, lattice_entry **out)
{
    ocl_backend *q = b->impl;
    int fp64 = b->ctx->ocl->has_fp64;
    size_t nodes = l ? (size_t)l->n_cols * l->n_rows : 0;
    size_t real = fp64 ? sizeof(double) : sizeof(float);
    lattice_entry *e = &q->lattice_stage[q->lattice_next];
    q->lattice_next = (q->lattice_next + 1) % q->lattice_stages;
    if (e->written) { /* its last copy must be done before it is reused */
        cl_int err = clWaitForEvents(1, &e->written);
        clReleaseEvent(e->written);
        e->written = NULL;
        if (err != CL_SUCCESS)
            return ocl_fail(b->ctx, err, "waiting for a sun lattice's copy");
    }
    e->ints_bytes = l ? (size_t)(l->n_cols + l->n_rows) * sizeof(int) : 0;
    e->reals_bytes = (3 * nodes + 3) * real;
    size_t bytes = e->ints_bytes + e->reals_bytes;
    if (bytes > e->cap) {
        unsigned char *grown = ss_realloc(e->bytes, bytes);
        if (!grown)
            return ss_fail(b->ctx, SS_ERR_MEMORY, "out of memory for a sun lattice");
        e->bytes = grown;
        e->cap = bytes;
    }
    double air[3] = {0, 0, 0};
    const double *arrays[3] = {NULL, NULL, NULL};
    if (l) {
        memcpy(e->bytes, l->cols, (size_t)l->n_cols * sizeof(int));
        memcpy(e->bytes + (size_t)l->n_cols * sizeof(int), l->rows, (size_t)l->n_rows * sizeof(int));
        air[0] = l->pressure_hpa;
        air[1] = l->temperature_c;
        air[2] = l->atmos_refract_deg;
        arrays[0] = l->grid_azimuth_deg;
        arrays[1] = l->elevation_deg;
        arrays[2] = l->refraction_deg;
    }
    unsigned char *reals = e->bytes + e->ints_bytes;
    for (size_t k = 0; k < 3 * nodes + 3; ++k) {
        double v = k < 3 * nodes ? arrays[k / nodes][k % nodes] : air[k - 3 * nodes];
        float f = (float)v;
        memcpy(reals + k * real, fp64 ? (const void *)&v : (const void *)&f, real);
    }
    *out = e;
    return SS_OK;
}

ss_status ocl_cells_step(ss_backend *b, const ss_band_run *run, int slot,
                                const ss_cells_step *step, const ss_sun_lattice *lattice,
                                float *step_out)
{
    ocl_backend *q = b->impl;
    cl_command_queue queue = b->ctx->ocl->queue;
    lattice_entry *e = NULL;
    size_t own = own_cells(run);
    ss_status st = ocl_unmap(b);
    if (st == SS_OK)
        st = stage_lattice(b, lattice, &e);
    /* The buffers grow before the copies are queued (growing drops what
     * they held); a kernel still queued keeps the one it was given. */
    if (st == SS_OK)
        st = room(b, &q->lattice_at, &q->lattice_at_cap, e->ints_bytes,
                  "allocating a sun lattice");
    if (st == SS_OK)
        st = room(b, &q->lattice_nodes, &q->lattice_nodes_cap, e->reals_bytes,
                  "allocating a sun lattice");
    if (st == SS_OK)
        st = room(b, &q->cell_step, &q->cell_step_cap, step_out ? own * sizeof(float) : 0,
                  "allocating a step's global");
    if (st != SS_OK)
        return st;
    /* Not waited for: the queue runs in order, and the entry is reused
     * only once the second copy, and so the first, is done. */
    cl_int err = e->ints_bytes == 0 ? CL_SUCCESS
                                    : clEnqueueWriteBuffer(queue, q->lattice_at, CL_FALSE, 0,
                                                           e->ints_bytes, e->bytes, 0, NULL, NULL);
    if (err == CL_SUCCESS)
        err = clEnqueueWriteBuffer(queue, q->lattice_nodes, CL_FALSE, 0, e->reals_bytes,
                                   e->bytes + e->ints_bytes, 0, NULL, &e->written);
    if (err != CL_SUCCESS)
        return ocl_fail(b->ctx, err, "copying a sun lattice");
    ss_band_run r = *run;
    kernel_arg args[] = {ARG(r),           ARG(*step),          ARG(slot),
                         ARG(q->z),        ARG(q->outs),        ARG(q->cell_terms),
                         ARG(q->lattice_at), ARG(q->lattice_nodes), ARG(q->cell_planes),
                         ARG(q->cell_stored), ARG(q->cell_step)};
    st = ocl_run_kernel(b, b->ctx->ocl->k_cells, args, 11, own, "the insolation kernel");
    if (st != SS_OK || !step_out)
        return st;
    err = clEnqueueReadBuffer(queue, q->cell_step, CL_TRUE, 0, own * sizeof(float), step_out, 0,
                              NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : ocl_fail(b->ctx, err, "reading a step's global");
}

/* The band's sums come back in pieces of this many floats, added into the
 * host's as they come: a whole grid's 19 planes would double them. */
#define CELLS_BACK_FLOATS ((size_t)1 << 20)

ss_status ocl_cells_end(ss_backend *b, const ss_band_run *run, float *planes)
{
    ocl_backend *q = b->impl;
    size_t n = own_cells(run) * (size_t)q->cell_planes_n;
    ss_status st = ocl_unmap(b);
    if (st == SS_OK && !q->planes_back &&
        !(q->planes_back = ss_malloc(CELLS_BACK_FLOATS * sizeof(float))))
        st = ss_fail(b->ctx, SS_ERR_MEMORY, "out of memory for the cells' sums");
    for (size_t at = 0; st == SS_OK && at < n; at += CELLS_BACK_FLOATS) {
        size_t m = n - at < CELLS_BACK_FLOATS ? n - at : CELLS_BACK_FLOATS;
        cl_int err = clEnqueueReadBuffer(b->ctx->ocl->queue, q->cell_planes, CL_TRUE,
                                         at * sizeof(float), m * sizeof(float), q->planes_back,
                                         0, NULL, NULL);
        if (err != CL_SUCCESS)
            return ocl_fail(b->ctx, err, "reading the cells' sums");
        for (size_t k = 0; k < m; ++k)
            planes[at + k] += q->planes_back[k];
    }
    return st;
}
