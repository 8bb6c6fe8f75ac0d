/* ss-bench: times the SVF sweep (the one driver, ss_sky_rows) against the
 * bare pass over the same lines, on a raw float32 grid or a synthetic one.
 * It links only the core library and OpenCL (no GDAL), so it also runs on
 * machines that have nothing else, such as a lent GPU machine
 * (reference/toolchain.md).
 *
 *   ss-bench [--raw FILE WIDTH HEIGHT] [--synthetic N] [--cell METRES]
 *            [--directions D] [--device SPEC] [--lines interpolated|digital]
 *            [--offset DEG] [--reps R] [--batch B] [--band-rows R]
 *
 * Prints one line per measurement: cell-directions per second of the bare
 * pass (one launch per direction) and of the SVF sweep (batches of B
 * directions, 0: the device's choice; in bands of R rows, 0: the whole
 * grid), medians over R repetitions, their ratio, the kernel build time and
 * the peak resident memory. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <time.h>

#include "products_internal.h"

typedef struct {
    const char *raw_path;
    int width, height;
    int synthetic;
    double cell_m;
    int directions;
    const char *device;
    int lines;
    int reps;
    double offset_deg;
    int batch, band_rows;
} bench_args;

static int parse(int argc, char **argv, bench_args *a)
{
    *a = (bench_args){NULL, 0, 0, 1024, 30.0, 16, NULL, SS_LINES_INTERPOLATED, 5, 0.0, 0, 0};
    for (int i = 1; i < argc; ++i) {
        const char *o = argv[i];
        int more = argc - i - 1;
        if (!strcmp(o, "--raw") && more >= 3) {
            a->raw_path = argv[++i];
            a->width = atoi(argv[++i]);
            a->height = atoi(argv[++i]);
        } else if (!strcmp(o, "--synthetic") && more >= 1) {
            a->synthetic = atoi(argv[++i]);
        } else if (!strcmp(o, "--cell") && more >= 1) {
            a->cell_m = atof(argv[++i]);
        } else if (!strcmp(o, "--directions") && more >= 1) {
            a->directions = atoi(argv[++i]);
        } else if (!strcmp(o, "--device") && more >= 1) {
            a->device = argv[++i];
        } else if (!strcmp(o, "--lines") && more >= 1) {
            a->lines = strcmp(argv[++i], "digital") == 0 ? SS_LINES_DIGITAL
                                                        : SS_LINES_INTERPOLATED;
        } else if (!strcmp(o, "--offset") && more >= 1) {
            a->offset_deg = atof(argv[++i]);
        } else if (!strcmp(o, "--batch") && more >= 1) {
            a->batch = atoi(argv[++i]);
        } else if (!strcmp(o, "--band-rows") && more >= 1) {
            a->band_rows = atoi(argv[++i]);
        } else if (!strcmp(o, "--reps") && more >= 1) {
            a->reps = atoi(argv[++i]);
        } else {
            fprintf(stderr, "ss-bench: bad argument '%s' (see the comment in ss_bench.c)\n", o);
            return -1;
        }
    }
    if (a->directions < 1 || a->reps < 1 || (!a->raw_path && a->synthetic < 2)) {
        fprintf(stderr, "ss-bench: directions, reps >= 1 and a grid are needed\n");
        return -1;
    }
    return 0;
}

/* Rolling hills with a few sharp ridges: hulls of realistic size. */
static void synthetic_terrain(ss_grid *g)
{
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            double x = c * g->cell_x_m, y = r * g->cell_y_m;
            double z = 400 * sin(x / 3100.0) * cos(y / 2700.0) + 150 * sin((x + 2 * y) / 900.0) +
                       40 * fabs(sin(x / 230.0 + y / 410.0));
            g->z[(size_t)r * g->width + c] = (float)z;
        }
}

static int load_grid(ss_ctx *ctx, const bench_args *a, ss_grid *g)
{
    int w = a->raw_path ? a->width : a->synthetic, h = a->raw_path ? a->height : a->synthetic;
    if (ss_grid_alloc(ctx, g, w, h, a->cell_m, a->cell_m) != SS_OK)
        return -1;
    if (!a->raw_path) {
        synthetic_terrain(g);
        return 0;
    }
    FILE *f = fopen(a->raw_path, "rb");
    size_t n = (size_t)w * h;
    size_t got = f ? fread(g->z, sizeof(float), n, f) : 0;
    if (f)
        fclose(f);
    if (got != n) {
        fprintf(stderr, "ss-bench: cannot read %zu floats from %s\n", n, a->raw_path);
        return -1;
    }
    /* Nodata in raw grids is written as a huge negative value or NaN. */
    for (size_t i = 0; i < n; ++i)
        if (!(g->z[i] > -1e30f))
            g->z[i] = NAN;
    return 0;
}

static int cmp_double(const void *x, const void *y)
{
    double a = *(const double *)x, b = *(const double *)y;
    return (a > b) - (a < b);
}

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static ss_status keep_nothing(void *user, int output, int index, int row0, int n_rows,
                               const float *values)
{
    (void)user, (void)output, (void)index, (void)row0, (void)n_rows, (void)values;
    return SS_OK;
}

/* One run of every direction: the bare pass (a launch per direction, on a
 * backend of its own b) or the SVF sweep through the driver. */
static ss_status run_once(ss_ctx *ctx, ss_backend *b, const ss_grid *g,
                          const ss_sweep_options *opt, int bare, int band_rows)
{
    if (!bare) {
        ss_source src = ss_source_of_grid(g);
        src.band_rows = band_rows;
        return ss_sky_rows(ctx, &src, opt, SS_SKY_SVF_GEOMETRIC, 0.0, NULL, keep_nothing, NULL);
    }
    ss_band_run run = {.row1 = g->height,
                       .held_rows = g->height,
                       .height = g->height,
                       .width = g->width,
                       .whole = 1};
    ss_status st = b->ops->load(b, &run, g->z, NULL);
    for (int i = 0; i < opt->directions && st == SS_OK; ++i) {
        ss_band_dir d = {0};
        ss_product_lines(g, opt, i, &d.ls);
        float *out;
        st = b->ops->bare(b, &run, &d, &out);
    }
    return st;
}

/* Median wall seconds of `reps` runs of all directions of one pass kind;
 * *cpu gets the median process CPU seconds (all threads), which a busy
 * machine disturbs much less than wall time. */
static double time_pass(ss_ctx *ctx, ss_backend *b, const ss_grid *g, const ss_sweep_options *opt,
                        int bare, int band_rows, int reps, double *cpu)
{
    double *t = malloc(sizeof(double) * reps), *c = malloc(sizeof(double) * reps);
    for (int r = 0; r < reps; ++r) {
        double t0 = ss_seconds_now(), c0 = cpu_seconds();
        if (run_once(ctx, b, g, opt, bare, band_rows) != SS_OK)
            fprintf(stderr, "ss-bench: %s\n", ss_ctx_message(ctx));
        t[r] = ss_seconds_now() - t0;
        c[r] = cpu_seconds() - c0;
    }
    qsort(t, reps, sizeof *t, cmp_double);
    qsort(c, reps, sizeof *c, cmp_double);
    double median = t[reps / 2];
    if (cpu)
        *cpu = c[reps / 2];
    free(t);
    free(c);
    return median;
}

int main(int argc, char **argv)
{
    bench_args a;
    if (parse(argc, argv, &a) != 0)
        return 2;
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, a.device);
    ss_grid g;
    if (load_grid(ctx, &a, &g) != 0)
        return 3;
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = a.directions;
    opt.lines = a.lines;
    opt.offset_deg = a.offset_deg;
    ss_ctx_set_batch(ctx, a.batch);
    ss_backend b = {.ctx = ctx,
                    .walk = {.term = SS_SVF_GEOMETRIC},
                    .width = g.width,
                    .max_held_rows = g.height,
                    .batch = 1,
                    .whole_z = g.z};
    double t0 = ss_seconds_now();
    if (ss_backend_open(&b) != SS_OK) {
        fprintf(stderr, "ss-bench: %s\n", ss_ctx_message(ctx));
        return 5;
    }
    double open_s = ss_seconds_now() - t0;
    /* One untimed round warms caches, page mappings and the first launch. */
    time_pass(ctx, &b, &g, &opt, 0, a.band_rows, 1, NULL);
    double bare_cpu, sweep_cpu;
    double bare = time_pass(ctx, &b, &g, &opt, 1, 0, a.reps, &bare_cpu);
    double sweep = time_pass(ctx, &b, &g, &opt, 0, a.band_rows, a.reps, &sweep_cpu);
    b.ops->close(&b);
    double cd = (double)g.width * g.height * a.directions;
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    printf("device    %s\n", ss_ctx_device_name(ctx));
    printf("grid      %d x %d, %d directions, %s lines, median of %d\n", g.width, g.height,
           a.directions, a.lines == SS_LINES_DIGITAL ? "digital" : "interpolated", a.reps);
    if (a.band_rows > 0 || a.batch > 0)
        printf("driver    bands of %d rows, batches of %d directions (0: whole grid; the "
               "device's choice)\n",
               a.band_rows, a.batch);
    printf("build     %.3f s (device open %.3f s)\n", ss_ctx_counters(ctx).build_seconds, open_s);
    printf("bare      %.4f s  %7.1f M cell-directions/s  %.2f us/direction  (cpu %.4f s)\n",
           bare, cd / bare / 1e6, bare / a.directions * 1e6, bare_cpu);
    printf("sweep     %.4f s  %7.1f M cell-directions/s  %.2f us/direction  (cpu %.4f s)\n",
           sweep, cd / sweep / 1e6, sweep / a.directions * 1e6, sweep_cpu);
    printf("ratio     %.2f wall, %.2f cpu (sweep / bare pass)\n", sweep / bare,
           sweep_cpu / bare_cpu);
    printf("peak RSS  %.1f MB (grid %.1f MB)\n", ru.ru_maxrss / 1024.0,
           (double)g.width * g.height * 4 / 1048576.0);
    ss_grid_free(&g);
    ss_ctx_free(ctx);
    return 0;
}
