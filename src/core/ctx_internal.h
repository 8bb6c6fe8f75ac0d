/* What the library keeps per context, and the helpers every core file uses
 * to fail with a message, report progress and count work. */
#ifndef SS_CTX_INTERNAL_H
#define SS_CTX_INTERNAL_H

#include <signal.h>

#include "skysweep.h"

#ifdef __cplusplus
extern "C" {
#endif

struct ss_ocl; /* ocl_devices.c: the opened OpenCL device, context and kernels */
/* Opens the context's chosen device and builds the kernels, once per
 * context; a failure leaves the context as it was, so the next call tries
 * again. */
ss_status ss_ocl_acquire(ss_ctx *ctx);
void ss_ocl_release(struct ss_ocl *ocl);
/* Whether ctx runs on an OpenCL CPU device (opened), whose buffers are
 * host memory. */
int ss_ocl_is_cpu(const ss_ctx *ctx);
/* Whether ctx runs on an OpenCL device with its own memory (a GPU,
 * opened): its global memory and largest buffer in *global_mem and
 * *max_alloc (CL_DEVICE_GLOBAL_MEM_SIZE, CL_DEVICE_MAX_MEM_ALLOC_SIZE). */
int ss_ocl_own_memory(const ss_ctx *ctx, double *global_mem, double *max_alloc);
/* The bytes a device's batch of directions' buffers, and its cells'
 * buffers, may take: the memory plan's, else (no plan made) a quarter of
 * global_mem each. */
double ss_memory_device_bytes(const ss_ctx *ctx, double global_mem);
double ss_memory_device_cells_bytes(const ss_ctx *ctx, double global_mem);
/* The planner (memory_plan.c) on a context or none (NULL: no device): the
 * bytes the process holds with bands of rows rows (the grid's height:
 * whole), and the band rows for need's budget, its plan in *plan (or NULL). */
double ss_memory_planned(const ss_ctx *ctx, const ss_memory_need *need, int rows);
int ss_memory_plan_rows(const ss_ctx *ctx, const ss_memory_need *need, ss_memory_plan *plan);

struct ss_ctx {
    char message[2048];
    ss_progress_fn progress;
    void *progress_user;
    char device_spec[256];
    int use_reference; /* run the C twin instead of OpenCL */
    int device_auto;   /* "auto": each plan chooses device_spec */
    int batch;         /* directions per batch (ss_ctx_set_batch); 0: the device's choice */
    ss_cells_where cells; /* ss_ctx_set_cells */
    ss_memory_plan memory; /* the last ss_memory_plan_make's */
    struct ss_ocl *ocl;
    char device_name[600];
    ss_counters counters;
    volatile sig_atomic_t cancel_requested; /* ss_ctx_cancel; read by every worker */
    unsigned long failures; /* messages recorded: whether a callee said why it failed */
};

/* An OpenCL device as the planner weighs it (plan.c, doc/devices.md). */
typedef struct {
    char spec[16];  /* "P:D" */
    char name[520]; /* "platform: device" */
    int is_cpu;
    int compute_units; /* CL_DEVICE_MAX_COMPUTE_UNITS */
} ss_device_candidate;
/* Up to max of the OpenCL devices found (0 without a platform). */
int ss_opencl_devices(ss_device_candidate *out, int max);

/* Where a public call begins: the message of an earlier failure is gone
 * (ss_ctx_message is the last call's). */
static inline void ss_call_begin(ss_ctx *ctx)
{
    ctx->message[0] = '\0';
}

/* Records a one-line message (newlines become spaces) and returns status. */
ss_status ss_fail(ss_ctx *ctx, ss_status status, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Reports progress; returns SS_ERR_CANCELLED (with a message) if the
 * callback asks to stop or ss_ctx_cancel was called. */
ss_status ss_progress(ss_ctx *ctx, double complete, const char *what);

/* SS_ERR_CANCELLED (with a message naming what) once ss_ctx_cancel was
 * called, else SS_OK: for the places between progress reports. */
ss_status ss_check_cancel(ss_ctx *ctx, const char *what);

double ss_seconds_now(void);

/* The core's allocations (alloc.c), released with free(). */
void *ss_malloc(size_t bytes);
void *ss_calloc(size_t count, size_t size);
void *ss_realloc(void *p, size_t bytes);
/* Aligned allocation for grids shared with OpenCL (zero-copy on PoCL). */
void *ss_alloc_grid(size_t bytes);

/* Fault injection for the tests: the core's allocations so far, and making
 * the n-th allocation from now fail (once; n <= 0: none fails). */
long ss_fault_allocations(void);
void ss_fault_fail_allocation(long n);

#ifdef __cplusplus
}
#endif
#endif
