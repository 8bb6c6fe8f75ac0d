/* What box lines cost and buy (doc/box_lines.md, written by `make
 * box-lines`): for each line model and number of box lines per cell, the
 * share of cells whose cast shadow agrees with the box-model ray march
 * (tests/box_march.c) for four suns off the grid axes, the mean error of
 * the geometric SVF (16 directions) against the march's, and the wall time
 * of one cast shadow and of a 16-direction SVF on the C twin (medians),
 * on a synthetic city and on the Gothenburg 1 m DSM (argument 1). */
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

static void table(const char *name, const ss_grid *g)
{
    printf("\n### %s (%d x %d cells)\n\n", name, g->width, g->height);
    printf("| lines | per cell | shadows agree, mean of 4 suns | worst sun | SVF error, from "
           "0 deg | from 5 deg | shadow, s | SVF 16 directions, s |\n"
           "|---|---|---|---|---|---|---|---|\n");
    const int counts[] = {0, 0, 1, 2, 4, 8, 16, 32, 64};
    for (int k = 0; k < 9; ++k) {
        ss_sweep_options opt;
        ss_sweep_options_default(&opt);
        opt.directions = 16;
        opt.lines = k == 0 ? SS_LINES_INTERPOLATED : k == 1 ? SS_LINES_DIGITAL : SS_LINES_BOX;
        if (counts[k] > 0)
            opt.box_lines = counts[k];
        double mean = 0, worst = 1;
        char err[300] = "";
        for (int s = 0; s < 4; ++s) {
            double a = box_march_agreement(g, &opt, suns[s][0], suns[s][1], err);
            mean += a / 4;
            worst = fmin(worst, a);
        }
        char per_cell[16] = "-";
        if (counts[k] > 0)
            snprintf(per_cell, sizeof per_cell, "%d", counts[k]);
        double svf_error = box_march_svf_error(g, &opt, err);
        ss_sweep_options turned = opt;
        turned.offset_deg = 5;
        printf("| %s | %s | %.3f %% | %.3f %% | %.4f | %.4f | %.4f | %.3f |\n",
               ss_line_model_name(opt.lines), per_cell, 100 * mean, 100 * worst, svf_error,
               box_march_svf_error(g, &turned, err), seconds(g, &opt, 0, 5),
               seconds(g, &opt, 1, 3));
    }
}

int main(int argc, char **argv)
{
    printf("# Box lines: agreement with the box model against time\n\n"
           "Written by `make box-lines` (doc/box_lines_driver.c). Suns (azimuth/elevation): "
           "117/25, 203/40, 251/15, 331/30; agreement: the share of cells whose cast shadow "
           "equals an independent box-model ray march's (tests/box_march.c); SVF error: mean "
           "|geometric SVF - the march's| over the same 16 directions, from 0 deg (four of them "
           "along the diagonals, where rays run through cell corners) and from 5 deg. Times: "
           "medians, "
           "the C twin on this machine, kernel build excluded; the shadow is the first sun's.\n");
    ss_grid city = box_march_city(300);
    table("A synthetic city: boxes of 4..45 m on 1 m cells", &city);
    ss_grid_free(&city);
    if (argc > 1) {
        ss_ctx *ctx = ss_ctx_new();
        ss_dem dem;
        const char *paths[] = {argv[1]};
        if (ss_dem_read(ctx, paths, 1, NULL, &dem) != SS_OK) {
            fprintf(stderr, "box_lines_driver: %s\n", ss_ctx_message(ctx));
            ss_ctx_free(ctx);
            return 1;
        }
        table("The Gothenburg 1 m DSM (`../shared/data/goteborg_kronenhuset_dsm_1m.tif`)",
              &dem.grid);
        ss_dem_free(&dem);
        ss_ctx_free(ctx);
    }
    return 0;
}
