/* Test Anything Protocol output for automake's TAP driver (build-aux/
 * tap-driver.sh), which does the harness work: counting, logs, summary.
 * cmocka 1.1's TAP mode marks skips "not ok # SKIP", which that driver
 * counts as failures, hence these few lines. */
#ifndef SS_TAP_H
#define SS_TAP_H

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

static int tap_count = 0, tap_failed = 0;

static inline int tap_ok(int pass, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static inline int tap_ok(int pass, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    printf("%s %d - ", pass ? "ok" : "not ok", ++tap_count);
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
    fflush(stdout);
    if (!pass)
        tap_failed++;
    return pass;
}

static inline void tap_skip(const char *what, const char *why)
{
    printf("ok %d - %s # SKIP %s\n", ++tap_count, what, why);
    fflush(stdout);
}

static inline void tap_diag(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline void tap_diag(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    printf("# ");
    vprintf(fmt, ap);
    printf("\n");
    va_end(ap);
}

/* |got - want| <= tol, with the values in the message. */
static inline int tap_close(double got, double want, double tol, const char *what)
{
    int pass = isfinite(got) && fabs(got - want) <= tol;
    return tap_ok(pass, "%s: got %.9g, want %.9g +- %.3g", what, got, want, tol);
}

static inline int tap_done(void)
{
    printf("1..%d\n", tap_count);
    return tap_failed ? 1 : 0;
}

#endif
