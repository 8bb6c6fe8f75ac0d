/* A toy product, added to the registry by this one file and nothing else
 * (tests/test_toy_product.sh): "toy", the highest horizon elevation of
 * each cell over the sweep's directions. Built as a shared object that
 * registers its entry when loaded (ss_product_register): the CLI, its
 * --help-json, the Python package and the QGIS provider then offer it as
 * they offer the built-in products, without an edit of their own. */
#include <math.h>
#include <stdlib.h>

#include "skysweep_products.h"

/* The horizon rows of each direction, folded into each row's highest
 * angle; a row goes on to the product's sink once every direction gave
 * it (whatever order the sweep delivers them in). */
typedef struct {
    ss_rows_sink sink;
    void *user;
    int width, directions;
    float *highest; /* the grid's rows */
    int *given;     /* directions given, per row */
} toy_rows;

static ss_status fold(void *user, int output, int index, int row0, int n_rows,
                      const float *angles)
{
    (void)output, (void)index;
    toy_rows *t = user;
    for (int r = 0; r < n_rows; ++r) {
        int row = row0 + r;
        float *h = t->highest + (size_t)row * (size_t)t->width;
        const float *a = angles + (size_t)r * (size_t)t->width;
        for (int c = 0; c < t->width; ++c)
            h[c] = t->given[row] == 0 || a[c] == SS_NODATA ? a[c] : fmaxf(h[c], a[c]);
        if (++t->given[row] == t->directions) {
            ss_status st = t->sink(t->user, 0, 0, row, 1, h);
            if (st != SS_OK)
                return st;
        }
    }
    return SS_OK;
}

static ss_status toy_run(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                         const void *params, const ss_product_sun *sun, unsigned outputs,
                         const ss_share *share, ss_rows_sink sink, void *user)
{
    (void)params, (void)sun, (void)outputs, (void)share;
    toy_rows t = {sink, user, src->width, opt->directions,
                  malloc((size_t)src->width * (size_t)src->height * sizeof(float)),
                  calloc((size_t)src->height, sizeof(int))};
    ss_status st = t.highest && t.given ? ss_horizon_rows(ctx, src, opt, 0, fold, &t)
                                        : ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
    free(t.highest);
    free(t.given);
    return st;
}

static void toy_request(const void *params, double cell_size_m, ss_plan_request *req)
{
    (void)params, (void)cell_size_m;
    req->kind = SS_PLAN_HORIZONS;
}

static double toy_cell_bytes(const void *params, unsigned outputs)
{
    (void)params, (void)outputs;
    return ss_horizon_band_cell_bytes(0) + sizeof(float);
}

static double toy_halo_m(const void *params, double cell_size_m)
{
    (void)params, (void)cell_size_m;
    return 0.0;
}

static const char *const toy_tables[] = {"sweep", NULL};
static const ss_product_output toy_outputs[] = {
    {"toy", NULL, "deg", 1, "highest horizon", 0}, {0}};
static const ss_product_info toy = {
    "toy", "highest horizon elevation of each cell (a test's toy product)", "Highest horizon",
    "Terrain", "The highest horizon elevation (degrees) of every cell over the sweep's directions.",
    NULL, toy_tables, 0, toy_outputs, SS_PLAN_HORIZONS, 0, toy_request, toy_cell_bytes,
    toy_halo_m, toy_run};

__attribute__((constructor)) static void toy_register(void)
{
    ss_product_register(&toy);
}
