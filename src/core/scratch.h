/* Scratch files: the unnamed temporaries a run in bands keeps its cells in
 * between visits (engine.c, cell_store.c). They lie in $TMPDIR, else /tmp,
 * unlinked as soon as made, so nothing is left whatever ends the process;
 * a failure names the folder (a full disk: which one is full). */
#ifndef SS_SCRATCH_H
#define SS_SCRATCH_H

#include <stdio.h>
#include <sys/types.h>

#include "skysweep.h"

typedef struct {
    FILE *file;
    char dir[512]; /* the folder it lies in */
} ss_scratch;

ss_status ss_scratch_open(ss_ctx *ctx, ss_scratch *s);
/* Writes (put) or reads bytes at offset at. */
ss_status ss_scratch_move(ss_ctx *ctx, ss_scratch *s, off_t at, void *data, size_t bytes,
                          int put);
/* Closes it, if open. */
void ss_scratch_close(ss_scratch *s);

#endif
