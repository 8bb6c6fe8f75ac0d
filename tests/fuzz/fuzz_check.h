/* The invariant check of every fuzz harness: a broken invariant prints
 * what failed, where, and with which values, then aborts, which libFuzzer
 * records as a crash (and the replayers in make check as a failure). And
 * the input written to a file, for the harnesses of readers. */
#ifndef SS_FUZZ_CHECK_H
#define SS_FUZZ_CHECK_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>

#define FUZZ_CHECK(cond, ...)                                                                    \
    do {                                                                                         \
        if (!(cond)) {                                                                           \
            fprintf(stderr, "%s:%d: %s failed: ", __FILE__, __LINE__, #cond);                    \
            fprintf(stderr, __VA_ARGS__);                                                        \
            fprintf(stderr, "\n");                                                               \
            abort();                                                                             \
        }                                                                                        \
    } while (0)

/* Writes the input to `name` in a private folder made on the first call
 * (one per process, as libFuzzer runs one input at a time) and returns the
 * file's path. */
static inline char *fuzz_input_file(const char *name, const uint8_t *data, size_t size)
{
    static char path[128];
    if (!path[0]) {
        char dir[] = "/tmp/ss-fuzz.XXXXXX";
        if (!mkdtemp(dir))
            abort();
        snprintf(path, sizeof path, "%s/%s", dir, name);
    }
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, size, f) != size || fclose(f) != 0)
        abort();
    return path;
}

#endif
