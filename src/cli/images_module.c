/* OpenImageIO at run time. Loading OIIO and the codecs it links (OpenEXR,
 * OpenVDB, FFmpeg, ...) costs about 0.3 s at every start of the program,
 * more than a whole SVF of a small DEM, so the adapter (images.cpp) is a
 * module, skysweep-images.so, loaded only by the commands that read or
 * write plain images (--heightmap, quicklook). The two functions of
 * images.h the command line uses are defined here: they load the module
 * on first use and call its own.
 *
 * Where the module is looked for: $SKYSWEEP_MODULE_DIR if set; the build
 * tree's .libs when this program runs from its build tree (make check);
 * the installed module folder (pkglibdir). */
#include "config.h"

#include <dlfcn.h>
#include <libgen.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "images.h"

#define MODULE_NAME "skysweep-images.so"

typedef ss_status (*heightmap_fn)(ss_ctx *, const char *, double, double, double, ss_grid *);
typedef ss_status (*quicklook_fn)(ss_ctx *, const char *, const float *, int, int, double,
                                  double, const char *, int, int);

static void *module;
static heightmap_fn module_heightmap;
static quicklook_fn module_quicklook;

/* Whether this program runs from the build tree (its binary in BUILD or
 * BUILD/.libs, where libtool puts it). */
static int running_from_build_tree(void)
{
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return 0;
    exe[n] = '\0';
    const char *dir = dirname(exe);
    return strcmp(dir, SS_BUILD_DIR) == 0 || strcmp(dir, SS_BUILD_DIR "/.libs") == 0;
}

static ss_status load_module(ss_ctx *ctx)
{
    if (module)
        return SS_OK;
    const char *dirs[3] = {getenv("SKYSWEEP_MODULE_DIR"),
                           running_from_build_tree() ? SS_BUILD_DIR "/.libs" : NULL,
                           SS_MODULE_DIR};
    char path[PATH_MAX], why[1024] = "not found in";
    for (int i = 0; i < 3 && !module; ++i) {
        if (!dirs[i] || !*dirs[i])
            continue;
        if (strncmp(why, "not found", 9) == 0 && strlen(why) + strlen(dirs[i]) + 2 < sizeof why)
            strcat(strcat(why, " "), dirs[i]);
        snprintf(path, sizeof path, "%s/%s", dirs[i], MODULE_NAME);
        if (access(path, R_OK) != 0)
            continue;
        module = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!module)
            snprintf(why, sizeof why, "%s", dlerror());
    }
    if (module) {
        /* POSIX's way to turn dlsym's object pointer into a function's. */
        *(void **)&module_heightmap = dlsym(module, "ss_image_read_heightmap");
        *(void **)&module_quicklook = dlsym(module, "ss_image_write_quicklook");
        if (!module_heightmap || !module_quicklook) {
            snprintf(why, sizeof why, "it lacks the adapter's functions");
            dlclose(module);
            module = NULL;
        }
    }
    if (!module)
        return ss_ctx_error(ctx, SS_ERR_DEVICE,
                            "cannot load the OpenImageIO module %s (%s): reinstall skysweep or "
                            "set SKYSWEEP_MODULE_DIR to its folder",
                            MODULE_NAME, why);
    return SS_OK;
}

ss_status ss_image_read_heightmap(ss_ctx *ctx, const char *path, double cell_m, double z_scale,
                                  double z_offset, ss_grid *out)
{
    ss_status st = load_module(ctx);
    return st != SS_OK ? st : module_heightmap(ctx, path, cell_m, z_scale, z_offset, out);
}

ss_status ss_image_write_quicklook(ss_ctx *ctx, const char *png_path, const float *values,
                                   int width, int height, double vmin, double vmax,
                                   const char *colormap, int bits, int alpha_for_nodata)
{
    ss_status st = load_module(ctx);
    return st != SS_OK ? st
                       : module_quicklook(ctx, png_path, values, width, height, vmin, vmax,
                                          colormap, bits, alpha_for_nodata);
}
