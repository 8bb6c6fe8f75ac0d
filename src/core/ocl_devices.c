/* The OpenCL devices: finds and lists them, picks the one asked for (PoCL's
 * CPU device by default), opens it and builds kernels/sweep.cl (embedded at
 * build time, so an installed binary needs no kernel files). */
#include "config.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/resource.h>
#include <sys/statvfs.h>

#include "ocl_build.h"
#include "ocl_internal.h"

extern const char ss_kernel_source[];

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

ss_status ocl_fail(ss_ctx *ctx, cl_int err, const char *what)
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

/* A CPU device's OpenCL (PoCL) compiles each kernel for the work-group
 * size it is enqueued with (and for ranges below 65536 work-items apart,
 * its "smallgrid" variant) only when it is first enqueued, keeping the
 * result in its cache folder (POCL_CACHE_DIR). With a cold cache those
 * compiles, LLVM's working memory, came in the middle of the sweep, after
 * the memory plan had measured the process, and its peak passed --memory
 * (doc/engine.md). Here every kernel is enqueued with the sweeps'
 * work-group size over both sizes of range, on nothing: no direction slot
 * and no cell, so that every work-item returns at once (NULL buffers).
 * The compiles then come with the program's build, before the plan
 * measures the process. Each kernel's arguments: m a buffer, R the band
 * (ss_band_run), S an insolation step (ss_cells_step), i an int. */
static ss_status compile_kernels_now(ss_ctx *ctx, struct ss_ocl *o)
{
    ss_band_run run;
    ss_cells_step step;
    memset(&run, 0, sizeof run);
    memset(&step, 0, sizeof step);
    run.lines = 1; /* batch_line divides by it; with no slot every work-item returns */
    int zero = 0;
    struct {
        cl_kernel k;
        const char *args;
    } kernels[] = {{o->k_sum, "mRimmmmmmmmm"},  {o->k_horizon, "mRimmmmmmmmm"},
                   {o->k_hand_on, "mRimmmmmmmmm"}, {o->k_radius, "mRimmm"},
                   {o->k_bare, "mRimm"},         {o->k_reduce, "Rimm"},
                   {o->k_carry, "Riiiiimmm"},    {o->k_finish, "Rim"},
                   {o->k_cells, "RSimmmmmmmm"}};
    size_t local = o->work_group;
    size_t ranges[] = {local, (65536 + local - 1) / local * local};
    cl_int err = CL_SUCCESS;
    ss_status st = SS_OK;
    for (size_t i = 0; i < sizeof kernels / sizeof kernels[0] && st == SS_OK; ++i) {
        cl_kernel k = kernels[i].k;
        for (cl_uint a = 0; kernels[i].args[a] && err == CL_SUCCESS; ++a) {
            char c = kernels[i].args[a];
            err = c == 'm'   ? clSetKernelArg(k, a, sizeof(cl_mem), NULL)
                  : c == 'R' ? clSetKernelArg(k, a, sizeof run, &run)
                  : c == 'S' ? clSetKernelArg(k, a, sizeof step, &step)
                             : clSetKernelArg(k, a, sizeof zero, &zero);
        }
        for (size_t r = 0; r < 2 && err == CL_SUCCESS; ++r)
            err = clEnqueueNDRangeKernel(o->queue, k, 1, NULL, &ranges[r], &local, 0, NULL,
                                         NULL);
        if (err == CL_SUCCESS)
            err = clFinish(o->queue);
        /* A kernel's compile takes a second or so with a cold cache: a
         * cancel is heard between them. */
        st = err == CL_SUCCESS ? ss_progress(ctx, 0.0, "the kernel build")
                               : ocl_fail(ctx, err, "compiling the kernels");
    }
    return st;
}

static ss_status build_program(ss_ctx *ctx, struct ss_ocl *o)
{
    cl_int err;
    const char *src = ss_kernel_source;
    o->program = clCreateProgramWithSource(o->context, 1, &src, NULL, &err);
    if (err != CL_SUCCESS)
        return ocl_fail(ctx, err, "clCreateProgramWithSource");
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
            return ocl_fail(ctx, err, kernels[i].name);
    }
    size_t max_wg = 64;
    clGetKernelWorkGroupInfo(o->k_sum, o->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof max_wg,
                             &max_wg, NULL);
    o->work_group = max_wg < 64 ? max_wg : 64;
    if (!o->is_cpu)
        return SS_OK;
    t0 = ss_seconds_now();
    st = compile_kernels_now(ctx, o);
    ctx->counters.build_seconds += ss_seconds_now() - t0;
    return st;
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
        return ocl_fail(ctx, err, "clCreateContext");
    o->queue = clCreateCommandQueue(o->context, o->device, 0, &err);
    if (err != CL_SUCCESS)
        return ocl_fail(ctx, err, "clCreateCommandQueue");
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

ss_status ss_ocl_acquire(ss_ctx *ctx)
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

int ss_ocl_own_memory(const ss_ctx *ctx, double *global_mem, double *max_alloc)
{
    if (!ctx || ctx->use_reference || !ctx->ocl || ctx->ocl->is_cpu)
        return 0;
    *global_mem = (double)ctx->ocl->global_mem;
    *max_alloc = (double)ctx->ocl->max_alloc;
    return 1;
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
