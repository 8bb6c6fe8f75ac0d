/* What box lines cost and buy (doc/box_lines.md and the planner's table
 * src/core/box_lines_table.c, both written by `make box-lines`): for each
 * line model and number of box lines per cell, the share of cells whose
 * cast shadow agrees with the box-model ray march (tests/box_march.c) for
 * four suns off the grid axes, the mean and 95th percentile error of the
 * geometric SVF (16 directions) against the march's, and the wall time of
 * one cast shadow and of a 16-direction SVF on the C twin (medians), on a
 * synthetic city and on the Gothenburg 1 m DSM.
 *
 * usage: box_lines_driver [--table FILE] [DSM]
 * --table writes the box-line counts' SVF errors (p95, from 5 deg) as C. */
#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "box_march.h"
#include "dem_io.h"

static const double suns[][2] = {{117, 25}, {203, 40}, {251, 15}, {331, 30}};

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int by_value(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median wall time of `reps` runs of a shadow (svf = 0) or an SVF. */
static double seconds(const ss_grid *g, const ss_sweep_options *opt, int svf, int reps)
{
    size_t n = (size_t)g->width * g->height;
    float *out = malloc(n * sizeof(float));
    double t[9];
    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, "reference");
    for (int k = 0; k < reps; ++k) {
        double t0 = now();
        ss_status st = svf ? ss_svf(ctx, g, opt, SS_SVF_DEF_GEOMETRIC, out)
                           : ss_cast_shadow(ctx, g, opt, suns[0][0], suns[0][1], NULL, out, NULL);
        t[k] = st == SS_OK ? now() - t0 : NAN;
    }
    ss_ctx_free(ctx);
    free(out);
    qsort(t, (size_t)reps, sizeof *t, by_value);
    return t[reps / 2];
}

/* The box-line counts the planner's table covers (powers of two). */
static const int counts[] = {1, 2, 4, 8, 16, 32, 64};
#define N_COUNTS ((int)(sizeof counts / sizeof counts[0]))

typedef struct {
    char name[160];
    double p95[N_COUNTS]; /* geometric SVF error from 5 deg, 95th percentile */
} measured;

static void row(const char *lines, const char *per_cell, const ss_grid *g,
                const ss_sweep_options *opt, int svf, double *p95_turned)
{
    double mean = 0, worst = 1;
    char err[300] = "";
    for (int s = 0; s < 4; ++s) {
        double a = box_march_agreement(g, opt, suns[s][0], suns[s][1], err);
        mean += a / 4;
        worst = fmin(worst, a);
    }
    printf("| %s | %s | %.3f %% | %.3f %% ", lines, per_cell, 100 * mean, 100 * worst);
    if (svf) {
        ss_sweep_options turned = *opt;
        turned.offset_deg = 5;
        double p95;
        double from_0 = box_march_svf_error(g, opt, NULL, err);
        double from_5 = box_march_svf_error(g, &turned, &p95, err);
        printf("| %.4f | %.4f | %.4f | %.4f | %.3f |\n", from_0, from_5, p95,
               seconds(g, opt, 0, 5), seconds(g, opt, 1, 3));
        if (p95_turned)
            *p95_turned = p95;
    } else {
        printf("| - | - | - | %.4f | - |\n", seconds(g, opt, 0, 5));
    }
    if (err[0])
        fprintf(stderr, "box_lines_driver: %s\n", err);
}

static void table(const char *name, const ss_grid *g, measured *m)
{
    printf("\n### %s (%d x %d cells)\n\n", name, g->width, g->height);
    printf("| lines | per cell | shadows agree, mean of 4 suns | worst sun | SVF error, mean, "
           "from 0 deg | mean, from 5 deg | p95, from 5 deg | shadow, s | SVF 16 directions, s "
           "|\n"
           "|---|---|---|---|---|---|---|---|---|\n");
    ss_sweep_options opt;
    ss_sweep_options_default(&opt);
    opt.directions = 16;
    opt.lines = SS_LINES_INTERPOLATED;
    row("interpolated", "-", g, &opt, 1, NULL);
    opt.lines = SS_LINES_DIGITAL;
    row("digital", "-", g, &opt, 1, NULL);
    opt.lines = SS_LINES_BOX;
    /* The rows per count measure the families' walks, shadows and SVF. */
    opt.box_shadows = SS_BOX_SHADOWS_LINES;
    opt.box_sky = SS_BOX_SKY_LINES;
    for (int k = 0; k < N_COUNTS; ++k) {
        char per_cell[16];
        snprintf(per_cell, sizeof per_cell, "%d", counts[k]);
        opt.box_lines = counts[k];
        row("box", per_cell, g, &opt, 1, &m->p95[k]);
    }
    /* The defaults since: each cell's own ray, for shadows and the SVF. */
    opt.box_lines = SS_BOX_LINES_DEFAULT;
    opt.box_shadows = SS_BOX_SHADOWS_MARCH;
    opt.box_sky = SS_BOX_SKY_MARCH;
    row("box, each cell's own ray (--box-shadows march, --box-sky march: the defaults)", "-", g,
        &opt, 1, NULL);
    snprintf(m->name, sizeof m->name, "%s (%d x %d cells)", name, g->width, g->height);
}

/* The planner's table (src/core/box_lines_table.h), as C. */
static int write_table(const char *path, const measured *m, int n)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        return 1;
    }
    fprintf(f, "/* The 95th percentile (over cells) of |geometric SVF with box lines - the\n"
               " * box model's from an independent ray march| (tests/box_march.c), 16\n"
               " * directions from 5 deg, for each box-line count (box_lines_table.h).\n"
               " * GENERATED by `make box-lines` (doc/box_lines_driver.c), which writes\n"
               " * doc/box_lines.md from the same run: do not edit by hand. */\n"
               "#include \"config.h\"\n\n#include \"box_lines_table.h\"\n\n"
               "/* clang-format off */\n"
               "const int ss_box_lines_counts[SS_BOX_LINES_N_COUNTS] = {");
    for (int k = 0; k < N_COUNTS; ++k)
        fprintf(f, "%s%d", k ? ", " : "", counts[k]);
    fprintf(f, "};\n\nconst ss_box_lines_row ss_box_lines_rows[] = {\n");
    for (int r = 0; r < n; ++r) {
        fprintf(f, "    {\"%s\",\n     {", m[r].name);
        for (int k = 0; k < N_COUNTS; ++k)
            fprintf(f, "%s%.3g", k ? ", " : "", m[r].p95[k]);
        fprintf(f, "}},\n");
    }
    fprintf(f, "};\nconst int ss_box_lines_n_rows = (int)(sizeof ss_box_lines_rows / "
               "sizeof ss_box_lines_rows[0]);\n/* clang-format on */\n");
    return fclose(f) != 0;
}

/* The 1, 5 and 15 minute load averages, or "unknown". */
static const char *load_average(char *buf, size_t size)
{
    FILE *f = fopen("/proc/loadavg", "r");
    double a[3];
    int ok = f && fscanf(f, "%lf %lf %lf", &a[0], &a[1], &a[2]) == 3;
    if (f)
        fclose(f);
    if (ok)
        snprintf(buf, size, "%.2f %.2f %.2f", a[0], a[1], a[2]);
    else
        snprintf(buf, size, "unknown");
    return buf;
}

int main(int argc, char **argv)
{
    char load[64];
    const char *table_path = NULL, *dsm = NULL;
    for (int i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--table") == 0 && i + 1 < argc)
            table_path = argv[++i];
        else
            dsm = argv[i];
    }
    printf("# Box lines: agreement with the box model against time\n\n"
           "Written by `make box-lines` (doc/box_lines_driver.c), which also writes the "
           "planner's table of box-line counts (src/core/box_lines_table.c: the p95 column). "
           "Suns (azimuth/elevation): "
           "117/25, 203/40, 251/15, 331/30; agreement: the share of cells whose cast shadow "
           "equals an independent box-model ray march's (tests/box_march.c); SVF error: "
           "|geometric SVF - the march's| over the same 16 directions, its mean over the cells "
           "from 0 deg (four of them along the diagonals, where rays run through cell corners) "
           "and from 5 deg, and its 95th percentile from 5 deg (what the planner chooses "
           "`--box-lines` by where `--box-sky lines` asks for them, doc/planner.md). The rows "
           "per count take `--box-shadows lines --box-sky lines` (the families' walks); the "
           "last row, each cell's own ray, the default for shadows and for the sky view since "
           "issue 42 (src/core/box_shadow.c, src/core/box_sky.c). Times: medians, "
           "the C twin on this machine, kernel build excluded; the shadow is the first sun's. "
           "Load average when this began: %s (the machine is shared: under load times are "
           "noisy, and their ratios along a table hold better than their values).\n",
           load_average(load, sizeof load));
    measured m[2];
    int n = 0;
    ss_grid city = box_march_city(300);
    table("A synthetic city: boxes of 4..45 m on 1 m cells", &city, &m[n++]);
    ss_grid_free(&city);
    if (dsm) {
        ss_ctx *ctx = ss_ctx_new();
        ss_dem dem;
        const char *paths[] = {dsm};
        if (ss_dem_read(ctx, paths, 1, NULL, &dem) != SS_OK) {
            fprintf(stderr, "box_lines_driver: %s\n", ss_ctx_message(ctx));
            ss_ctx_free(ctx);
            return 1;
        }
        table("The Gothenburg 1 m DSM (`../shared/data/goteborg_kronenhuset_dsm_1m.tif`)",
              &dem.grid, &m[n++]);
        ss_dem_free(&dem);
        ss_ctx_free(ctx);
    }
    printf("\nCrowns (`--canopy`) on box lines are met by each cell's own ray too "
           "(`--box-shadows march`): `tests/test_box_crowns` holds every cell of 280 suns to "
           "the independent march of `tests/box_march.c` on synthetic scenes and on "
           "Gothenburg's DSM and CDSM, and doc/vegetation.md (\"Crowns by each cell's own "
           "ray\") measures what they cost in a PV year.\n");
    return table_path ? write_table(table_path, m, n) : 0;
}
