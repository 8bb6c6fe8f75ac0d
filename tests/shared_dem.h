/* A check run on a DEM of ../shared/data where the tests have it, skipped
 * cleanly where they do not: a build without GDAL (SS_TEST_READS_DEMS
 * unset, the core-only build) or a checkout without ../shared. */
#ifndef SS_TEST_SHARED_DEM_H
#define SS_TEST_SHARED_DEM_H

#include "skysweep.h"
#include "tap.h"
#include "testlib.h"
#ifdef SS_TEST_READS_DEMS
#include "dem_io.h"
#endif

typedef void (*shared_dem_check)(const char *name, const ss_grid *grid, void *user);

/* Runs check(name, the DEM's grid, user) on ../shared/data/file, or says
 * why not: a TAP skip where it cannot be read here, a failure where it is
 * there but does not read. */
static inline void shared_dem_run(const char *file, const char *name, shared_dem_check check,
                                  void *user)
{
#ifndef SS_TEST_READS_DEMS
    (void)file, (void)check, (void)user;
    tap_skip(name, "a build without GDAL reads no GeoTIFF");
#else
    const char *path = test_shared_data(file);
    if (!path) {
        tap_skip(name, "../shared/data is not here");
        return;
    }
    ss_ctx *ctx = ss_ctx_new();
    ss_dem dem;
    const char *paths[] = {path};
    if (ss_dem_read(ctx, paths, 1, NULL, &dem) == SS_OK) {
        check(name, &dem.grid, user);
        ss_dem_free(&dem);
    } else {
        tap_ok(0, "cannot read %s: %s", path, ss_ctx_message(ctx));
    }
    ss_ctx_free(ctx);
#endif
}

#endif
