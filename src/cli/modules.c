/* Loading the picture adapters at run time (modules.h). */
#include "config.h"

#include <dlfcn.h>
#include <libgen.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "module_dir.h"
#include "modules.h"

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

/* The folders a module is looked for in, in order; NULL where none. */
static void module_dirs(const char *dirs[3])
{
    dirs[0] = getenv("SKYSWEEP_MODULE_DIR");
    dirs[1] = running_from_build_tree() ? SS_BUILD_DIR "/.libs" : NULL;
    dirs[2] = SS_MODULE_DIR;
}

int cli_module_find(const char *file, char *path, size_t size)
{
    const char *dirs[3];
    module_dirs(dirs);
    for (int i = 0; i < 3; ++i)
        if (dirs[i] && *dirs[i]) {
            snprintf(path, size, "%s/%s", dirs[i], file);
            if (access(path, R_OK) == 0)
                return 1;
        }
    snprintf(path, size, "not found in");
    for (int i = 0; i < 3; ++i)
        if (dirs[i] && *dirs[i] && strlen(path) + strlen(dirs[i]) + 2 < size)
            strcat(strcat(path, " "), dirs[i]);
    return 0;
}

ss_status cli_module_load(ss_ctx *ctx, const char *file, const char *what,
                          const char *const *symbols, int n, void **fns, void **handle)
{
    if (*handle)
        return SS_OK;
    const char *dirs[3];
    module_dirs(dirs);
    char path[PATH_MAX], why[1024] = "not found in";
    void *module = NULL;
    for (int i = 0; i < 3 && !module; ++i) {
        if (!dirs[i] || !*dirs[i])
            continue;
        if (strncmp(why, "not found", 9) == 0 && strlen(why) + strlen(dirs[i]) + 2 < sizeof why)
            strcat(strcat(why, " "), dirs[i]);
        snprintf(path, sizeof path, "%s/%s", dirs[i], file);
        if (access(path, R_OK) != 0)
            continue;
        module = dlopen(path, RTLD_NOW | RTLD_LOCAL);
        if (!module)
            snprintf(why, sizeof why, "%s", dlerror());
    }
    for (int i = 0; module && i < n; ++i)
        if (!(fns[i] = dlsym(module, symbols[i]))) {
            snprintf(why, sizeof why, "it lacks the adapter's %s", symbols[i]);
            dlclose(module);
            module = NULL;
        }
    if (!module)
        return ss_ctx_error(ctx, SS_ERR_DEVICE,
                            "cannot load the %s module %s (%s): reinstall skysweep or set "
                            "SKYSWEEP_MODULE_DIR to its folder",
                            what, file, why);
    *handle = module;
    return SS_OK;
}
