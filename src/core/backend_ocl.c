/* The OpenCL backend: finds and opens a device, builds kernels/sweep.cl
 * (embedded at build time, so an installed binary needs no kernel files),
 * and runs one work-item per line. Grids shared with the host use
 * CL_MEM_USE_HOST_PTR, which PoCL serves without copies. */
#include "config.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <limits.h>
#include <sys/resource.h>
#include <sys/statvfs.h>

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include "session.h"
#include "ss_passes.h"

extern const char ss_kernel_source[];

struct ss_ocl {
    cl_device_id device;
    cl_context context;
    cl_command_queue queue;
    cl_program program;
    cl_kernel k_svf, k_horizon, k_horizon_finish, k_bare, k_radius;
    size_t work_group;
};

typedef struct {
    cl_mem z, stack, out[SS_SESSION_MAX_OUTPUTS];
    cl_mem weight; /* horizon weights (ss_pass_horizon_walk), made on first use */
    cl_mem grad;   /* gradients for the radiative SVF (ss_gradient_grid), made on first use */
    float *host[SS_SESSION_MAX_OUTPUTS];
    int mapped[SS_SESSION_MAX_OUTPUTS];
    cl_event queued; /* marks the end of the last pass queued (pace) */
} ocl_session;

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
    if (!ctx->device_auto || !plan->device[0] || strcmp(ctx->device_spec, plan->device) == 0)
        return SS_OK;
    select_device(ctx, plan->device);
    /* A device the model chose but that does not open leaves the job to the
     * C twin, which computes the same (the summary names the device used). */
    if (!ctx->use_reference && ocl_acquire(ctx) != SS_OK)
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
    err = clBuildProgram(o->program, 1, &o->device, "-cl-std=CL1.2", NULL, NULL);
    ctx->counters.build_seconds += ss_seconds_now() - t0;
    if (err != CL_SUCCESS) {
        size_t log_size = 0;
        clGetProgramBuildInfo(o->program, o->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &log_size);
        char *log = ss_calloc(1, log_size + 1);
        if (log)
            clGetProgramBuildInfo(o->program, o->device, CL_PROGRAM_BUILD_LOG, log_size, log,
                                  NULL);
        ss_status st = ss_fail(ctx, SS_ERR_DEVICE,
                               "OpenCL kernels failed to build on %s (use --device reference "
                               "to run the C reference): %.1500s",
                               ctx->device_name, log ? log : "(no build log)");
        free(log);
        return st;
    }
    struct {
        cl_kernel *k;
        const char *name;
    } kernels[] = {{&o->k_svf, "sweep_svf"},
                   {&o->k_horizon, "sweep_horizon"},
                   {&o->k_horizon_finish, "sweep_horizon_finish"},
                   {&o->k_bare, "sweep_bare"},
                   {&o->k_radius, "sweep_radius_terms"}};
    for (size_t i = 0; i < sizeof kernels / sizeof kernels[0]; ++i) {
        *kernels[i].k = clCreateKernel(o->program, kernels[i].name, &err);
        if (err != CL_SUCCESS)
            return cl_fail(ctx, err, kernels[i].name);
    }
    size_t max_wg = 64;
    clGetKernelWorkGroupInfo(o->k_svf, o->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof max_wg,
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
    if (o->k_svf)
        clReleaseKernel(o->k_svf);
    if (o->k_horizon)
        clReleaseKernel(o->k_horizon);
    if (o->k_horizon_finish)
        clReleaseKernel(o->k_horizon_finish);
    if (o->k_bare)
        clReleaseKernel(o->k_bare);
    if (o->k_radius)
        clReleaseKernel(o->k_radius);
    if (o->program)
        clReleaseProgram(o->program);
    if (o->queue)
        clReleaseCommandQueue(o->queue);
    if (o->context)
        clReleaseContext(o->context);
    free(o);
}

/* ---- sessions ------------------------------------------------------------ */

static ss_status unmap_all(ss_session *s)
{
    ocl_session *q = s->impl;
    for (int i = 0; i < s->n_outputs; ++i) {
        if (!q->mapped[i])
            continue;
        cl_int err = clEnqueueUnmapMemObject(s->ctx->ocl->queue, q->out[i], q->host[i], 0, NULL,
                                             NULL);
        q->mapped[i] = 0;
        if (err != CL_SUCCESS)
            return cl_fail(s->ctx, err, "clEnqueueUnmapMemObject");
    }
    return SS_OK;
}

static size_t grid_cells(const ss_session *s)
{
    return (size_t)s->grid->width * (size_t)s->grid->height;
}

static ss_status ocl_clear(ss_session *s, int output)
{
    ocl_session *q = s->impl;
    ss_status st = unmap_all(s);
    if (st != SS_OK)
        return st;
    float zero = 0.0f;
    cl_int err = clEnqueueFillBuffer(s->ctx->ocl->queue, q->out[output], &zero, sizeof zero, 0,
                                     grid_cells(s) * sizeof(float), 0, NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : cl_fail(s->ctx, err, "clEnqueueFillBuffer");
}

/* Sets kernel arguments in order from a list of (size, pointer) pairs. */
typedef struct {
    size_t size;
    const void *value;
} kernel_arg;

/* Runs kernel k over the lines of a direction, one round after the other;
 * args[1] is the round number, set here. */
static ss_status launch(ss_session *s, cl_kernel k, kernel_arg *args, int n_args,
                        const ss_line_set *ls, const char *what)
{
    struct ss_ocl *o = s->ctx->ocl;
    ss_status st = unmap_all(s);
    if (st != SS_OK)
        return st;
    for (int round = 0; round < 2; ++round) {
        int n_lines = ss_round_lines(ls, round);
        if (n_lines == 0)
            continue;
        args[1].size = sizeof round;
        args[1].value = &round;
        for (int i = 0; i < n_args; ++i) {
            cl_int err = clSetKernelArg(k, (cl_uint)i, args[i].size, args[i].value);
            if (err != CL_SUCCESS)
                return cl_fail(s->ctx, err, what);
        }
        size_t local = o->work_group;
        size_t global = ((size_t)n_lines + local - 1) / local * local;
        cl_int err = clEnqueueNDRangeKernel(o->queue, k, 1, NULL, &global, &local, 0, NULL, NULL);
        if (err != CL_SUCCESS)
            return cl_fail(s->ctx, err, what);
    }
    return SS_OK;
}

/* Ends a pass: waits for the pass before it, so that at most one pass is
 * queued behind the running one. The device never idles (the next pass is
 * queued before the wait), and a cancelled run waits for two passes, not for
 * every direction it had queued (an NDRange cannot be stopped once queued). */
static ss_status pace(ss_session *s, ss_status st)
{
    ocl_session *q = s->impl;
    cl_command_queue queue = s->ctx->ocl->queue;
    if (st != SS_OK)
        return st;
    cl_event mark;
    cl_int err = clEnqueueMarkerWithWaitList(queue, 0, NULL, &mark);
    if (err == CL_SUCCESS)
        err = clFlush(queue);
    if (err != CL_SUCCESS)
        return cl_fail(s->ctx, err, "queueing a pass");
    if (q->queued) {
        err = clWaitForEvents(1, &q->queued);
        clReleaseEvent(q->queued);
    }
    q->queued = mark;
    if (err != CL_SUCCESS)
        return cl_fail(s->ctx, err, "waiting for a pass");
    return ss_check_cancel(s->ctx, "the sweep");
}

/* The radiative SVF's gradient grid, computed on the host (as the C twin
 * does) and copied to the device once per session. */
static ss_status make_gradients(ss_session *s)
{
    ocl_session *q = s->impl;
    size_t bytes = 2 * grid_cells(s) * sizeof(float);
    float *host = ss_alloc_grid(bytes);
    if (!host)
        return ss_fail(s->ctx, SS_ERR_MEMORY, "cannot allocate %zu MB of surface gradients",
                       bytes >> 20);
    ss_gradient_grid(s->grid, host);
    cl_int err = CL_SUCCESS;
    q->grad = clCreateBuffer(s->ctx->ocl->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes,
                             host, &err);
    free(host);
    if (err != CL_SUCCESS) {
        q->grad = NULL;
        return cl_fail(s->ctx, err, "allocating the surface gradients");
    }
    return SS_OK;
}

static ss_status ocl_svf(ss_session *s, const ss_line_set *ls, int definition, float curv_k,
                         float sin_az, float cos_az)
{
    ocl_session *q = s->impl;
    float cx = (float)s->grid->cell_x_m, cy = (float)s->grid->cell_y_m;
    int height = s->grid->height;
    if (definition == SS_SVF_TILTED && !q->grad) {
        ss_status st = make_gradients(s);
        if (st != SS_OK)
            return st;
    }
    /* The other definitions read no gradient: the heights stand in. */
    cl_mem grad = definition == SS_SVF_TILTED ? q->grad : q->z;
    kernel_arg args[] = {{sizeof *ls, ls},          {0, NULL},
                         {sizeof definition, &definition},
                         {sizeof curv_k, &curv_k},  {sizeof sin_az, &sin_az},
                         {sizeof cos_az, &cos_az},  {sizeof cx, &cx},
                         {sizeof cy, &cy},          {sizeof height, &height},
                         {sizeof(cl_mem), &q->z},   {sizeof(cl_mem), &grad},
                         {sizeof(cl_mem), &q->stack}, {sizeof(cl_mem), &q->out[0]}};
    return pace(s, launch(s, s->ctx->ocl->k_svf, args, 13, ls, "the SVF kernel"));
}

/* Zeroes the horizon weight grid, creating it on first use: only horizon
 * sessions pay for it. */
static ss_status clear_weight(ss_session *s)
{
    ocl_session *q = s->impl;
    struct ss_ocl *o = s->ctx->ocl;
    size_t bytes = grid_cells(s) * sizeof(float);
    cl_int err = CL_SUCCESS;
    if (!q->weight)
        q->weight = clCreateBuffer(o->context, CL_MEM_READ_WRITE, bytes, NULL, &err);
    if (err != CL_SUCCESS)
        return cl_fail(s->ctx, err, "allocating the horizon weights");
    float zero = 0.0f;
    err = clEnqueueFillBuffer(o->queue, q->weight, &zero, sizeof zero, 0, bytes, 0, NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : cl_fail(s->ctx, err, "clEnqueueFillBuffer");
}

/* Divides the angle sums by their weights (ss_pass_horizon_finish), one
 * work-item per cell. */
static ss_status finish_horizon(ss_session *s, float none_deg)
{
    ocl_session *q = s->impl;
    struct ss_ocl *o = s->ctx->ocl;
    int n_cells = (int)grid_cells(s);
    kernel_arg args[] = {{sizeof n_cells, &n_cells},
                         {sizeof none_deg, &none_deg},
                         {sizeof(cl_mem), &q->out[0]},
                         {sizeof(cl_mem), &q->weight}};
    for (cl_uint i = 0; i < 4; ++i) {
        cl_int err = clSetKernelArg(o->k_horizon_finish, i, args[i].size, args[i].value);
        if (err != CL_SUCCESS)
            return cl_fail(s->ctx, err, "the horizon finishing kernel");
    }
    size_t local = o->work_group;
    size_t global = ((size_t)n_cells + local - 1) / local * local;
    cl_int err = clEnqueueNDRangeKernel(o->queue, o->k_horizon_finish, 1, NULL, &global, &local,
                                        0, NULL, NULL);
    return err == CL_SUCCESS ? SS_OK : cl_fail(s->ctx, err, "the horizon finishing kernel");
}

static ss_status ocl_horizon(ss_session *s, const ss_line_set *ls, float curv_k, float none_deg,
                             int want)
{
    ocl_session *q = s->impl;
    ss_status st = clear_weight(s);
    if (st != SS_OK)
        return st;
    /* Grids not asked for are never written: output 0 stands in. */
    cl_mem dist = want & SS_HORIZON_WANT_DIST ? q->out[1] : q->out[0];
    cl_mem cast = want & SS_HORIZON_WANT_CAST ? q->out[2] : q->out[0];
    kernel_arg args[] = {{sizeof *ls, ls},           {0, NULL},
                         {sizeof curv_k, &curv_k},   {sizeof(cl_mem), &q->z},
                         {sizeof(cl_mem), &q->stack}, {sizeof(cl_mem), &q->out[0]},
                         {sizeof(cl_mem), &q->weight}, {sizeof(cl_mem), &dist},
                         {sizeof(cl_mem), &cast},    {sizeof want, &want}};
    st = launch(s, s->ctx->ocl->k_horizon, args, 10, ls, "the horizon kernel");
    return pace(s, st == SS_OK ? finish_horizon(s, none_deg) : st);
}

static ss_status ocl_bare(ss_session *s, const ss_line_set *ls)
{
    ocl_session *q = s->impl;
    kernel_arg args[] = {
        {sizeof *ls, ls}, {0, NULL}, {sizeof(cl_mem), &q->z}, {sizeof(cl_mem), &q->out[0]}};
    return pace(s, launch(s, s->ctx->ocl->k_bare, args, 4, ls, "the bare-pass kernel"));
}

static ss_status ocl_radius_terms(ss_session *s, const ss_line_set *ls, int definition,
                                  float radius_m, float curv_k)
{
    ocl_session *q = s->impl;
    kernel_arg args[] = {{sizeof *ls, ls},
                         {0, NULL},
                         {sizeof definition, &definition},
                         {sizeof radius_m, &radius_m},
                         {sizeof curv_k, &curv_k},
                         {sizeof(cl_mem), &q->z},
                         {sizeof(cl_mem), &q->out[0]}};
    return pace(s,
                launch(s, s->ctx->ocl->k_radius, args, 7, ls, "the radius-limited horizon kernel"));
}

static ss_status ocl_view(ss_session *s, int output, float **host)
{
    ocl_session *q = s->impl;
    if (!q->mapped[output]) {
        cl_int err;
        void *p = clEnqueueMapBuffer(s->ctx->ocl->queue, q->out[output], CL_TRUE, CL_MAP_READ | CL_MAP_WRITE, 0,
                                     grid_cells(s) * sizeof(float), 0, NULL, NULL, &err);
        if (err != CL_SUCCESS)
            return cl_fail(s->ctx, err, "clEnqueueMapBuffer");
        q->host[output] = p;
        q->mapped[output] = 1;
    }
    *host = q->host[output];
    return SS_OK;
}

static void ocl_close(ss_session *s)
{
    ocl_session *q = s->impl;
    if (!q)
        return;
    if (s->ctx->ocl) {
        unmap_all(s);
        clFinish(s->ctx->ocl->queue);
    }
    if (q->queued)
        clReleaseEvent(q->queued);
    if (q->z)
        clReleaseMemObject(q->z);
    if (q->stack)
        clReleaseMemObject(q->stack);
    if (q->weight)
        clReleaseMemObject(q->weight);
    if (q->grad)
        clReleaseMemObject(q->grad);
    for (int i = 0; i < SS_SESSION_MAX_OUTPUTS; ++i)
        if (q->out[i])
            clReleaseMemObject(q->out[i]);
    free(q);
}

static const ss_backend ocl_backend = {ocl_clear, ocl_svf,  ocl_horizon, ocl_bare,
                                       ocl_radius_terms, ocl_view, ocl_close};

ss_status ss_backend_ocl_open(ss_session *s)
{
    ss_status st = ocl_acquire(s->ctx);
    if (st != SS_OK)
        return st;
    if (s->ctx->use_reference) /* the default device could not work here */
        return ss_backend_ref_open(s);
    struct ss_ocl *o = s->ctx->ocl;
    ocl_session *q = ss_calloc(1, sizeof *q);
    if (!q)
        return ss_fail(s->ctx, SS_ERR_MEMORY, "out of memory opening a session");
    s->impl = q;
    s->backend = &ocl_backend;
    size_t bytes = grid_cells(s) * sizeof(float);
    cl_int err;
    q->z = clCreateBuffer(o->context, CL_MEM_READ_ONLY | CL_MEM_USE_HOST_PTR, bytes,
                          s->grid->z, &err);
    if (err == CL_SUCCESS)
        q->stack = clCreateBuffer(o->context, CL_MEM_READ_WRITE, grid_cells(s) * sizeof(int),
                                  NULL, &err);
    for (int i = 0; i < s->n_outputs && err == CL_SUCCESS; ++i)
        q->out[i] = clCreateBuffer(o->context, CL_MEM_READ_WRITE, bytes, NULL, &err);
    if (err != CL_SUCCESS) {
        ocl_close(s);
        s->impl = NULL;
        return cl_fail(s->ctx, err, "allocating device buffers");
    }
    for (int i = 0; i < s->n_outputs; ++i)
        if ((st = ocl_clear(s, i)) != SS_OK) {
            ocl_close(s);
            s->impl = NULL;
            return st;
        }
    return SS_OK;
}
