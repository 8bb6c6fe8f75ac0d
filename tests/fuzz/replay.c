/* Replays fuzz inputs through a harness's LLVMFuzzerTestOneInput without
 * libFuzzer, so that `make check` (and the sanitizer build) re-runs every
 * crash ever found and the seed corpus. Linked with one fuzz_*.c; FUZZ_NAME
 * is that harness's name. With no arguments it replays
 * $TOP_SRCDIR/tests/fuzz/regressions/FUZZ_NAME and .../corpus/FUZZ_NAME
 * (TOP_SRCDIR defaults to the source tree it was built from); arguments
 * name files or folders to replay instead. One TAP line per folder: a
 * failing input aborts, and the TAP driver reports the crash. */
#include "config.h"

#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef FUZZ_NAME
#error "compile with -DFUZZ_NAME='\"fuzz_xxx\"'"
#endif

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv) __attribute__((weak));

static FILE *tap; /* the harness may redirect stdout */
static int tap_n;

static int replay_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t cap = 4096, len = 0;
    uint8_t *buf = malloc(cap);
    size_t got;
    while (buf && (got = fread(buf + len, 1, cap - len, f)) > 0) {
        len += got;
        if (len == cap) {
            uint8_t *bigger = realloc(buf, cap *= 2);
            if (!bigger) {
                free(buf);
                buf = NULL;
            }
            buf = bigger;
        }
    }
    fclose(f);
    if (!buf)
        return -1;
    /* Exactly len bytes, so that reading past them is caught. */
    uint8_t *exact = malloc(len ? len : 1);
    memcpy(exact, buf, len);
    free(buf);
    fprintf(stderr, "replay %s (%zu bytes)\n", path, len);
    LLVMFuzzerTestOneInput(exact, len);
    free(exact);
    return 0;
}

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Replays a file or every file of a folder (sorted); returns the count or -1. */
static int replay_path(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return -1;
    if (!S_ISDIR(st.st_mode))
        return replay_file(path) == 0 ? 1 : -1;
    DIR *d = opendir(path);
    if (!d)
        return -1;
    char **names = NULL;
    size_t n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] == '.')
            continue;
        names = realloc(names, (n + 1) * sizeof *names);
        names[n++] = strdup(e->d_name);
    }
    closedir(d);
    qsort(names, n, sizeof *names, cmp_names);
    int count = 0;
    for (size_t i = 0; i < n; ++i) {
        char file[4096];
        snprintf(file, sizeof file, "%s/%s", path, names[i]);
        if (replay_file(file) == 0)
            count++;
        free(names[i]);
    }
    free(names);
    return count;
}

int main(int argc, char **argv)
{
    int out = dup(1);
    tap = out >= 0 ? fdopen(out, "w") : stdout;
    if (LLVMFuzzerInitialize)
        LLVMFuzzerInitialize(&argc, &argv);
    int failed = 0;
    if (argc > 1) {
        for (int i = 1; i < argc; ++i) {
            int n = replay_path(argv[i]);
            fprintf(tap, "%s %d - %s: %s replayed (%d inputs)\n", n >= 0 ? "ok" : "not ok",
                    ++tap_n, FUZZ_NAME, argv[i], n);
            failed += n < 0;
        }
    } else {
        const char *top = getenv("TOP_SRCDIR");
#ifdef TOP_SRCDIR
        if (!top)
            top = TOP_SRCDIR;
#endif
        if (!top)
            top = ".";
        const char *kinds[] = {"regressions", "corpus"};
        for (int k = 0; k < 2; ++k) {
            char dir[4096];
            snprintf(dir, sizeof dir, "%s/tests/fuzz/%s/%s", top, kinds[k], FUZZ_NAME);
            int n = replay_path(dir);
            if (n < 0)
                fprintf(tap, "ok %d - %s %s # SKIP no folder %s\n", ++tap_n, FUZZ_NAME, kinds[k],
                        dir);
            else
                fprintf(tap, "ok %d - %s: %d %s inputs replayed without a failure\n", ++tap_n,
                        FUZZ_NAME, n, kinds[k]);
            fflush(tap);
        }
    }
    fprintf(tap, "1..%d\n", tap_n);
    fclose(tap);
    return failed ? 1 : 0;
}
