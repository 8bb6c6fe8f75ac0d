/* Fault injection over the public calls, SQLite style (doc/reliability.md): for
 * n = 1, 2, ... the n-th allocation of the core fails (src/core/alloc.c),
 * until a run makes fewer than n. Every such run must return SS_ERR_MEMORY
 * (or SS_OK with the undisturbed answer, where the failure is one the call
 * can do without), and the same context must then give the undisturbed
 * answer: nothing half-built is kept. Leaks are LeakSanitizer's to find
 * (the sanitizer build runs this). The same over the progress callback
 * returning "stop" at its k-th call (SS_ERR_CANCELLED), over ss_ctx_cancel
 * from another thread, and over device set-ups that fail (a device that
 * does not exist, kernels that do not build). */
#include "config.h"

#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "ctx_internal.h"
#include "tap.h"
#include "testlib.h"

#define W 26
#define H 21
#define CELLS ((size_t)W * H)
#define OUT_MAX (5 * CELLS)

static ss_grid grid;
static ss_sweep_options opt;

/* A call under test: writes its outputs (up to OUT_MAX floats) into out. */
typedef ss_status (*call_fn)(ss_ctx *ctx, float *out);

static ss_status call_svf(ss_ctx *ctx, float *out)
{
    ss_status st = ss_svf(ctx, &grid, &opt, SS_SVF_DEF_GEOMETRIC, out);
    if (st == SS_OK)
        st = ss_svf(ctx, &grid, &opt, SS_SVF_DEF_RADIATIVE, out + CELLS);
    return st == SS_OK ? ss_svf_within(ctx, &grid, &opt, SS_SVF_DEF_HORIZONTAL, 200.0,
                                       out + 2 * CELLS)
                       : st;
}

static ss_status call_openness(ss_ctx *ctx, float *out)
{
    ss_status st = ss_openness(ctx, &grid, &opt, 0, 0.0, out);
    return st == SS_OK ? ss_openness(ctx, &grid, &opt, 1, 0.0, out + CELLS) : st;
}

typedef struct {
    float *out;
    int n;
} horizon_copy;

static int keep_horizon(int index, double azimuth_deg, const float *angle_deg,
                        const float *dist_m, const float *cast_height_m, void *user)
{
    (void)azimuth_deg;
    horizon_copy *h = user;
    if (index < 1) { /* the first direction's three grids */
        memcpy(h->out, angle_deg, CELLS * sizeof(float));
        memcpy(h->out + CELLS, dist_m, CELLS * sizeof(float));
        memcpy(h->out + 2 * CELLS, cast_height_m, CELLS * sizeof(float));
    }
    h->n++;
    return 1;
}

static ss_status call_horizon(ss_ctx *ctx, float *out)
{
    horizon_copy h = {out, 0};
    return ss_horizon(ctx, &grid, &opt, SS_HORIZON_DISTANCE | SS_HORIZON_CAST_HEIGHT,
                      keep_horizon, &h);
}

static ss_status call_shadow(ss_ctx *ctx, float *out)
{
    return ss_cast_shadow(ctx, &grid, &opt, 123.0, 12.0, NULL, out, out + CELLS);
}

static ss_status call_vat(ss_ctx *ctx, float *out)
{
    return ss_vat(ctx, &grid, &opt, 0.0, out);
}

static ss_status call_hillshade(ss_ctx *ctx, float *out)
{
    return ss_hillshade(ctx, &grid, 315.0, 45.0, 1.0, 0, 0, out);
}

static ss_status one_sun(ss_ctx *ctx, int index, ss_sun_step *step, void *user)
{
    (void)ctx;
    (void)user;
    memset(step, 0, sizeof *step);
    step->duration_h = 1.0;
    step->linke = 3.0;
    step->extraterrestrial_w_m2 = 1361.0;
    step->azimuth_deg = step->grid_azimuth_deg = 90.0 + 40.0 * index;
    step->elevation_deg = 10.0 + 15.0 * index;
    step->apparent_elevation_deg = step->elevation_deg + 0.1;
    return SS_OK;
}

static ss_status sun_rows(ss_ctx *ctx, int index, int row0, int n_rows, ss_sun_step *step,
                          void *user)
{
    (void)row0;
    (void)n_rows;
    return one_sun(ctx, index, step, user);
}

static ss_status insolation_mode(ss_ctx *ctx, float *out, ss_shadow_mode mode)
{
    ss_insolation_options io = {.albedo = 0.2, .shadow_mode = mode};
    ss_insolation_out o = {.global = out,
                           .beam = out + CELLS,
                           .diffuse = out + 2 * CELLS,
                           .reflected = out + 3 * CELLS,
                           .sun_hours = out + 4 * CELLS};
    return ss_insolation(ctx, &grid, &opt, &io, 3, one_sun, NULL, NULL, NULL, &o);
}

static ss_status call_insolation(ss_ctx *ctx, float *out)
{
    return insolation_mode(ctx, out, SS_SHADOW_EXACT);
}

static ss_status call_insolation_interpolated(ss_ctx *ctx, float *out)
{
    return insolation_mode(ctx, out, SS_SHADOW_INTERPOLATED);
}

/* ---- calls in bands: rows read from and written into the whole grid --- */

static ss_status read_rows(void *user, int row0, int n_rows, float *z)
{
    (void)user;
    memcpy(z, grid.z + (size_t)row0 * W, (size_t)n_rows * W * sizeof(float));
    return SS_OK;
}

/* Output o's band `index` (0: the first) goes to out + o * CELLS, the
 * others are dropped; horizons keep direction 2. */
typedef struct {
    float *out;
    int index;
} rows_into;

static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    rows_into *r = user;
    if (index == r->index && output * CELLS + (size_t)H * W <= OUT_MAX)
        memcpy(r->out + output * CELLS + (size_t)row0 * W, values,
               (size_t)n_rows * W * sizeof(float));
    return SS_OK;
}

static ss_status call_sky_banded(ss_ctx *ctx, float *out)
{
    ss_source src = test_source(&grid, read_rows, NULL, 5, NULL);
    rows_into r = {out, 0};
    return ss_sky_rows(ctx, &src, &opt, SS_SKY_SVF_GEOMETRIC, 0.0, NULL, write_rows, &r);
}

static ss_status call_horizon_banded(ss_ctx *ctx, float *out)
{
    ss_source src = test_source(&grid, read_rows, NULL, 4, NULL);
    rows_into r = {out, 2};
    return ss_horizon_rows(ctx, &src, &opt, SS_HORIZON_DISTANCE, write_rows, &r);
}

static ss_status call_insolation_banded(ss_ctx *ctx, float *out)
{
    ss_source src = test_source(&grid, read_rows, NULL, 6, NULL);
    ss_insolation_options o = {.albedo = 0.2, .shadow_mode = SS_SHADOW_EXACT};
    rows_into r = {out, 0};
    return ss_insolation_rows(ctx, &src, &opt, &o, 3, sun_rows, NULL, 0, NULL, write_rows, &r);
}

/* Crowns 3 m tall on every fifth cell: the crown sweep's union grows. */
static ss_status call_canopy(ss_ctx *ctx, float *out)
{
    float height[CELLS];
    unsigned char crossed[CELLS];
    for (size_t i = 0; i < CELLS; ++i)
        height[i] = i % 5 == 0 ? 3.0f : 0.0f;
    ss_canopy canopy = {height, NULL, 0.25, 0.03};
    ss_status st = ss_canopy_crossed(ctx, &grid, &canopy, NULL, 123.0, 12.0, crossed);
    for (size_t i = 0; st == SS_OK && i < CELLS; ++i)
        out[i] = crossed[i];
    return st;
}

typedef struct {
    const char *name;
    call_fn fn;
} call_case;

static const call_case cases[] = {
    {"ss_svf and ss_svf_within", call_svf},
    {"ss_openness", call_openness},
    {"ss_horizon", call_horizon},
    {"ss_cast_shadow", call_shadow},
    {"ss_canopy_crossed", call_canopy},
    {"ss_vat", call_vat},
    {"ss_hillshade", call_hillshade},
    {"ss_insolation", call_insolation},
    {"ss_insolation (interpolated)", call_insolation_interpolated},
    {"ss_sky_rows in bands", call_sky_banded},
    {"ss_horizon_rows in bands", call_horizon_banded},
    {"ss_insolation_rows in bands", call_insolation_banded},
};
#define N_CASES (sizeof cases / sizeof cases[0])

static int same(const float *a, const float *b, double tol)
{
    for (size_t i = 0; i < OUT_MAX; ++i)
        if (!(fabs((double)a[i] - (double)b[i]) <= tol * (1.0 + fabs((double)b[i]))) &&
            !(isnan(a[i]) && isnan(b[i])))
            return 0;
    return 1;
}

/* Runs fn on a new context for device into out (NAN first). */
static ss_status run_fresh(const char *device, call_fn fn, float *out, ss_ctx **keep)
{
    for (size_t i = 0; i < OUT_MAX; ++i)
        out[i] = NAN;
    ss_ctx *ctx = ss_ctx_new();
    if (!ctx)
        return SS_ERR_MEMORY;
    ss_ctx_use_device(ctx, device);
    ss_status st = fn(ctx, out);
    if (keep)
        *keep = ctx;
    else
        ss_ctx_free(ctx);
    return st;
}

static long total_points, total_calls, total_stops;

/* Fails allocation n = 1, 2, ... of one call until it makes fewer. */
static void inject_allocations(const char *device, const call_case *c, const float *want)
{
    float *out = malloc(OUT_MAX * sizeof(float));
    int points = 0, wrong_status = 0, not_recovered = 0;
    for (long n = 1; n < 100000; ++n) {
        ss_ctx *ctx = NULL;
        long before = ss_fault_allocations();
        ss_fault_fail_allocation(n);
        for (size_t i = 0; i < OUT_MAX; ++i)
            out[i] = NAN;
        ctx = ss_ctx_new();
        ss_status st = SS_ERR_MEMORY;
        if (ctx) {
            ss_ctx_use_device(ctx, device);
            st = c->fn(ctx, out);
        }
        int reached = ss_fault_allocations() - before >= n;
        ss_fault_fail_allocation(0);
        if (!reached) {
            ss_ctx_free(ctx);
            break;
        }
        points++;
        if (st != SS_ERR_MEMORY && !(st == SS_OK && same(out, want, 1e-5))) {
            wrong_status++;
            tap_diag("%s: allocation %ld failing gave status %d: %s", c->name, n, (int)st,
                     ctx ? ss_ctx_message(ctx) : "");
        }
        if (ctx) {
            /* The same context, nothing failing: the undisturbed answer. */
            for (size_t i = 0; i < OUT_MAX; ++i)
                out[i] = NAN;
            if (c->fn(ctx, out) != SS_OK || !same(out, want, 1e-5))
                not_recovered++;
            ss_ctx_free(ctx);
        }
    }
    total_points += points;
    total_calls++;
    tap_ok(points > 0 && wrong_status == 0 && not_recovered == 0,
           "%s on %s: %d allocations failed in turn, %d gave another status than "
           "SS_ERR_MEMORY, %d left the context unable to give the right answer",
           c->name, device ? device : "the default device", points, wrong_status,
           not_recovered);
    free(out);
}

typedef struct {
    int stop_at, calls;
} stopper;

static int stop_at_call(double complete, const char *message, void *user)
{
    (void)complete;
    (void)message;
    stopper *s = user;
    return ++s->calls != s->stop_at;
}

/* Stops the run at the progress callback's k-th call, k = 1, 2, ... */
static void inject_cancels(const char *device, const call_case *c, const float *want)
{
    float *out = malloc(OUT_MAX * sizeof(float));
    int points = 0, wrong = 0;
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, device);
    for (int k = 1; k < 100000; ++k) {
        stopper s = {k, 0};
        ss_ctx_set_progress(ctx, stop_at_call, &s);
        ss_status st = c->fn(ctx, out);
        if (s.calls < k) { /* ran to the end without reaching call k */
            wrong += st != SS_OK;
            break;
        }
        points++;
        wrong += st != SS_ERR_CANCELLED || strstr(ss_ctx_message(ctx), "cancel") == NULL;
    }
    total_stops += points;
    ss_ctx_set_progress(ctx, NULL, NULL);
    for (size_t i = 0; i < OUT_MAX; ++i)
        out[i] = NAN;
    ss_status st = c->fn(ctx, out);
    /* A call without progress reports (a single pass) has no point to stop at. */
    tap_ok(wrong == 0 && st == SS_OK && same(out, want, 1e-5),
           "%s on %s: stopped at each of its %d progress calls, %d runs gave another status "
           "than SS_ERR_CANCELLED; then the same context gives the right answer (%d)",
           c->name, device ? device : "the default device", points, wrong, (int)st);
    ss_ctx_free(ctx);
    free(out);
}

/* ---- ss_ctx_cancel from another thread during a long sweep ------------- */

typedef struct {
    ss_ctx *ctx;
    double delay_s;
} canceller;

static void *cancel_later(void *arg)
{
    canceller *c = arg;
    struct timespec ts = {0, (long)(c->delay_s * 1e9)};
    nanosleep(&ts, NULL);
    ss_ctx_cancel(c->ctx);
    return NULL;
}

static void cancel_from_thread(const char *device)
{
    ss_grid big = test_grid(700, 700, 10.0, 10.0);
    test_fill(&big, TERRAIN_SMOOTH, 11, 300.0);
    ss_sweep_options o;
    ss_sweep_options_default(&o);
    o.directions = 100000; /* minutes of work */
    float *out = malloc((size_t)700 * 700 * sizeof(float));
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, device);
    canceller c = {ctx, 0.5};
    pthread_t t;
    pthread_create(&t, NULL, cancel_later, &c);
    double t0 = ss_seconds_now();
    ss_status st = ss_svf(ctx, &big, &o, SS_SVF_DEF_GEOMETRIC, out);
    double took = ss_seconds_now() - t0;
    pthread_join(t, NULL);
    tap_ok(st == SS_ERR_CANCELLED && took < 1.5,
           "ss_ctx_cancel from another thread 0.5 s into 100000 directions on %s: status %d "
           "after %.2f s (want %d within 1.5 s)",
           device ? device : "the default device", (int)st, took, (int)SS_ERR_CANCELLED);
    ss_status again = ss_svf(ctx, &grid, &opt, SS_SVF_DEF_GEOMETRIC, out);
    ss_ctx_cancel_clear(ctx);
    ss_status cleared = ss_svf(ctx, &grid, &opt, SS_SVF_DEF_GEOMETRIC, out);
    tap_ok(again == SS_ERR_CANCELLED && cleared == SS_OK,
           "a cancelled context refuses the next call (%d) until ss_ctx_cancel_clear (%d)",
           (int)again, (int)cleared);
    ss_ctx_free(ctx);
    free(out);
    ss_grid_free(&big);
}

/* ---- a cancel during the device's first kernel build ------------------- */

/* main() points PoCL at an empty cache folder before anything opens a
 * device, so this first build compiles the kernels: seconds here, which
 * clBuildProgram cannot be interrupted in. The call must not wait for it,
 * and the same context must then build again and compute. */
static void cancel_during_first_build(void)
{
    if (!test_have_pocl()) {
        tap_skip("a cancel during PoCL's first kernel build", "no PoCL device");
        return;
    }
    ss_ctx *ctx = ss_ctx_new();
    float *out = malloc(OUT_MAX * sizeof(float)), *want = malloc(OUT_MAX * sizeof(float));
    ss_ctx_use_device(ctx, "reference");
    ss_status ref = call_svf(ctx, want);
    ss_ctx_use_device(ctx, "Portable");
    canceller c = {ctx, 0.3};
    pthread_t t;
    pthread_create(&t, NULL, cancel_later, &c);
    double t0 = ss_seconds_now();
    ss_status st = call_svf(ctx, out);
    double took = ss_seconds_now() - t0;
    pthread_join(t, NULL);
    char message[200];
    snprintf(message, sizeof message, "%s", ss_ctx_message(ctx));
    ss_ctx_cancel_clear(ctx);
    t0 = ss_seconds_now();
    ss_status again = call_svf(ctx, out);
    double took_again = ss_seconds_now() - t0;
    if (st == SS_OK && took < 0.3)
        tap_skip("a cancel during PoCL's first kernel build",
                 "the build and the run ended before the cancel came");
    else
        tap_ok(ref == SS_OK && st == SS_ERR_CANCELLED && strstr(message, "kernel build") &&
                   took < 1.0 && again == SS_OK && same(out, want, 1e-4),
               "cancelled 0.3 s into PoCL's first kernel build: status %d (%s) after %.2f s "
               "(want %d within 1 s); then the same context builds and computes in %.2f s (%d)",
               (int)st, message, took, (int)SS_ERR_CANCELLED, took_again, (int)again);
    ss_ctx_free(ctx);
    free(out);
    free(want);
}

/* ---- device set-ups that fail, then the same context ------------------- */

static void failed_device_setups(const float *want_svf, int have_opencl)
{
    float *out = malloc(OUT_MAX * sizeof(float));
    for (size_t i = 0; i < OUT_MAX; ++i)
        out[i] = NAN;
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "no such device anywhere");
    ss_status bad = call_svf(ctx, out), bad_again = call_svf(ctx, out);
    ss_ctx_use_device(ctx, "reference");
    ss_status good = call_svf(ctx, out);
    tap_ok(bad == SS_ERR_DEVICE && bad_again == SS_ERR_DEVICE && good == SS_OK &&
               same(out, want_svf, 1e-4),
           "a device that does not exist fails twice alike (%d, %d: %s), then the same "
           "context on the C twin gives the right answer (%d)",
           (int)bad, (int)bad_again, ss_ctx_message(ctx), (int)good);
    ss_ctx_free(ctx);
    if (!have_opencl) {
        tap_skip("kernels that fail to build, then the same context", "no OpenCL device");
        free(out);
        return;
    }
    /* PoCL adds POCL_EXTRA_BUILD_FLAGS to each build; defining the guard of
     * kernels/ss_compat.h empties it, so the kernels do not compile (in a
     * fresh cache folder, so nothing cached is reused). */
    char cache[] = "/tmp/ss-fault-cache.XXXXXX";
    if (!mkdtemp(cache)) {
        tap_skip("kernels that fail to build, then the same context", "no temporary folder");
        free(out);
        return;
    }
    setenv("POCL_CACHE_DIR", cache, 1);
    setenv("POCL_EXTRA_BUILD_FLAGS", "-DSS_COMPAT_H", 1);
    ctx = ss_ctx_new();
    ss_status broken = call_svf(ctx, out), broken_again = call_svf(ctx, out);
    unsetenv("POCL_EXTRA_BUILD_FLAGS");
    ss_ctx_use_device(ctx, "reference");
    ss_status fixed = call_svf(ctx, out);
    /* PoCL reads POCL_EXTRA_BUILD_FLAGS once: the platform stays broken in
     * this process, and each call on it must say so again, never succeed
     * with no kernels. */
    tap_ok(broken == SS_ERR_DEVICE && broken_again == SS_ERR_DEVICE && fixed == SS_OK &&
               same(out, want_svf, 1e-4),
           "kernels that fail to build: %d, and again %d (%.80s), then the same context on the "
           "C twin gives the right answer (%d)",
           (int)broken, (int)broken_again, ss_ctx_message(ctx), (int)fixed);
    ss_ctx_free(ctx);
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", cache);
    if (system(cmd) != 0)
        tap_diag("could not remove %s", cache);
    free(out);
}

int main(void)
{
    char first_cache[] = "/tmp/ss-first-build.XXXXXX";
    int fresh_cache = mkdtemp(first_cache) != NULL;
    if (fresh_cache)
        setenv("POCL_CACHE_DIR", first_cache, 1);
    grid = test_grid(W, H, 20.0, 20.0);
    test_fill(&grid, TERRAIN_SMOOTH, 7, 150.0);
    test_holes(&grid, 3, 2, 4);
    ss_sweep_options_default(&opt);
    opt.directions = 6;

    if (fresh_cache)
        cancel_during_first_build();
    else
        tap_skip("a cancel during PoCL's first kernel build", "no temporary folder");
    float *want = malloc(N_CASES * OUT_MAX * sizeof(float));
    ss_ctx *probe = ss_ctx_new();
    int have_opencl = strcmp(ss_ctx_device_name(probe), "(no device)") != 0 &&
                      strncmp(ss_ctx_device_name(probe), "C reference", 11) != 0;
    ss_ctx_free(probe);
    const char *devices[2] = {"reference", NULL};
    for (int d = 0; d < 2; ++d) {
        if (d == 1 && !have_opencl) {
            tap_skip("fault injection on the default OpenCL device", "no OpenCL device");
            continue;
        }
        for (size_t i = 0; i < N_CASES; ++i) {
            float *w = want + i * OUT_MAX;
            ss_status st = run_fresh(devices[d], cases[i].fn, w, NULL);
            if (!tap_ok(st == SS_OK, "%s runs undisturbed (%d)", cases[i].name, (int)st))
                continue;
            inject_allocations(devices[d], &cases[i], w);
            inject_cancels(devices[d], &cases[i], w);
        }
        cancel_from_thread(devices[d]);
    }
    tap_diag("fault injection: %ld calls x allocations failed in turn = %ld failure points; "
             "%ld progress stops",
             total_calls, total_points, total_stops);
    failed_device_setups(want, have_opencl);
    if (fresh_cache) {
        char cmd[128];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", first_cache);
        if (system(cmd) != 0)
            tap_diag("could not remove %s", first_cache);
    }
    free(want);
    ss_grid_free(&grid);
    return tap_done();
}
