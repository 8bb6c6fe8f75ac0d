/* The run's files and the one check that keeps outputs off inputs
 * (run_files.h). */
#include "config.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_io.h"
#include "run_files.h"

int ss_run_files_add(ss_run_files *set, const char *path, const char *named_by, int output)
{
    if (set->n == set->cap) {
        int cap = set->cap ? 2 * set->cap : 16;
        ss_run_file *grown = realloc(set->files, sizeof *grown * (size_t)cap);
        if (!grown)
            return -1;
        set->files = grown;
        set->cap = cap;
    }
    char *copy = strdup(path);
    if (!copy)
        return -1;
    ss_run_file *f = &set->files[set->n++];
    f->path = copy;
    f->output = output;
    snprintf(f->named_by, sizeof f->named_by, "%s", named_by);
    return 0;
}

ss_status ss_run_files_check(ss_ctx *ctx, const ss_run_files *set)
{
    /* Each output against every file named before it, input or output. */
    for (int i = 0; i < set->n; ++i)
        for (int j = 0; j < set->n; ++j) {
            const ss_run_file *out = &set->files[i], *other = &set->files[j];
            if (!out->output || i == j || (other->output && j > i) ||
                !ss_same_output(out->path, other->path))
                continue;
            if (other->output)
                return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                                    "'%s' (%s) and '%s' (%s) are the same output; name different "
                                    "files",
                                    other->path, other->named_by, out->path, out->named_by);
            return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                                "output '%s' (%s) is also an input ('%s', %s); choose another "
                                "name",
                                out->path, out->named_by, other->path, other->named_by);
        }
    return SS_OK;
}

void ss_run_files_clear(ss_run_files *set)
{
    for (int i = 0; i < set->n; ++i)
        free(set->files[i].path);
    free(set->files);
    memset(set, 0, sizeof *set);
}
