/* Fuzz target: the ISO 8601 parsers (instants, durations, ranges) and the
 * instant formatter (src/core/iso_time.c). Beyond "no crash, no undefined
 * behaviour" it checks what the parsers promise:
 *   - a refusal is SS_ERR_ARGUMENT with a non-empty one-line message;
 *   - an accepted instant is finite and survives format -> parse to 1 us;
 *   - an accepted duration has non-negative, finite parts;
 *   - an accepted range is non-empty, has at most SS_TIME_RANGE_MAX_STEPS
 *     instants, and its count agrees with ss_time_range_at (the last
 *     instant lies before the end, the next one does not).
 * The input is the text (cut at 300 bytes; NUL ends it early, as in C). */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "skysweep_sun.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static void check_refusal(ss_ctx *ctx, ss_status st, const char *text)
{
    const char *m = ss_ctx_message(ctx);
    FUZZ_CHECK(st == SS_ERR_ARGUMENT, "status %d for '%s'", (int)st, text);
    FUZZ_CHECK(m[0] != '\0' && !strchr(m, '\n'), "message '%s' for '%s'", m, text);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static ss_ctx *ctx;
    if (!ctx)
        ctx = ss_ctx_new();
    char text[301];
    size_t n = size < 300 ? size : 300;
    memcpy(text, data, n);
    text[n] = '\0';

    double t = NAN;
    ss_status st = ss_parse_instant(ctx, text, &t);
    if (st != SS_OK) {
        check_refusal(ctx, st, text);
    } else {
        FUZZ_CHECK(isfinite(t), "instant '%s' -> %g", text, t);
        char buf[64];
        size_t len = ss_format_instant(t, buf, sizeof buf);
        FUZZ_CHECK(len < sizeof buf && strlen(buf) == len, "format of %.17g is %zu chars", t, len);
        if (fabs(t) < 9e12) {
            double back = NAN;
            st = ss_parse_instant(ctx, buf, &back);
            FUZZ_CHECK(st == SS_OK, "'%s' formats as '%s', which does not parse: %s", text, buf,
                       ss_ctx_message(ctx));
            double tol = 1e-6 + fabs(t) * 4e-16;
            FUZZ_CHECK(fabs(back - t) <= tol, "'%s' -> %.6f -> '%s' -> %.6f", text, t, buf, back);
        } else {
            FUZZ_CHECK(strcmp(buf, "invalid") == 0, "%.17g formats as '%s'", t, buf);
        }
    }

    ss_duration d;
    st = ss_parse_duration(ctx, text, &d);
    if (st != SS_OK)
        check_refusal(ctx, st, text);
    else
        FUZZ_CHECK(d.years >= 0 && d.months >= 0 && isfinite(d.seconds) && d.seconds >= 0 &&
                       (d.years || d.months || d.seconds >= 0),
                   "duration '%s' -> %lld y %lld m %g s", text, d.years, d.months, d.seconds);

    ss_time_range r;
    st = ss_parse_time_range(ctx, text, &r);
    if (st != SS_OK) {
        check_refusal(ctx, st, text);
        return 0;
    }
    FUZZ_CHECK(isfinite(r.start_unix_s) && isfinite(r.end_unix_s), "range '%s' not finite", text);
    FUZZ_CHECK(r.count >= 0 && r.count <= SS_TIME_RANGE_MAX_STEPS, "range '%s': %lld instants",
               text, r.count);
    if (r.count == 1 && !r.has_step) {
        FUZZ_CHECK(r.start_unix_s == r.end_unix_s, "single instant '%s' has an interval", text);
        return 0;
    }
    FUZZ_CHECK(r.end_unix_s > r.start_unix_s, "range '%s' is empty or reversed", text);
    if (!r.has_step) {
        FUZZ_CHECK(r.count == 0, "range '%s' without a step has %lld instants", text, r.count);
        return 0;
    }
    FUZZ_CHECK(r.count >= 1, "stepped range '%s' has no instants", text);
    double last = ss_time_range_at(&r, r.count - 1), next = ss_time_range_at(&r, r.count);
    FUZZ_CHECK(ss_time_range_at(&r, 0) == r.start_unix_s, "range '%s' does not start at start",
               text);
    FUZZ_CHECK(last < r.end_unix_s && !(next < r.end_unix_s),
               "range '%s': count %lld, instant %.6f / next %.6f vs end %.6f", text, r.count, last,
               next, r.end_unix_s);
    return 0;
}
