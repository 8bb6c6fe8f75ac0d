/* The context: last error message, progress callback, device choice and
 * work counters. */
#include "config.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "ctx_internal.h"

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

ss_status ss_fail(ss_ctx *ctx, ss_status status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(ctx->message, sizeof ctx->message, fmt, ap);
    va_end(ap);
    for (char *p = ctx->message; *p; ++p)
        if (*p == '\n' || *p == '\r')
            *p = ' ';
    ctx->failures++;
    return status;
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

ss_status ss_check_cancel(ss_ctx *ctx, const char *what)
{
    return ctx->cancel_requested
               ? ss_fail(ctx, SS_ERR_CANCELLED, "cancelled during %s", what ? what : "the run")
               : SS_OK;
}

ss_status ss_progress(ss_ctx *ctx, double complete, const char *what)
{
    ss_status st = ss_check_cancel(ctx, what);
    if (st != SS_OK)
        return st;
    if (ctx->progress && !ctx->progress(complete, what, ctx->progress_user))
        return ss_fail(ctx, SS_ERR_CANCELLED, "cancelled during %s", what ? what : "the run");
    return SS_OK;
}

double ss_seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
