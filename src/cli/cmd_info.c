/* skysweep info: version, dependencies, devices, and whether the kernels
 * build on the selected device. */
#include "config.h"

#include <limits.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "modules.h"

#ifdef HAVE_OIIO
#define HAVE_OIIO_FLAG 1
#else
#define HAVE_OIIO_FLAG 0
#endif
#ifdef HAVE_VTK
#define HAVE_VTK_FLAG 1
#else
#define HAVE_VTK_FLAG 0
#endif
#ifdef HAVE_MPI
#define HAVE_MPI_FLAG 1
#else
#define HAVE_MPI_FLAG 0
#endif
#ifdef HAVE_SANITIZERS
#define HAVE_SANITIZERS_FLAG 1
#else
#define HAVE_SANITIZERS_FLAG 0
#endif

static const char *built_with(int flag)
{
    return flag ? "yes" : "no";
}
#include "run.h"

typedef struct {
    const char *device;
} info_settings;

static const opt_spec info_options[] = {
    {"device", OPT_STRING, offsetof(info_settings, device), "NAME", NULL, 0, 0, NULL,
     "device whose kernel build to check (default: the default device)"},
    OPT_END};

static const char info_usage[] = "skysweep info [options]";
static const char info_summary[] =
    "Version, dependency versions, where the run-time modules are, OpenCL devices and kernel\nbuild status.";

int cmd_info(int argc, char **argv)
{
    info_settings set = {0};
    const opt_spec *tables[] = {info_options, NULL};
    if (opt_print_reference(tables, argc, argv, "info", info_usage, info_summary, ss_version()))
        return 0;
    const char *pos[1];
    int n_pos = 0;
    char err[512];
    int r = opt_parse(tables, &set, argc, argv, pos, &n_pos, 0, err, sizeof err);
    if (r < 0)
        return run_usage_error("info", err);
    if (r > 0) {
        opt_print_help(tables, info_usage, info_summary);
        return 0;
    }
    printf("skysweep %s\n", ss_version());
    printf("GDAL     %s\n", ss_gdal_version());
    printf("built    OpenImageIO %s, VTK %s, MPI %s, sanitizers %s\n", built_with(HAVE_OIIO_FLAG),
           built_with(HAVE_VTK_FLAG), built_with(HAVE_MPI_FLAG), built_with(HAVE_SANITIZERS_FLAG));
    /* The run-time modules of the libraries that were built in. */
    static const struct {
        int built;
        const char *file;
    } modules[] = {{HAVE_OIIO_FLAG, "skysweep-images.so"},
                   {HAVE_VTK_FLAG, "skysweep-render.so"},
                   {HAVE_MPI_FLAG, "skysweep-mpi.so"}};
    for (size_t i = 0; i < sizeof modules / sizeof modules[0]; ++i) {
        char where[PATH_MAX + 16];
        if (modules[i].built) {
            cli_module_find(modules[i].file, where, sizeof where);
            printf("module   %s: %s\n", modules[i].file, where);
        }
    }
    printf("devices:\n");
    command_list_devices();

    ss_ctx *ctx = ss_ctx_new();
    ss_ctx_use_device(ctx, set.device);
    /* A tiny sweep proves the kernels build and run on the device. */
    ss_grid g;
    ss_status st = ss_grid_alloc(ctx, &g, 4, 3, 1.0, 1.0);
    float out[12];
    if (st == SS_OK) {
        for (int i = 0; i < 12; ++i)
            g.z[i] = (float)(i % 5);
        ss_sweep_options opt;
        ss_sweep_options_default(&opt);
        opt.directions = 4;
        st = ss_svf(ctx, &g, &opt, SS_SVF_DEF_GEOMETRIC, out);
    }
    ss_counters c = ss_ctx_counters(ctx);
    if (st == SS_OK)
        printf("kernels  built and ran on %s (build %.3f s)\n", ss_ctx_device_name(ctx),
               c.build_seconds);
    else
        printf("kernels  FAILED: %s\n", ss_ctx_message(ctx));
    ss_grid_free(&g);
    ss_ctx_free(ctx);
    return st == SS_OK ? 0 : (int)st;
}
