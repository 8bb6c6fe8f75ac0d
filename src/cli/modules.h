/* Adapters loaded at run time: the C++ libraries whose start-up costs more
 * than a small job (OpenImageIO and its codecs: 0.3 s; VTK: dozens of
 * shared libraries) are modules, skysweep-NAME.so, loaded only by the
 * commands that use them. images_module.c and render_module.c define the
 * adapters' functions the command line calls on top of this. */
#ifndef SS_MODULES_H
#define SS_MODULES_H

#include <stddef.h>

#include "skysweep.h"

/* Loads module `file` (once; *handle keeps it) and looks up the n symbols
 * into fns. Looked for in $SKYSWEEP_MODULE_DIR if set, the build tree's
 * .libs when this program runs from its build tree (make check), and the
 * installed module folder (pkglibdir). On failure, SS_ERR_DEVICE with a
 * message naming `what` (the library) and where it was looked for. */
ss_status cli_module_load(ss_ctx *ctx, const char *file, const char *what,
                          const char *const *symbols, int n, void **fns, void **handle);

/* Where cli_module_load would first look for module `file` and find it
 * readable: 1 with that path, or 0 with "not found in" and the folders
 * (skysweep info says so). */
int cli_module_find(const char *file, char *path, size_t size);

#endif
