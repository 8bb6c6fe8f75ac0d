/* What the OpenCL backend's files share (backend_ocl.c: the backend and
 * its walks; ocl_devices.c: finding, opening and releasing a device and
 * building the kernels; ocl_cells.c: insolation's cells on the device). */
#ifndef SS_OCL_INTERNAL_H
#define SS_OCL_INTERNAL_H

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include "backend.h"

struct ss_ocl {
    cl_device_id device;
    cl_context context;
    cl_command_queue queue;
    cl_program program;
    cl_kernel k_sum, k_horizon, k_hand_on, k_radius, k_bare, k_reduce, k_carry, k_finish;
    cl_kernel k_cells;
    size_t work_group;
    cl_ulong global_mem, max_alloc;
    int is_cpu;
    int has_fp64; /* the kernels' ss_real is double (ss_sun_lattice.h, SS_REAL_DOUBLE), else float */
};

/* Records err's failure of what: a memory status for the device's
 * allocation failures, else a device one. */
ss_status ocl_fail(ss_ctx *ctx, cl_int err, const char *what);

/* A step's sun lattice as queued for the device: its columns then rows
 * (ints), then its three node arrays and the air (ss_real). */
typedef struct {
    unsigned char *bytes;
    size_t cap, ints_bytes, reals_bytes;
    cl_event written; /* the copy's end, or NULL */
} lattice_entry;

typedef struct {
    cl_mem z, grad, stacks, sums, parts, outs, carry, dirs;
    cl_mem lit_levels; /* the walk's, or one byte no direction reads (lit_level -1) */
    int lit_levels_loaded; /* in bands: each band's levels come with its heights */
    /* Hulls handed on (ss_band.h): in from the band before, out to the next. */
    cl_mem hull_in, hull_out, in_off, in_cnt, out_off, out_cnt, state, counters;
    size_t hull_cap_in, hull_cap_out; /* points */
    int lines_cap;                    /* entries of the per-line arrays */
    cl_mem mapped;                    /* the buffer the host holds mapped, or NULL */
    /* The batches' directions as queued (a write not waited for reads them
     * later): two, since a batch is done before the one after next. */
    ss_band_dir *staged[2];
    int stage;
    void *mapped_ptr;
    cl_event queued;                  /* marks the end of the last batch queued (pace) */
    /* Insolation's steps (cells_*): the band's own cells' terms, planes and
     * stored horizons, a step's own global, each step's lattice, and where
     * the planes come back to. */
    cl_mem cell_terms, cell_planes, cell_stored, cell_step, lattice_at, lattice_nodes;
    size_t cell_terms_cap, cell_planes_cap, cell_stored_cap, cell_step_cap; /* bytes */
    size_t lattice_at_cap, lattice_nodes_cap;
    int cell_planes_n;
    float *planes_back; /* CELLS_BACK_FLOATS */
    /* Each step's lattice as queued (written without waiting): a ring, each
     * entry reused once its write is done; a batch's steps and two more, so
     * that the host waits on a step of the batch before last, done with it. */
    lattice_entry *lattice_stage;
    int lattice_stages, lattice_next;
} ocl_backend;

typedef struct {
    size_t size;
    const void *value;
} kernel_arg;

#define ARG(x) {sizeof(x), &(x)}

/* The backend's device helpers (backend_ocl.c). */
ss_status ocl_run_kernel(ss_backend *b, cl_kernel k, const kernel_arg *args, int n_args,
                         size_t items, const char *what);
ss_status ocl_fill(ss_backend *b, cl_mem buf, size_t bytes);
ss_status ocl_unmap(ss_backend *b);
cl_mem ocl_new_buffer(ss_backend *b, cl_mem_flags flags, size_t bytes, void *host,
                      cl_int *err);
ss_status ocl_upload(ss_backend *b, cl_mem buf, size_t bytes, const void *host);

/* Insolation's steps on the device (ocl_cells.c; ss_backend_ops.cells_*). */
ss_status ocl_cells_begin(ss_backend *b, const ss_band_run *run, const ss_cell_terms *terms,
                          int planes, const int16_t *stored, int stored_planes,
                          size_t stored_stride);
ss_status ocl_cells_step(ss_backend *b, const ss_band_run *run, int slot,
                         const ss_cells_step *step, const ss_sun_lattice *lattice,
                         float *step_out);
ss_status ocl_cells_end(ss_backend *b, const ss_band_run *run, float *planes);

#endif
