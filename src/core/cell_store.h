/* Per-cell values of a whole DEM that one run writes band by band and a
 * later run reads band by band (a product built from several walks: the
 * SVF under insolation, VAT's layers, stored horizons): in memory when the
 * DEM is held whole in one band, else in a temporary file. */
#ifndef SS_CELL_STORE_H
#define SS_CELL_STORE_H

#include "ctx_internal.h"

typedef struct ss_cell_store ss_cell_store;

/* planes planes of width x height values of elem_size bytes each. */
ss_status ss_cell_store_open(ss_ctx *ctx, const ss_source *src, int planes, size_t elem_size,
                             ss_cell_store **out);
ss_status ss_cell_store_put(ss_cell_store *s, int plane, int row0, int n_rows,
                            const void *values);
ss_status ss_cell_store_get(ss_cell_store *s, int plane, int row0, int n_rows, void *values);
/* The rows from row0 of a plane where the store holds them in memory
 * (planes lie width x height values apart), else NULL. */
const void *ss_cell_store_peek(const ss_cell_store *s, int plane, int row0);
void ss_cell_store_close(ss_cell_store *s);

/* A rows sink (ss_rows_sink) that puts output rows into plane `plane` of
 * a store (floats). */
typedef struct {
    ss_cell_store *store;
    int plane;
} ss_store_sink;
ss_status ss_store_sink_rows(void *sink, int output, int index, int row0, int n_rows,
                             const float *values);

#endif
