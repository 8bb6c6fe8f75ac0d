/* The memory planner (ss_memory_plan_make) against a device's own memory,
 * a GPU's, simulated here by need's device_memory_bytes: the device's
 * planned bytes stay within its memory less the reserve (a tenth), band
 * rows shrink with the device where the host's budget would sweep the
 * grid whole, the batch's and the cells' shares fit beside the heights,
 * sums and hulls, a device too small for one band is refused with the
 * least that would do (and that one does), and where the host's budget is
 * the limit a large device changes nothing. */
#include "config.h"

#include <math.h>

#include "ss_band.h"
#include "tap.h"
#include "testlib.h"

#define MIB 1048576.0
#define RESERVE 0.10

/* An SVF of 4096 x 4096 cells and 16 directions: heights, stack slots and
 * sums, 12 bytes a cell of a band. */
static ss_memory_need svf_need(double budget, double device_memory)
{
    ss_memory_need n = {.budget_bytes = budget,
                        .baseline_bytes = 40 * MIB,
                        .width = 4096,
                        .height = 4096,
                        .cell_bytes = 12.0,
                        .whole_cell_bytes = 16.0,
                        .column_bytes = 16.0,
                        .hull_lines = 16,
                        .cache_bytes = 16 * MIB,
                        .device_memory_bytes = device_memory};
    return n;
}

static ss_memory_plan plan_of(ss_ctx *ctx, double budget, double device_memory)
{
    ss_memory_need n = svf_need(budget, device_memory);
    ss_memory_plan p;
    ss_memory_plan_make(ctx, &n, &p);
    return p;
}

int main(void)
{
    ss_ctx *ctx = ss_ctx_new();
    double host = 16384 * MIB; /* the whole grid fits the host */
    ss_memory_plan none = plan_of(ctx, host, 0);
    tap_ok(none.band_rows == 0 && none.device_memory == 0 && none.device_planned == 0,
           "no device of its own memory: swept whole (band rows %d), no device planned",
           none.band_rows);

    int last_rows = 0;
    const double sizes[] = {1024, 512, 256, 128}; /* the hulls alone take 72 MiB */
    for (int i = 0; i < 4; ++i) {
        double device = sizes[i] * MIB;
        ss_memory_plan p = plan_of(ctx, host, device);
        double usable = device * (1.0 - RESERVE);
        tap_ok(p.band_rows > 0 && p.band_rows < 4096 && p.device_memory == device &&
                   p.device_planned <= usable && p.device_planned > 0.5 * usable,
               "device of %.0f MiB: bands of %d rows, %.1f MiB of it planned (at most %.1f)",
               sizes[i], p.band_rows, p.device_planned / MIB, usable / MIB);
        if (i > 0)
            tap_ok(p.band_rows < last_rows, "device of %.0f MiB: fewer rows (%d) than %.0f MiB's (%d)",
                   sizes[i], p.band_rows, sizes[i - 1], last_rows);
        /* Heights and sums (8 bytes a held cell) beside the batch's and the
         * cells' shares: within the usable memory. */
        double held = (p.band_rows + 2.0 * SS_BAND_HALO) * 4096;
        tap_ok(p.device_bytes >= 4 * 12.0 * held && p.device_cells_bytes >= 12.0 * held &&
                   8.0 * held + p.hull_bytes + p.device_bytes + p.device_cells_bytes <= usable,
               "device of %.0f MiB: a batch of 4 directions (%.1f MiB) and the cells (%.1f MiB) "
               "fit beside the heights, sums and hulls", sizes[i], p.device_bytes / MIB,
               p.device_cells_bytes / MIB);
        last_rows = p.band_rows;
    }

    ss_memory_plan small = plan_of(ctx, host, 2 * MIB);
    tap_ok(small.band_rows == -1 && small.device_least > 2 * MIB && small.least_budget < host,
           "device of 2 MiB: refused, the least device %.1f MiB (the host's budget suffices)",
           small.device_least / MIB);
    ss_memory_plan least = plan_of(ctx, host, small.device_least);
    tap_ok(least.band_rows >= 1 && least.device_planned <= small.device_least * (1.0 - RESERVE),
           "device of the least named, %.1f MiB: bands of %d rows within it",
           small.device_least / MIB, least.band_rows);

    /* The host's budget the limit: a large device's bound does not count
     * the buffers twice. */
    double tight = 200 * MIB;
    ss_memory_plan host_only = plan_of(ctx, tight, 0), both = plan_of(ctx, tight, 65536 * MIB);
    tap_ok(host_only.band_rows > 0 && both.band_rows == host_only.band_rows &&
               both.planned_bytes == host_only.planned_bytes,
           "--memory 200M, device of 64 GiB: bands of %d rows as without a device (%d)",
           both.band_rows, host_only.band_rows);
    ss_ctx_free(ctx);
    return tap_done();
}
