/* Fuzz target: the weather file readers (src/adapt/weather_read.c). The
 * input is the file; it is written to a private temporary folder and read
 * as `skysweep weather` and `insolation --weather` would. Checked: a
 * refusal is SS_ERR_INPUT or SS_ERR_MEMORY with a one-line message naming
 * the file; a read file has records whose times are finite, durations in
 * (0, 24] hours and irradiance finite within its range or NAN. */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "weather.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int irradiance_ok(float v)
{
    return isnan(v) || (v >= -100.0f && v <= 2000.0f);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 200000)
        return 0;
    const char *path = fuzz_input_file("weather", data, size);
    ss_ctx *ctx = ss_ctx_new();
    if (!ctx)
        abort();
    ss_weather w;
    ss_status st = ss_weather_read(ctx, path, NAN, &w);
    if (st != SS_OK) {
        const char *m = ss_ctx_message(ctx);
        FUZZ_CHECK(st == SS_ERR_INPUT || st == SS_ERR_MEMORY, "status %d: %s", st, m);
        FUZZ_CHECK(m[0] && !strchr(m, '\n') && strstr(m, path), "message '%s'", m);
        FUZZ_CHECK(w.records == NULL && w.n == 0, "a refusal kept %zu records", w.n);
    } else {
        FUZZ_CHECK(w.n > 0 && w.records && w.format_name && w.stamps[0], "%zu records", w.n);
        for (size_t i = 0; i < w.n; ++i) {
            const ss_weather_record *r = &w.records[i];
            FUZZ_CHECK(isfinite(r->stamp_unix_s) && isfinite(r->sun_unix_s) &&
                           fabs(r->sun_unix_s - r->stamp_unix_s) <= 2 * 86400.0,
                       "record %zu: stamp %g, sun %g", i, r->stamp_unix_s, r->sun_unix_s);
            FUZZ_CHECK(r->duration_h > 0 && r->duration_h <= 24, "record %zu: %g h", i,
                       r->duration_h);
            FUZZ_CHECK(irradiance_ok(r->ghi) && irradiance_ok(r->dni) && irradiance_ok(r->dhi),
                       "record %zu: %g %g %g", i, r->ghi, r->dni, r->dhi);
            FUZZ_CHECK(isnan(r->albedo) || (r->albedo > 0 && r->albedo <= 1), "albedo %g",
                       r->albedo);
        }
        ss_weather_free(&w);
    }
    ss_ctx_free(ctx);
    return 0;
}
