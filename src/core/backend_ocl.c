/* The OpenCL backend: finds and opens a device, builds kernels/sweep.cl
 * (embedded at build time, so an installed binary needs no kernel files),
 * and runs one work-item per line and direction of a batch. A whole grid
 * held by the caller is used with CL_MEM_USE_HOST_PTR, which PoCL serves
 * without copies. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <limits.h>
#include <sys/resource.h>
#include <sys/statvfs.h>

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include "backend.h"
#include "ocl_build.h"
#include "ss_passes.h"

extern const char ss_kernel_source[];

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

static const char *cl_error_name(cl_int err)
{
    switch (err) {
    case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
    case CL_DEVICE_NOT_AVAILABLE: return "CL_DEVICE_NOT_AVAILABLE";
    case CL_COMPILER_NOT_AVAILABLE: return "CL_COMPILER_NOT_AVAILABLE";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
    case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    default: return "OpenCL error";
    }
}

static ss_status cl_fail(ss_ctx *ctx, cl_int err, const char *what)
{
    ss_status st = (err == CL_MEM_OBJECT_ALLOCATION_FAILURE || err == CL_OUT_OF_HOST_MEMORY ||
                    err == CL_INVALID_BUFFER_SIZE)
                       ? SS_ERR_MEMORY
                       : SS_ERR_DEVICE;
    return ss_fail(ctx, st, "OpenCL: %s failed: %s (%d)", what, cl_error_name(err), (int)err);
}

/* ---- device discovery ---------------------------------------------------- */

typedef struct {
    cl_platform_id platform;
    cl_device_id device;
    int platform_index, device_index;
    char platform_name[256], device_name[256], version[64];
    cl_device_type type;
} ocl_device_info;

/* Calls fn for every device of every platform until it returns nonzero;
 * returns that value, 0, or -1 when out of memory. */
static int for_each_device(int (*fn)(const ocl_device_info *, void *), void *user)
{
    cl_uint n_platforms = 0;
    if (clGetPlatformIDs(0, NULL, &n_platforms) != CL_SUCCESS || n_platforms == 0)
        return 0;
    cl_platform_id *platforms = ss_calloc(n_platforms, sizeof *platforms);
    if (!platforms)
        return -1;
    if (clGetPlatformIDs(n_platforms, platforms, NULL) != CL_SUCCESS) {
        free(platforms);
        return 0;
    }
    int stop = 0;
    for (cl_uint p = 0; p < n_platforms && !stop; ++p) {
        cl_uint n_devices = 0;
        if (clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, 0, NULL, &n_devices) != CL_SUCCESS)
            continue;
        cl_device_id *devices = ss_calloc(n_devices, sizeof *devices);
        if (!devices) {
            stop = -1;
            break;
        }
        if (clGetDeviceIDs(platforms[p], CL_DEVICE_TYPE_ALL, n_devices, devices, NULL) ==
            CL_SUCCESS) {
            for (cl_uint d = 0; d < n_devices && !stop; ++d) {
                ocl_device_info info = {0};
                info.platform = platforms[p];
                info.device = devices[d];
                info.platform_index = (int)p;
                info.device_index = (int)d;
                clGetPlatformInfo(platforms[p], CL_PLATFORM_NAME, sizeof info.platform_name - 1,
                                  info.platform_name, NULL);
                clGetDeviceInfo(devices[d], CL_DEVICE_NAME, sizeof info.device_name - 1,
                                info.device_name, NULL);
                clGetDeviceInfo(devices[d], CL_DEVICE_OPENCL_C_VERSION, sizeof info.version - 1,
                                info.version, NULL);
                clGetDeviceInfo(devices[d], CL_DEVICE_TYPE, sizeof info.type, &info.type, NULL);
                stop = fn(&info, user);
            }
        }
        free(devices);
    }
    free(platforms);
    return stop;
}

typedef struct {
    char *buf;
    size_t size, used;
    int count;
} list_state;

static int list_one(const ocl_device_info *info, void *user)
{
    list_state *ls = user;
    ls->count++;
    if (ls->buf && ls->used < ls->size) {
        int n = snprintf(ls->buf + ls->used, ls->size - ls->used, "%d:%d %s: %s (%s)\n",
                         info->platform_index, info->device_index, info->platform_name,
                         info->device_name, info->version);
        if (n > 0)
            ls->used += (size_t)n;
    }
    return 0;
}

int ss_list_devices(ss_ctx *ctx, char *buf, size_t buf_size)
{
    (void)ctx;
    list_state ls = {buf, buf_size, 0, 0};
    if (buf && buf_size)
        buf[0] = '\0';
    for_each_device(list_one, &ls);
    return ls.count;
}

typedef struct {
    const char *spec;
    int want_p, want_d; /* from "P:D", else -1 */
    ocl_device_info found;
    int have;
} pick_state;

static int is_pocl_cpu(const ocl_device_info *info)
{
    return strstr(info->platform_name, "Portable Computing Language") != NULL &&
           (info->type & CL_DEVICE_TYPE_CPU);
}

static int pick_one(const ocl_device_info *info, void *user)
{
    pick_state *ps = user;
    if (ps->want_p >= 0) {
        if (info->platform_index == ps->want_p && info->device_index == ps->want_d) {
            ps->found = *info;
            ps->have = 1;
            return 1;
        }
        return 0;
    }
    if (ps->spec[0]) {
        char full[600];
        snprintf(full, sizeof full, "%s: %s", info->platform_name, info->device_name);
        size_t n = strlen(ps->spec);
        for (const char *p = full; *p; ++p)
            if (strncasecmp(p, ps->spec, n) == 0) {
                ps->found = *info;
                ps->have = 1;
                return 1;
            }
        return 0;
    }
    /* Default: PoCL's CPU device; otherwise remember the first device. */
    if (is_pocl_cpu(info)) {
        ps->found = *info;
        ps->have = 1;
        return 1;
    }
    if (!ps->have) {
        ps->found = *info;
        ps->have = 2; /* a fallback, keep looking for PoCL */
    }
    return 0;
}

typedef struct {
    ss_device_candidate *out;
    int max, n;
} candidates_state;

static int add_candidate(const ocl_device_info *info, void *user)
{
    candidates_state *cs = user;
    if (cs->n >= cs->max)
        return 1;
    ss_device_candidate *c = &cs->out[cs->n++];
    snprintf(c->spec, sizeof c->spec, "%d:%d", info->platform_index, info->device_index);
    snprintf(c->name, sizeof c->name, "%s: %s", info->platform_name, info->device_name);
    c->is_cpu = (info->type & CL_DEVICE_TYPE_CPU) != 0;
    cl_uint units = 0;
    clGetDeviceInfo(info->device, CL_DEVICE_MAX_COMPUTE_UNITS, sizeof units, &units, NULL);
    c->compute_units = (int)units;
    return 0;
}

int ss_opencl_devices(ss_device_candidate *out, int max)
{
    candidates_state cs = {out, max, 0};
    for_each_device(add_candidate, &cs);
    return cs.n;
}

/* Points the context at spec without touching its "auto" intent. */
static void select_device(ss_ctx *ctx, const char *spec)
{
    ss_ocl_release(ctx->ocl);
    ctx->ocl = NULL;
    ctx->device_name[0] = '\0';
    snprintf(ctx->device_spec, sizeof ctx->device_spec, "%s", spec ? spec : "");
    ctx->use_reference = spec && strcasecmp(spec, "reference") == 0;
    if (ctx->use_reference)
        snprintf(ctx->device_name, sizeof ctx->device_name, "C reference (host, OpenMP)");
}

ss_status ss_ctx_use_device(ss_ctx *ctx, const char *spec)
{
    ss_call_begin(ctx);
    /* The environment names the default, so whole test suites and scripts
     * can be pointed at another device (a GPU) without new options. */
    if (!spec || !spec[0])
        spec = getenv("SKYSWEEP_DEVICE");
    ctx->device_auto = spec && strcasecmp(spec, "auto") == 0;
    /* "auto" runs the C twin, which needs no set-up, until a plan chooses. */
    select_device(ctx, ctx->device_auto ? "reference" : spec);
    return SS_OK;
}

static ss_status ocl_acquire(ss_ctx *ctx);

ss_status ss_ctx_apply_plan(ss_ctx *ctx, const ss_plan *plan)
{
    ss_call_begin(ctx);
    if (!ctx->device_auto || !plan->device[0] || strcmp(ctx->device_spec, plan->device) == 0)
        return SS_OK;
    select_device(ctx, plan->device);
    /* A device the model chose but that does not open leaves the job to the
     * C twin, which computes the same (the summary names the device used);
     * a run cancelled while the device's kernels build stops. */
    ss_status st = ctx->use_reference ? SS_OK : ocl_acquire(ctx);
    if (st == SS_ERR_CANCELLED)
        return st;
    if (st != SS_OK)
        select_device(ctx, "reference");
    return SS_OK;
}

static ss_status build_program(ss_ctx *ctx, struct ss_ocl *o)
{
    cl_int err;
    const char *src = ss_kernel_source;
    o->program = clCreateProgramWithSource(o->context, 1, &src, NULL, &err);
    if (err != CL_SUCCESS)
        return cl_fail(ctx, err, "clCreateProgramWithSource");
    double t0 = ss_seconds_now();
    /* The lattice's type is the host's choice, so that the two agree. */
    const char *options = o->has_fp64 ? "-cl-std=CL1.2 -DSS_REAL_DOUBLE=1"
                                      : "-cl-std=CL1.2 -DSS_REAL_DOUBLE=0";
    ss_status st = ss_ocl_build(ctx, &o->program, o->device, options, &err);
    ctx->counters.build_seconds += ss_seconds_now() - t0;
    if (st != SS_OK)
        return st;
    if (err != CL_SUCCESS) {
        size_t log_size = 0;
        clGetProgramBuildInfo(o->program, o->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &log_size);
        char *log = ss_calloc(1, log_size + 1);
        if (log)
            clGetProgramBuildInfo(o->program, o->device, CL_PROGRAM_BUILD_LOG, log_size, log,
                                  NULL);
        st = ss_fail(ctx, SS_ERR_DEVICE,
                     "OpenCL kernels failed to build on %s (use --device reference to run the C "
                     "reference): %.1500s",
                     ctx->device_name, log ? log : "(no build log)");
        free(log);
        return st;
    }
    struct {
        cl_kernel *k;
        const char *name;
    } kernels[] = {{&o->k_sum, "band_sum"},         {&o->k_horizon, "band_horizon"},
                   {&o->k_hand_on, "band_hand_on"}, {&o->k_radius, "band_radius"},
                   {&o->k_bare, "band_bare"},       {&o->k_reduce, "band_reduce"},
                   {&o->k_carry, "band_carry"},     {&o->k_finish, "band_finish"},
                   {&o->k_cells, "insolation_cells"}};
    for (size_t i = 0; i < sizeof kernels / sizeof kernels[0]; ++i) {
        *kernels[i].k = clCreateKernel(o->program, kernels[i].name, &err);
        if (err != CL_SUCCESS)
            return cl_fail(ctx, err, kernels[i].name);
    }
    size_t max_wg = 64;
    clGetKernelWorkGroupInfo(o->k_sum, o->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof max_wg,
                             &max_wg, NULL);
    o->work_group = max_wg < 64 ? max_wg : 64;
    return SS_OK;
}

/* PoCL compiles kernels into files under its cache folder (LLVM ends the
 * process when such a write fails). Returns a reason when that cannot work
 * here: a file-size limit below what its compiler writes, or a cache folder
 * without room; NULL when it can. */
static const char *pocl_cannot_write(char *why, size_t size)
{
    const double need_file = 16.0 * 1048576, need_space = 64.0 * 1048576;
    struct rlimit lim;
    if (getrlimit(RLIMIT_FSIZE, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY &&
        (double)lim.rlim_cur < need_file) {
        snprintf(why, size, "the file size limit (ulimit -f: %.0f KiB) is below the 16 MiB "
                 "PoCL's kernel compiler may write", (double)lim.rlim_cur / 1024);
        return why;
    }
    char dir[PATH_MAX];
    const char *env = getenv("POCL_CACHE_DIR"), *xdg = getenv("XDG_CACHE_HOME"),
               *home = getenv("HOME");
    if (env && *env)
        snprintf(dir, sizeof dir, "%s", env);
    else if (xdg && *xdg)
        snprintf(dir, sizeof dir, "%s/pocl", xdg);
    else
        snprintf(dir, sizeof dir, "%s/.cache/pocl", home ? home : "/tmp");
    /* The folder may not exist yet: its nearest existing parent holds it. */
    struct statvfs fs;
    while (statvfs(dir, &fs) != 0) {
        char *slash = strrchr(dir, '/');
        if (!slash || slash == dir)
            return NULL;
        *slash = '\0';
    }
    double free_bytes = (double)fs.f_bavail * (double)fs.f_frsize;
    if (free_bytes < need_space) {
        snprintf(why, size, "PoCL's kernel cache folder %s has %.1f MiB free, below the 64 MiB "
                 "its compiler may need", dir, free_bytes / 1048576);
        return why;
    }
    return NULL;
}

/* Opens the chosen device and builds the kernels, once per context; a
 * failure leaves the context as it was, so the next call tries again. */
static ss_status ocl_open(ss_ctx *ctx, struct ss_ocl *o, const ocl_device_info *found)
{
    o->device = found->device;
    cl_int err;
    cl_context_properties props[] = {CL_CONTEXT_PLATFORM, (cl_context_properties)found->platform,
                                     0};
    o->context = clCreateContext(props, 1, &o->device, NULL, NULL, &err);
    if (err != CL_SUCCESS)
        return cl_fail(ctx, err, "clCreateContext");
    o->queue = clCreateCommandQueue(o->context, o->device, 0, &err);
    if (err != CL_SUCCESS)
        return cl_fail(ctx, err, "clCreateCommandQueue");
    clGetDeviceInfo(o->device, CL_DEVICE_GLOBAL_MEM_SIZE, sizeof o->global_mem, &o->global_mem,
                    NULL);
    clGetDeviceInfo(o->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof o->max_alloc, &o->max_alloc,
                    NULL);
    o->is_cpu = (found->type & CL_DEVICE_TYPE_CPU) != 0;
    cl_device_fp_config fp64 = 0;
    o->has_fp64 = clGetDeviceInfo(o->device, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof fp64, &fp64,
                                  NULL) == CL_SUCCESS &&
                  fp64 != 0;
    return build_program(ctx, o);
}

static ss_status ocl_acquire(ss_ctx *ctx)
{
    if (ctx->ocl)
        return SS_OK;
    pick_state ps = {ctx->device_spec, -1, -1, {0}, 0};
    int p, d;
    char tail;
    if (sscanf(ctx->device_spec, "%d:%d%c", &p, &d, &tail) == 2) {
        ps.want_p = p;
        ps.want_d = d;
    }
    if (for_each_device(pick_one, &ps) < 0)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory listing the OpenCL devices");
    if (!ps.have) {
        if (ctx->device_spec[0] && ss_list_devices(ctx, NULL, 0) > 0)
            return ss_fail(ctx, SS_ERR_DEVICE,
                           "no OpenCL device matches '%s' (see --device list)", ctx->device_spec);
        return ss_fail(ctx, SS_ERR_DEVICE,
                       "no OpenCL platform found%s%s%s: install pocl-opencl-icd, or run the C "
                       "twin with --device reference (or auto)",
                       ctx->device_spec[0] ? " (for '" : "", ctx->device_spec,
                       ctx->device_spec[0] ? "')" : "");
    }
    char why[PATH_MAX + 200];
    if (is_pocl_cpu(&ps.found) && pocl_cannot_write(why, sizeof why)) {
        if (ctx->device_spec[0])
            return ss_fail(ctx, SS_ERR_DEVICE, "cannot use %s: %s (use --device reference)",
                           ps.found.device_name, why);
        /* The default device cannot work here; the C twin computes the same. */
        ctx->use_reference = 1;
        snprintf(ctx->device_name, sizeof ctx->device_name,
                 "C reference (host, OpenMP), not PoCL: %.500s", why);
        return SS_OK;
    }
    struct ss_ocl *o = ss_calloc(1, sizeof *o);
    if (!o)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory opening OpenCL");
    snprintf(ctx->device_name, sizeof ctx->device_name, "%s: %s", ps.found.platform_name,
             ps.found.device_name);
    ss_status st = ocl_open(ctx, o, &ps.found);
    if (st != SS_OK) {
        ss_ocl_release(o);
        return st;
    }
    ctx->ocl = o;
    return SS_OK;
}

int ss_ocl_is_cpu(const ss_ctx *ctx)
{
    return ctx && !ctx->use_reference && ctx->ocl && ctx->ocl->is_cpu;
}

const char *ss_ctx_device_name(ss_ctx *ctx)
{
    if (!ctx->use_reference && !ctx->ocl && ocl_acquire(ctx) != SS_OK) {
        ctx->device_name[0] = '\0';
        return "(no device)";
    }
    return ctx->device_name;
}

void ss_ocl_release(struct ss_ocl *o)
{
    if (!o)
        return;
    cl_kernel kernels[] = {o->k_sum,  o->k_horizon, o->k_hand_on, o->k_radius, o->k_bare,
                           o->k_reduce, o->k_carry, o->k_finish, o->k_cells};
    for (size_t i = 0; i < sizeof kernels / sizeof kernels[0]; ++i)
        if (kernels[i])
            clReleaseKernel(kernels[i]);
    if (o->program)
        clReleaseProgram(o->program);
    if (o->queue)
        clReleaseCommandQueue(o->queue);
    if (o->context)
        clReleaseContext(o->context);
    free(o);
}

/* ---- band walks ----------------------------------------------------------- */

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

static size_t run_cells(const ss_band_run *run)
{
    return (size_t)run->held_rows * (size_t)run->width;
}

static size_t held_cells(const ss_backend *b)
{
    return (size_t)b->max_held_rows * (size_t)b->width;
}

/* Sets k's arguments and runs it over `items` work-items. */
static ss_status run_kernel(ss_backend *b, cl_kernel k, const kernel_arg *args, int n_args,
                            size_t items, const char *what)
{
    struct ss_ocl *o = b->ctx->ocl;
    for (int i = 0; i < n_args; ++i) {
        cl_int err = clSetKernelArg(k, (cl_uint)i, args[i].size, args[i].value);
        if (err != CL_SUCCESS)
            return cl_fail(b->ctx, err, what);
    }
    if (items == 0)
        return SS_OK;
    size_t local = o->work_group, global = (items + local - 1) / local * local;
    cl_int err = clEnqueueNDRangeKernel(o->queue, k, 1, NULL, &global, &local, 0, NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : cl_fail(b->ctx, err, what);
}

static ss_status fill(ss_backend *b, cl_mem buf, size_t bytes)
{
    if (bytes == 0)
        return SS_OK;
    float zero = 0.0f;
    cl_int err = clEnqueueFillBuffer(b->ctx->ocl->queue, buf, &zero, sizeof zero, 0, bytes, 0,
                                     NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : cl_fail(b->ctx, err, "clEnqueueFillBuffer");
}

static ss_status unmap(ss_backend *b)
{
    ocl_backend *q = b->impl;
    if (!q->mapped)
        return SS_OK;
    cl_int err = clEnqueueUnmapMemObject(b->ctx->ocl->queue, q->mapped, q->mapped_ptr, 0, NULL,
                                         NULL);
    q->mapped = NULL;
    return err == CL_SUCCESS ? SS_OK : cl_fail(b->ctx, err, "clEnqueueUnmapMemObject");
}

/* Maps bytes of buf for the host (waiting for what is queued before). */
static ss_status map(ss_backend *b, cl_mem buf, size_t bytes, float **host)
{
    ocl_backend *q = b->impl;
    if (q->mapped != buf) {
        ss_status st = unmap(b);
        if (st != SS_OK)
            return st;
        cl_int err;
        q->mapped_ptr = clEnqueueMapBuffer(b->ctx->ocl->queue, buf, CL_TRUE,
                                           CL_MAP_READ | CL_MAP_WRITE, 0, bytes, 0, NULL, NULL,
                                           &err);
        if (err != CL_SUCCESS)
            return cl_fail(b->ctx, err, "clEnqueueMapBuffer");
        q->mapped = buf;
    }
    *host = q->mapped_ptr;
    return SS_OK;
}

static cl_mem new_buffer(ss_backend *b, cl_mem_flags flags, size_t bytes, void *host,
                         cl_int *err)
{
    if (*err != CL_SUCCESS)
        return NULL;
    return clCreateBuffer(b->ctx->ocl->context, flags, bytes ? bytes : 4, host, err);
}

static ss_status upload(ss_backend *b, cl_mem buf, size_t bytes, const void *host)
{
    cl_int err = clEnqueueWriteBuffer(b->ctx->ocl->queue, buf, CL_TRUE, 0, bytes, host, 0, NULL,
                                      NULL);
    return err == CL_SUCCESS ? SS_OK : cl_fail(b->ctx, err, "clEnqueueWriteBuffer");
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
    return err == CL_SUCCESS ? SS_OK : cl_fail(b->ctx, err, "clEnqueueWriteBuffer");
}

static ss_status ocl_load(ss_backend *b, const ss_band_run *run, const float *z, const float *grad)
{
    ocl_backend *q = b->impl;
    ss_status st = unmap(b);
    if (st != SS_OK)
        return st;
    if (b->whole_z) {
        /* The whole grid is loaded once; its gradients come with it. */
        cl_int err = CL_SUCCESS;
        if (grad && !q->grad)
            q->grad = new_buffer(b, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                 2 * run_cells(run) * sizeof(float), (void *)grad, &err);
        return err == CL_SUCCESS ? SS_OK : cl_fail(b->ctx, err, "copying the gradients");
    }
    st = upload(b, q->z, run_cells(run) * sizeof(float), z);
    if (st == SS_OK && grad)
        st = upload(b, q->grad, 2 * run_cells(run) * sizeof(float), grad);
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
    ss_status st = unmap(b);
    if (st != SS_OK)
        return st;
    if (n_lines > q->lines_cap) {
        cl_mem *arrays[] = {&q->in_off, &q->in_cnt, &q->out_off, &q->out_cnt, &q->state};
        cl_int err = CL_SUCCESS;
        for (int i = 0; i < 5; ++i) {
            clReleaseMemObject(*arrays[i]);
            size_t ints = (size_t)n_lines * (i == 4 ? SS_BAND_STATE : 1);
            *arrays[i] = new_buffer(b, CL_MEM_READ_WRITE, ints * sizeof(int), NULL, &err);
        }
        if (err != CL_SUCCESS) {
            for (int i = 0; i < 5; ++i) {
                if (*arrays[i])
                    clReleaseMemObject(*arrays[i]);
                *arrays[i] = NULL;
            }
            q->lines_cap = 0;
            return cl_fail(b->ctx, err, "allocating the per-line hull arrays");
        }
        q->lines_cap = n_lines;
    }
    st = fill(b, q->in_cnt, (size_t)n_lines * sizeof(int));
    if (st == SS_OK)
        st = fill(b, q->in_off, (size_t)n_lines * sizeof(int));
    if (st == SS_OK)
        st = fill(b, q->counters, SS_BAND_COUNTERS * sizeof(int));
    if (st == SS_OK)
        st = fill(b, q->carry, carry_floats(b) * sizeof(float));
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
    return run_kernel(b, b->ctx->ocl->k_carry, args, 9, (size_t)n * planes * run->width,
                      "the carrying kernel");
}

static ss_status ocl_sums_begin(ss_backend *b, const ss_band_run *run, int pass)
{
    ocl_backend *q = b->impl;
    ss_status st = unmap(b);
    if (st == SS_OK)
        st = fill(b, q->sums, run_cells(run) * sizeof(float));
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
        return cl_fail(b->ctx, err, "reading the hull counters");
    size_t need = (size_t)counters[SS_BAND_PENDING], used = (size_t)counters[SS_BAND_USED];
    if (need <= q->hull_cap_out)
        return SS_OK;
    size_t cap = need + need / 2 + 1024;
    cl_mem grown = new_buffer(b, CL_MEM_READ_WRITE, cap * sizeof(ss_hull_point), NULL, &err);
    if (err == CL_SUCCESS && used > 0)
        err = clEnqueueCopyBuffer(o->queue, q->hull_out, grown, 0, 0, used * sizeof(ss_hull_point),
                                  0, NULL, NULL);
    if (err != CL_SUCCESS) {
        if (grown)
            clReleaseMemObject(grown);
        return cl_fail(b->ctx, err, "growing the hulls handed on");
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
        return cl_fail(b->ctx, err, "queueing a batch");
    if (q->queued) {
        err = clWaitForEvents(1, &q->queued);
        clReleaseEvent(q->queued);
    }
    q->queued = mark;
    if (err != CL_SUCCESS)
        return cl_fail(b->ctx, err, "waiting for a batch");
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
        st = run_kernel(b, o->k_horizon, args, 12, items, "the horizon kernel");
    } else if (walk->radius_m > 0) {
        kernel_arg args[] = {ARG(q->dirs),   ARG(run), ARG(round),
                             ARG(q->z),      ARG(q->stacks), ARG(sums)};
        return run_kernel(b, o->k_radius, args, 6, items, "the radius-limited horizon kernel");
    } else {
        cl_mem grad = q->grad ? q->grad : q->z; /* read by the radiative term only */
        kernel_arg args[] = {ARG(q->dirs),   ARG(run),      ARG(round),      ARG(q->z),
                             ARG(grad),      ARG(q->stacks), ARG(sums),      ARG(q->hull_in),
                             ARG(q->in_off), ARG(q->in_cnt), ARG(q->state),  ARG(q->counters)};
        st = run_kernel(b, o->k_sum, args, 12, items, "the SVF kernel");
    }
    if (st != SS_OK || run.whole)
        return st;
    st = hull_room(b);
    kernel_arg args[] = {ARG(q->dirs),    ARG(run),      ARG(round),       ARG(q->z),
                         ARG(q->stacks),  ARG(q->hull_in), ARG(q->in_off), ARG(q->state),
                         ARG(q->hull_out), ARG(q->out_off), ARG(q->out_cnt), ARG(q->counters)};
    return st == SS_OK ? run_kernel(b, o->k_hand_on, args, 12, items, "the hand-on kernel") : st;
}

static ss_status ocl_walk(ss_backend *b, const ss_band_run *run, const ss_band_dir *dirs, int n)
{
    ocl_backend *q = b->impl;
    struct ss_ocl *o = b->ctx->ocl;
    int horizon = b->walk.term == SS_TERM_HORIZON;
    ss_status st = unmap(b);
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
        st = fill(b, q->outs, (size_t)n * run->planes * run_cells(run) * sizeof(float));
    if (st == SS_OK && horizon)
        st = carry(b, run, dirs[0].pass, n, run->planes, 1, 1, q->outs);
    if (st == SS_OK && slotted)
        st = fill(b, q->parts, (size_t)n * run_cells(run) * sizeof(float));
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
        st = run_kernel(b, o->k_reduce, args, 4, run_cells(run), "the reducing kernel");
    }
    if (st == SS_OK && horizon)
        st = carry(b, run, dirs[0].pass, n, run->planes, 0, 1, q->outs);
    if (st == SS_OK && horizon) {
        kernel_arg args[] = {ARG(*run), ARG(n), ARG(q->outs)};
        st = run_kernel(b, o->k_finish, args, 3,
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
    ss_status st = unmap(b);
    cl_int err = st == SS_OK ? clEnqueueReadBuffer(b->ctx->ocl->queue, q->counters, CL_TRUE, 0,
                                                   sizeof counters, counters, 0, NULL, NULL)
                             : CL_SUCCESS;
    if (st != SS_OK)
        return st;
    if (err != CL_SUCCESS)
        return cl_fail(b->ctx, err, "reading the hull counters");
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
    return fill(b, q->counters, sizeof counters);
}

static ss_status ocl_bare(ss_backend *b, const ss_band_run *run, const ss_band_dir *dir,
                          float **out)
{
    ocl_backend *q = b->impl;
    struct ss_ocl *o = b->ctx->ocl;
    ss_status st = unmap(b);
    if (st == SS_OK)
        st = fill(b, q->sums, run_cells(run) * sizeof(float));
    if (st == SS_OK)
        st = upload_dirs(b, dir, 1);
    for (int round = 0; round < ss_line_rounds(&dir->ls) && st == SS_OK; ++round) {
        ss_band_run r = *run;
        r.lines = ss_round_lines(&dir->ls, round);
        r.slots = 1;
        kernel_arg args[] = {ARG(q->dirs), ARG(r), ARG(round), ARG(q->z), ARG(q->sums)};
        st = run_kernel(b, o->k_bare, args, 5, (size_t)r.lines, "the bare-pass kernel");
    }
    if (st == SS_OK)
        st = map(b, q->sums, run_cells(run) * sizeof(float), out);
    return st;
}

/* ---- insolation's steps -------------------------------------------------- */

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
    *buf = new_buffer(b, CL_MEM_READ_WRITE, bytes, NULL, &err);
    *cap = err == CL_SUCCESS ? bytes : 0;
    return err == CL_SUCCESS ? SS_OK : cl_fail(b->ctx, err, what);
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
            return cl_fail(b->ctx, err, "copying the stored horizons");
    }
    return SS_OK;
}

static ss_status ocl_cells_begin(ss_backend *b, const ss_band_run *run,
                                 const ss_cell_terms *terms, int planes, const int16_t *stored,
                                 int stored_planes, size_t stored_stride)
{
    ocl_backend *q = b->impl;
    size_t own = own_cells(run);
    ss_status st = unmap(b);
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
        st = upload(b, q->cell_terms, own * sizeof(ss_cell_terms), terms);
    if (st == SS_OK)
        st = upload_stored(b, stored, stored_planes, own, stored_stride);
    if (st == SS_OK)
        st = fill(b, q->cell_planes, own * (size_t)planes * sizeof(float));
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
            return cl_fail(b->ctx, err, "waiting for a sun lattice's copy");
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

static ss_status ocl_cells_step(ss_backend *b, const ss_band_run *run, int slot,
                                const ss_cells_step *step, const ss_sun_lattice *lattice,
                                float *step_out)
{
    ocl_backend *q = b->impl;
    cl_command_queue queue = b->ctx->ocl->queue;
    lattice_entry *e = NULL;
    size_t own = own_cells(run);
    ss_status st = unmap(b);
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
        return cl_fail(b->ctx, err, "copying a sun lattice");
    ss_band_run r = *run;
    kernel_arg args[] = {ARG(r),           ARG(*step),          ARG(slot),
                         ARG(q->z),        ARG(q->outs),        ARG(q->cell_terms),
                         ARG(q->lattice_at), ARG(q->lattice_nodes), ARG(q->cell_planes),
                         ARG(q->cell_stored), ARG(q->cell_step)};
    st = run_kernel(b, b->ctx->ocl->k_cells, args, 11, own, "the insolation kernel");
    if (st != SS_OK || !step_out)
        return st;
    err = clEnqueueReadBuffer(queue, q->cell_step, CL_TRUE, 0, own * sizeof(float), step_out, 0,
                              NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : cl_fail(b->ctx, err, "reading a step's global");
}

/* The band's sums come back in pieces of this many floats, added into the
 * host's as they come: a whole grid's 19 planes would double them. */
#define CELLS_BACK_FLOATS ((size_t)1 << 20)

static ss_status ocl_cells_end(ss_backend *b, const ss_band_run *run, float *planes)
{
    ocl_backend *q = b->impl;
    size_t n = own_cells(run) * (size_t)q->cell_planes_n;
    ss_status st = unmap(b);
    if (st == SS_OK && !q->planes_back &&
        !(q->planes_back = ss_malloc(CELLS_BACK_FLOATS * sizeof(float))))
        st = ss_fail(b->ctx, SS_ERR_MEMORY, "out of memory for the cells' sums");
    for (size_t at = 0; st == SS_OK && at < n; at += CELLS_BACK_FLOATS) {
        size_t m = n - at < CELLS_BACK_FLOATS ? n - at : CELLS_BACK_FLOATS;
        cl_int err = clEnqueueReadBuffer(b->ctx->ocl->queue, q->cell_planes, CL_TRUE,
                                         at * sizeof(float), m * sizeof(float), q->planes_back,
                                         0, NULL, NULL);
        if (err != CL_SUCCESS)
            return cl_fail(b->ctx, err, "reading the cells' sums");
        for (size_t k = 0; k < m; ++k)
            planes[at + k] += q->planes_back[k];
    }
    return st;
}

static void ocl_close(ss_backend *b)
{
    ocl_backend *q = b->impl;
    if (!q)
        return;
    if (b->ctx->ocl) {
        unmap(b);
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
 * plan gives the device's buffers (memory_plan.c) and its largest buffer. A CPU device walks one direction
 * of a whole grid at a time unless the context asks for more: a launch
 * costs it about 0.1 ms against milliseconds of work, while a batch's own
 * sums and stack grids cost memory traffic; in bands, where each round of
 * a batch waits for its hulls' count, it takes up to 4 (doc/engine.md:
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
    ss_status st = ocl_acquire(b->ctx);
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
        q->z = new_buffer(b, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, fbytes, (void *)b->whole_z,
                          &err);
    else
        q->z = new_buffer(b, CL_MEM_READ_ONLY, fbytes, NULL, &err);
    if (!b->whole_z && b->walk.term == SS_SVF_TILTED)
        q->grad = new_buffer(b, CL_MEM_READ_ONLY, 2 * fbytes, NULL, &err);
    q->stacks = new_buffer(b, CL_MEM_READ_WRITE,
                           (size_t)b->batch * cells * b->stack_per_cell * sizeof(int), NULL, &err);
    q->sums = new_buffer(b, CL_MEM_READ_WRITE, fbytes, NULL, &err);
    if (horizon)
        q->outs = new_buffer(b, CL_MEM_READ_WRITE, (size_t)b->batch * planes * fbytes, NULL, &err);
    else if (b->batch > 1)
        q->parts = new_buffer(b, CL_MEM_READ_WRITE, (size_t)b->batch * fbytes, NULL, &err);
    q->carry = new_buffer(b, CL_MEM_READ_WRITE, carry_floats(b) * sizeof(float), NULL, &err);
    q->dirs = new_buffer(b, CL_MEM_READ_ONLY, (size_t)b->batch * sizeof(ss_band_dir), NULL, &err);
    q->counters = new_buffer(b, CL_MEM_READ_WRITE, SS_BAND_COUNTERS * sizeof(int), NULL, &err);
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
    b->cells_max_bytes =
        (size_t)fmin((double)o->max_alloc, ss_memory_device_bytes(b->ctx, (double)o->global_mem));
    /* Shadow walks stop early on a whole grid only (engine.c sets lit_level
     * -1 elsewhere). */
    if (horizon && b->walk.lit_levels && b->whole_z)
        q->lit_levels = new_buffer(b, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, cells,
                                   (void *)b->walk.lit_levels, &err);
    else
        q->lit_levels = new_buffer(b, CL_MEM_READ_ONLY, 1, NULL, &err);
    /* Valid (if empty) hull buffers, so every kernel argument is a buffer. */
    q->hull_in = new_buffer(b, CL_MEM_READ_WRITE, sizeof(ss_hull_point), NULL, &err);
    q->hull_out = new_buffer(b, CL_MEM_READ_WRITE, sizeof(ss_hull_point), NULL, &err);
    q->hull_cap_in = q->hull_cap_out = 1;
    cl_mem *lines[] = {&q->in_off, &q->in_cnt, &q->out_off, &q->out_cnt, &q->state};
    for (int i = 0; i < 5; ++i)
        *lines[i] = new_buffer(b, CL_MEM_READ_WRITE, SS_BAND_STATE * sizeof(int), NULL, &err);
    q->lines_cap = 1;
    if (err != CL_SUCCESS) {
        ocl_close(b);
        return cl_fail(b->ctx, err, "allocating device buffers");
    }
    return SS_OK;
}
