/* A stalled disk for tests/test_faults.sh, preloaded (LD_PRELOAD) into a
 * run: any write to a file whose name holds HOLD_WRITES_TO (an output's
 * temporary) never returns, whatever signal comes, as a write to a disk
 * that has stopped answering. Only the stop guard (src/cli/stop_guard.c)
 * can then end the run. Every other write passes through. */
#include "config.h"

#include <dlfcn.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <time.h>
#include <unistd.h>

ssize_t write(int fd, const void *buf, size_t n);
ssize_t pwrite64(int fd, const void *buf, size_t n, off_t offset);
size_t fwrite(const void *buf, size_t size, size_t count, FILE *stream);

/* Whether fd's file name holds $HOLD_WRITES_TO. */
static int held(int fd)
{
    const char *mark = getenv("HOLD_WRITES_TO");
    char link[64], name[PATH_MAX];
    snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
    ssize_t len = mark && *mark ? readlink(link, name, sizeof name - 1) : -1;
    if (len <= 0)
        return 0;
    name[len] = '\0';
    return strstr(name, mark) != NULL;
}

static void stall(void)
{
    for (;;) {
        struct timespec t = {3600, 0};
        nanosleep(&t, NULL);
    }
}

ssize_t write(int fd, const void *buf, size_t n)
{
    static ssize_t (*next)(int, const void *, size_t);
    if (!next)
        *(void **)&next = dlsym(RTLD_NEXT, "write");
    if (held(fd))
        stall();
    return next(fd, buf, n);
}

ssize_t pwrite64(int fd, const void *buf, size_t n, off_t offset)
{
    static ssize_t (*next)(int, const void *, size_t, off_t);
    if (!next)
        *(void **)&next = dlsym(RTLD_NEXT, "pwrite64");
    if (held(fd))
        stall();
    return next(fd, buf, n, offset);
}

size_t fwrite(const void *buf, size_t size, size_t count, FILE *stream)
{
    static size_t (*next)(const void *, size_t, size_t, FILE *);
    if (!next)
        *(void **)&next = dlsym(RTLD_NEXT, "fwrite");
    if (held(fileno(stream)))
        stall();
    return next(buf, size, count, stream);
}
