/* Fuzz target: scene files (src/cli/scene.c, INI through libinih). The
 * input is the file's text; it is written to a private temporary folder and
 * expanded as `skysweep svf --scene FILE` would (the shared sweep and sun
 * option tables). Checked: scene_expand returns 0 or -1; a refusal has a
 * one-line message; an expansion is a NULL-free argument vector that
 * opt_parse then reads without crashing. The expansion is released after
 * each input (scene_release), so that leak checking stays on. */
#include "config.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "options.h"
#include "run.h"
#include "scene.h"
#include "fuzz_check.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

typedef struct {
    common_settings common;
} scene_settings;

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size > 20000)
        return 0;
    char *path = fuzz_input_file("scene.ini", data, size);

    const opt_spec *tables[] = {common_options(), sun_options(), NULL};
    char *argv[] = {"svf", "--scene", path, NULL};
    int out_argc = 0;
    char **out_argv = NULL, err[512] = "";
    int rc = scene_expand(tables, 3, argv, &out_argc, &out_argv, err, sizeof err);
    FUZZ_CHECK(rc == 0 || rc == -1, "scene_expand returned %d", rc);
    if (rc < 0) {
        FUZZ_CHECK(err[0] && !strchr(err, '\n') && !strchr(err, '\r'),
                   "refusal without a one-line message: '%s'", err);
        FUZZ_CHECK(out_argv == NULL, "a refusal returned a vector");
        return 0;
    }
    FUZZ_CHECK(out_argv && out_argc >= 1, "expansion of %d arguments", out_argc);
    for (int i = 0; i < out_argc; ++i)
        FUZZ_CHECK(out_argv[i] != NULL, "argument %d of %d is NULL", i, out_argc);
    scene_settings set;
    memset(&set, 0, sizeof set);
    common_settings_init(&set.common);
    const char *pos[8];
    int n_pos = 0;
    char **copy = malloc(sizeof *copy * ((size_t)out_argc + 1));
    memcpy(copy, out_argv, sizeof *copy * (size_t)out_argc);
    copy[out_argc] = NULL;
    int r = opt_parse(tables, &set, out_argc, copy, pos, &n_pos, 8, err, sizeof err);
    FUZZ_CHECK(r >= -1 && r <= 1, "opt_parse returned %d", r);
    free(copy);
    scene_release();
    return 0;
}
