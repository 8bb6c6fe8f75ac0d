/* What every core file does with a context while it works: fail with a
 * message, check for cancellation, report progress, read the clock. Kept
 * apart from ctx.c, whose public calls open devices (ocl_devices.c), so
 * that the device code can fail and report without calling back into it. */
#include "config.h"

#include <stdarg.h>
#include <stdio.h>
#include <time.h>

#include "ctx_internal.h"

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
