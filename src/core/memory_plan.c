/* The one memory planner (doc/engine.md, "One memory planner"): from a
 * budget for the whole process's peak resident memory, what the process
 * already holds, and what a run's cells, columns, hulls, GDAL's cache and
 * the device's buffers cost, the rows of a band, the device's batch and the
 * bytes its buffers may take. The CLI's band rows, and backend_ocl.c's
 * batch and device cells (engine.c, cells_fit) all come from here. */
#include "config.h"

#include <math.h>

#include "ctx_internal.h"
#include "engine.h"

#define HALO SS_BAND_HALO
#define MIB 1048576.0

/* A whole-grid SVF or openness holds up to 24 bytes a cell: heights, hull
 * stack slots, sums and the product, and an inverted copy or gradients. */
#define WHOLE_BYTES_PER_CELL 24.0
/* What the program allocates beside the sweep's grids and GDAL's cache:
 * the writer's compression buffers (a block per thread), its rows handed
 * to GDAL, the allocator's slack (an allowance; test_memory_bound.sh
 * checks the peaks it gives). */
#define RUN_FIXED_BYTES (16.0 * MIB)
/* Points a carried hull holds on average, per line and direction crossing
 * a band's edge: measured 10.3 on test_memory_bound's hills, 11.8 on the
 * Kilauea DEM, 19.8 for insolation's suns there, 28 on a 4096^2 of broad
 * hills, where about two lines in three of a direction cross the edge (a
 * line per column is counted); at most a line's length. */
#define HULL_POINTS_PER_LINE 24.0
/* The most directions a CPU device walks at once in bands (backend_ocl.c,
 * fit_batch; one on a whole grid). */
#define CPU_BATCH_IN_BANDS 4

/* The share of a device's own memory (a GPU's) left to its driver and to
 * other processes (a display, another job's context): OpenCL reports the
 * whole memory, of which CUDA's runtime keeps a few hundred MiB. */
#define DEVICE_RESERVE 0.10
/* The directions a device of its own memory is planned to walk at once,
 * as a CPU device in bands (backend_ocl.c, fit_batch, gives it more where
 * the plan's share holds more). */
#define DEVICE_BATCH_PLANNED 4

/* A device with its own memory: a GPU, or one simulated (need's
 * device_memory_bytes). memory 0: none. */
typedef struct {
    double memory, usable, max_alloc;
} own_device;

static own_device own_device_of(const ss_ctx *ctx, const ss_memory_need *n)
{
    own_device d = {0};
    double global = 0.0, alloc = 0.0;
    int gpu = ss_ocl_own_memory(ctx, &global, &alloc);
    if (n->device_memory_bytes > 0) {
        d.memory = gpu ? fmin(global, n->device_memory_bytes) : n->device_memory_bytes;
        d.max_alloc = gpu ? fmin(alloc, d.memory) : d.memory;
    } else if (gpu) {
        d.memory = global;
        d.max_alloc = alloc;
    }
    if (!(d.max_alloc > 0)) /* a device that did not say */
        d.max_alloc = d.memory;
    d.usable = d.memory * (1.0 - DEVICE_RESERVE);
    return d;
}

/* Hulls handed on between bands: a line of each direction (box lines:
 * several) per column crossing a band's edge, the hulls read and the hulls
 * written held together, each array grown by half again as it fills. */
static double hull_bytes(const ss_memory_need *n)
{
    double points = fmin(HULL_POINTS_PER_LINE, (double)n->height);
    return (double)n->width * n->hull_lines * points * sizeof(ss_hull_point) * 2.0 * 1.5;
}

/* Bytes per cell a CPU OpenCL device's buffers take from the host's
 * memory: its copy of the heights and its sums, and per direction of a
 * batch its stack slots and planes, which a cell of the host's band
 * bounds. 0 for the C twin and for a GPU (its own memory). */
static double device_host_cell_bytes(const ss_ctx *ctx, const ss_memory_need *n, int batch)
{
    if (!ss_ocl_is_cpu(ctx))
        return 0.0;
    return 2.0 * sizeof(float) + batch * n->cell_bytes;
}

/* Bytes the process holds with bands of rows rows (height: the whole grid,
 * which hands no hulls on). */
double ss_memory_planned(const ss_ctx *ctx, const ss_memory_need *n, int rows)
{
    double w = (double)n->width;
    double fixed = n->baseline_bytes + n->cache_bytes + RUN_FIXED_BYTES +
                   n->grid_cell_bytes * w * n->height;
    if (rows >= n->height) {
        double per_cell = fmax(fmax(n->cell_bytes, WHOLE_BYTES_PER_CELL), n->whole_cell_bytes) +
                          device_host_cell_bytes(ctx, n, 1);
        return fixed + per_cell * w * n->height;
    }
    double held_rows = rows + 2.0 * (HALO + n->halo_rows);
    double per_cell = n->cell_bytes + device_host_cell_bytes(ctx, n, CPU_BATCH_IN_BANDS);
    double devices_hulls = ss_ocl_is_cpu(ctx) ? 2.0 : 1.0; /* PoCL's copies too */
    return fixed + per_cell * w * held_rows + devices_hulls * hull_bytes(n) +
           w * n->hull_lines * n->column_bytes;
}

/* Bytes per held cell in a device's own memory: the heights and sums, a
 * batch's stack slots and planes (a band's cell bytes each, as a CPU
 * device's), and the cells' buffers, whose terms, sums, stored horizons
 * and step a band's cell bytes bound too (engine.c, cells_fit). */
static double own_cell_bytes(const ss_memory_need *n)
{
    return 2.0 * sizeof(float) + (DEVICE_BATCH_PLANNED + 1) * n->cell_bytes;
}

static double held_rows_of(const ss_memory_need *n, int rows)
{
    return rows >= n->height ? (double)n->height : rows + 2.0 * (HALO + n->halo_rows);
}

/* Bytes of a device's own memory with bands of rows rows (the grid's
 * height: whole); in bands the device holds the hulls handed on and the
 * carried columns too. */
static double own_device_planned(const ss_memory_need *n, int rows)
{
    double w = (double)n->width, held = held_rows_of(n, rows);
    double carried = rows >= n->height ? 0.0 : hull_bytes(n) + w * n->hull_lines * n->column_bytes;
    return own_cell_bytes(n) * w * held + carried;
}

/* The least device memory for bands of rows rows: the plan within it less
 * the reserve, and one direction's buffers within its largest buffer (a
 * device whose largest is the same share of its memory). */
static double own_device_least(const own_device *d, const ss_memory_need *n, int rows)
{
    double largest = n->cell_bytes * n->width * held_rows_of(n, rows);
    return fmax(own_device_planned(n, rows) / (1.0 - DEVICE_RESERVE),
                largest * d->memory / d->max_alloc);
}

/* The most rows a band may take on the device (fractional), INFINITY where
 * the grid fits whole or there is no device of its own memory. */
static double own_device_rows(const own_device *d, const ss_memory_need *n)
{
    double w = (double)n->width;
    if (d->memory <= 0 || (own_device_planned(n, n->height) <= d->usable &&
                           n->cell_bytes * w * n->height <= d->max_alloc))
        return INFINITY;
    double halo_rows = 2.0 * (HALO + n->halo_rows);
    double carried = own_device_planned(n, 0) - own_cell_bytes(n) * w * halo_rows;
    double by_memory = (d->usable - carried) / (own_cell_bytes(n) * w);
    double by_alloc = d->max_alloc / (n->cell_bytes * w);
    return fmin(by_memory, by_alloc) - halo_rows;
}

/* The device's shares of its own memory for the plan's bands: the
 * batch's and the cells' planned buffers, and half each of what the plan
 * leaves. */
static void own_device_shares(const own_device *d, const ss_memory_need *n, int rows,
                              ss_memory_plan *p)
{
    double band = n->cell_bytes * n->width * held_rows_of(n, rows);
    double left = fmax(d->usable - p->device_planned, 0.0);
    double batch = DEVICE_BATCH_PLANNED * band + left / 2.0, cells = band + left / 2.0;
    /* A CPU device simulated smaller: within the host's shares too. */
    p->device_bytes = p->device_bytes > 0 ? fmin(p->device_bytes, batch) : batch;
    p->device_cells_bytes = p->device_cells_bytes > 0 ? fmin(p->device_cells_bytes, cells) : cells;
}

int ss_memory_plan_rows(const ss_ctx *ctx, const ss_memory_need *need, ss_memory_plan *plan)
{
    ss_memory_plan p = {0};
    own_device d = own_device_of(ctx, need);
    double budget = need->budget_bytes;
    double whole = ss_memory_planned(ctx, need, need->height);
    double one_band = ss_memory_planned(ctx, need, 1);
    double device_rows = own_device_rows(&d, need);
    p.least_budget = fmax(fmin(whole, one_band), need->peak_bytes);
    p.hull_bytes = hull_bytes(need);
    p.device_memory = d.memory;
    if (d.memory > 0)
        p.device_least = fmin(own_device_least(&d, need, need->height),
                              own_device_least(&d, need, 1));
    if (need->peak_bytes > budget || device_rows < 1) {
        p.band_rows = -1;
    } else if (whole <= budget && device_rows >= need->height) {
        p.band_rows = 0;
        p.planned_bytes = whole;
    } else {
        double fixed = ss_memory_planned(ctx, need, 0);
        double per_row = ss_memory_planned(ctx, need, 1) - fixed;
        double host_rows = whole <= budget ? INFINITY : (budget - fixed) / per_row;
        /* More rows than the grid's make one band of them all. */
        double rows = fmin(fmin(host_rows, device_rows), (double)need->height);
        /* Whole 256-row strips keep GeoTIFF tiles from being written twice. */
        int r = rows < 1 ? -1 : rows >= 256 ? 256 * (int)(rows / 256) : (int)rows;
        p.band_rows = r;
        p.planned_bytes = r > 0 ? ss_memory_planned(ctx, need, r < need->height ? r : need->height - 1)
                                : one_band;
    }
    /* A CPU device's buffers are counted above within the budget (a batch
     * of CPU_BATCH_IN_BANDS in bands): they may take what was counted for
     * them and what the budget leaves, the batch's and the cells' alike. */
    if (ss_ocl_is_cpu(ctx) && budget > 0 && p.band_rows >= 0) {
        int rows = p.band_rows ? p.band_rows : need->height;
        double held_rows = p.band_rows ? rows + 2.0 * (HALO + need->halo_rows) : rows;
        int batch = p.band_rows ? CPU_BATCH_IN_BANDS : 1;
        p.device_bytes = device_host_cell_bytes(ctx, need, batch) * need->width * held_rows +
                         fmax(budget - p.planned_bytes, 0.0);
        p.device_cells_bytes = p.device_bytes;
    }
    /* A device's own memory (a GPU's) is a second bound beside the host's:
     * its buffers are planned within it, not within the budget. */
    if (d.memory > 0 && p.band_rows >= 0) {
        /* A band of all the grid's rows holds its halo and hulls as bands
         * do (the grid's height would stand for a whole sweep). */
        int held = p.band_rows == 0 ? need->height
                                    : p.band_rows < need->height ? p.band_rows : need->height - 1;
        p.device_planned = own_device_planned(need, held);
        own_device_shares(&d, need, held, &p);
    }
    if (plan)
        *plan = p;
    return p.band_rows;
}

ss_status ss_memory_plan_make(ss_ctx *ctx, const ss_memory_need *need, ss_memory_plan *plan)
{
    ss_call_begin(ctx);
    ss_memory_plan_rows(ctx, need, plan);
    ctx->memory = *plan;
    return SS_OK;
}

double ss_memory_device_bytes(const ss_ctx *ctx, double global_mem)
{
    return ctx->memory.device_bytes > 0 ? ctx->memory.device_bytes : global_mem / 4.0;
}

double ss_memory_device_cells_bytes(const ss_ctx *ctx, double global_mem)
{
    return ctx->memory.device_cells_bytes > 0 ? ctx->memory.device_cells_bytes
                                              : ss_memory_device_bytes(ctx, global_mem);
}
