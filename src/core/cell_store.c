/* Per-cell values kept between runs (cell_store.h). */
#include "config.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cell_store.h"
#include "engine.h"
#include "scratch.h"

struct ss_cell_store {
    ss_ctx *ctx;
    size_t row_bytes, plane_bytes;
    unsigned char *memory; /* the DEM held whole */
    ss_scratch file;       /* else */
};

ss_status ss_cell_store_open(ss_ctx *ctx, const ss_source *src, int planes, size_t elem_size,
                             ss_cell_store **out)
{
    *out = NULL;
    ss_cell_store *s = ss_calloc(1, sizeof *s);
    if (!s)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a store of cells");
    s->ctx = ctx;
    s->row_bytes = (size_t)src->width * elem_size;
    s->plane_bytes = s->row_bytes * (size_t)src->height;
    int whole = src->z && ss_source_band_rows(src) == src->height;
    size_t bytes = s->plane_bytes * (size_t)planes;
    if (whole && !(s->memory = ss_malloc(bytes ? bytes : 1))) {
        free(s);
        return ss_fail(ctx, SS_ERR_MEMORY, "cannot allocate %zu MB to keep %d planes of cells",
                       bytes >> 20, planes);
    }
    ss_status st = whole ? SS_OK : ss_scratch_open(ctx, &s->file);
    if (st != SS_OK) {
        free(s);
        return st;
    }
    *out = s;
    return SS_OK;
}

static ss_status move_rows(ss_cell_store *s, int plane, int row0, int n_rows, void *values,
                           int put)
{
    size_t at = (size_t)plane * s->plane_bytes + (size_t)row0 * s->row_bytes;
    size_t n = (size_t)n_rows * s->row_bytes;
    if (s->memory) {
        if (put)
            memcpy(s->memory + at, values, n);
        else
            memcpy(values, s->memory + at, n);
        return SS_OK;
    }
    return ss_scratch_move(s->ctx, &s->file, (off_t)at, values, n, put);
}

ss_status ss_cell_store_put(ss_cell_store *s, int plane, int row0, int n_rows,
                            const void *values)
{
    return move_rows(s, plane, row0, n_rows, (void *)values, 1);
}

ss_status ss_cell_store_get(ss_cell_store *s, int plane, int row0, int n_rows, void *values)
{
    return move_rows(s, plane, row0, n_rows, values, 0);
}

const void *ss_cell_store_peek(const ss_cell_store *s, int plane, int row0)
{
    if (!s->memory)
        return NULL;
    return s->memory + (size_t)plane * s->plane_bytes + (size_t)row0 * s->row_bytes;
}

void ss_cell_store_close(ss_cell_store *s)
{
    if (!s)
        return;
    free(s->memory);
    ss_scratch_close(&s->file);
    free(s);
}

ss_status ss_store_sink_rows(void *sink, int output, int index, int row0, int n_rows,
                             const float *values)
{
    (void)output, (void)index;
    ss_store_sink *k = sink;
    return ss_cell_store_put(k->store, k->plane, row0, n_rows, values);
}
