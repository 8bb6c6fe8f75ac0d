/* Scene files (scene.c): a job described in an INI file whose keys are the
 * command's options. */
#ifndef SS_CLI_SCENE_H
#define SS_CLI_SCENE_H

#include <stddef.h>

#include "options.h"

/* If argv holds --scene FILE, reads it and returns in *out_argv a command
 * line with the scene's options first, then argv's (which override them),
 * then the scene's DEMs and output unless argv names its own. Returns 0
 * (with *out_argv NULL when there is no scene), or -1 with "FILE:LINE:
 * message" in err. */
int scene_expand(const opt_spec *const *tables, int argc, char **argv, int *out_argc,
                 char ***out_argv, char *err, size_t err_size);
/* Index of the --scene option in argv (its file follows), or -1. */
int scene_arg(int argc, char **argv);
/* Frees what the last scene_expand returned (at the end of the run). */
void scene_release(void);
/* The scene's `product` (for skysweep plan/run SCENE). */
int scene_product(const char *file, char *product, size_t size, char *err, size_t err_size);

#endif
