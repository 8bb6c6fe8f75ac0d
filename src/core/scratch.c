/* Scratch files (scratch.h). tmpfile() would ignore TMPDIR and say nothing
 * of where it failed. */
#include "config.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "ctx_internal.h"
#include "scratch.h"

/* One line for a failure of the scratch file in s->dir, from errno. */
static ss_status scratch_failed(ss_ctx *ctx, const ss_scratch *s, const char *what)
{
    int err = errno;
    if (err == ENOSPC || err == EDQUOT)
        return ss_fail(ctx, SS_ERR_OUTPUT,
                       "the temporary folder '%s' is full (%s %s a run's cells kept between "
                       "bands): free space there or set TMPDIR to a folder with room",
                       s->dir, strerror(err), what);
    return ss_fail(ctx, SS_ERR_OUTPUT,
                   "a temporary file in '%s' failed while %s a run's cells kept between bands: "
                   "%s (TMPDIR names another folder)",
                   s->dir, what, err ? strerror(err) : "end of file");
}

ss_status ss_scratch_open(ss_ctx *ctx, ss_scratch *s)
{
    const char *env = getenv("TMPDIR");
    snprintf(s->dir, sizeof s->dir, "%s", env && env[0] ? env : P_tmpdir);
    char name[sizeof s->dir + 32];
    snprintf(name, sizeof name, "%s/skysweep-scratch-XXXXXX", s->dir);
    int fd = mkstemp(name);
    if (fd >= 0)
        unlink(name);
    s->file = fd >= 0 ? fdopen(fd, "w+b") : NULL;
    if (!s->file) {
        ss_status st = scratch_failed(ctx, s, "creating");
        if (fd >= 0)
            close(fd);
        return st;
    }
    return SS_OK;
}

ss_status ss_scratch_move(ss_ctx *ctx, ss_scratch *s, off_t at, void *data, size_t bytes,
                          int put)
{
    errno = 0;
    /* A seek flushes what was written before: a full disk may show here. */
    if (fseeko(s->file, at, SEEK_SET) != 0)
        return scratch_failed(ctx, s, "writing");
    size_t done = put ? fwrite(data, 1, bytes, s->file) : fread(data, 1, bytes, s->file);
    if (done == bytes)
        return SS_OK;
    return scratch_failed(ctx, s, put ? "writing" : "reading");
}

void ss_scratch_close(ss_scratch *s)
{
    if (s->file)
        fclose(s->file);
    s->file = NULL;
}
