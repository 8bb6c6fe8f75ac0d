/* The context: last error message, progress callback, device choice and
 * work counters. */
#include "config.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "ctx_internal.h"

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

ss_status ss_ctx_apply_plan(ss_ctx *ctx, const ss_plan *plan)
{
    ss_call_begin(ctx);
    if (!ctx->device_auto || !plan->device[0] || strcmp(ctx->device_spec, plan->device) == 0)
        return SS_OK;
    select_device(ctx, plan->device);
    /* A device the model chose but that does not open leaves the job to the
     * C twin, which computes the same (the summary names the device used);
     * a run cancelled while the device's kernels build stops. */
    ss_status st = ctx->use_reference ? SS_OK : ss_ocl_acquire(ctx);
    if (st == SS_ERR_CANCELLED)
        return st;
    if (st != SS_OK)
        select_device(ctx, "reference");
    return SS_OK;
}

const char *ss_ctx_device_name(ss_ctx *ctx)
{
    if (!ctx->use_reference && !ctx->ocl && ss_ocl_acquire(ctx) != SS_OK) {
        ctx->device_name[0] = '\0';
        return "(no device)";
    }
    return ctx->device_name;
}

ss_ctx *ss_ctx_new(void)
{
    ss_ctx *ctx = ss_calloc(1, sizeof(ss_ctx));
    if (!ctx)
        return NULL;
    ss_ctx_use_device(ctx, NULL); /* the default, which SKYSWEEP_DEVICE may name */
    const char *cells = getenv("SKYSWEEP_CELLS"); /* ss_ctx_set_cells's default */
    ctx->cells = !cells                       ? SS_CELLS_AUTO
                 : strcmp(cells, "host") == 0   ? SS_CELLS_HOST
                 : strcmp(cells, "device") == 0 ? SS_CELLS_DEVICE
                                                : SS_CELLS_AUTO;
    return ctx;
}

void ss_ctx_free(ss_ctx *ctx)
{
    if (!ctx)
        return;
    ss_ocl_release(ctx->ocl);
    free(ctx);
}

const char *ss_ctx_message(const ss_ctx *ctx)
{
    return ctx->message;
}

void ss_ctx_set_progress(ss_ctx *ctx, ss_progress_fn fn, void *user)
{
    ctx->progress = fn;
    ctx->progress_user = user;
}

void ss_ctx_set_batch(ss_ctx *ctx, int directions)
{
    ctx->batch = directions > 0 ? directions : 0;
}

void ss_ctx_set_cells(ss_ctx *ctx, ss_cells_where where)
{
    ctx->cells = (unsigned)where <= SS_CELLS_DEVICE ? where : SS_CELLS_AUTO;
}

const char *ss_version(void)
{
    return PACKAGE_VERSION;
}

ss_counters ss_ctx_counters(const ss_ctx *ctx)
{
    return ctx->counters;
}

ss_status ss_ctx_error(ss_ctx *ctx, ss_status status, const char *fmt, ...)
{
    char line[sizeof ctx->message];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    return ss_fail(ctx, status, "%s", line);
}

void ss_ctx_cancel(ss_ctx *ctx)
{
    ctx->cancel_requested = 1;
}

void ss_ctx_cancel_clear(ss_ctx *ctx)
{
    ctx->cancel_requested = 0;
}
