/* The registry of outputs being written and the removal of their
 * temporaries by a thread other than the writer's (temporaries.h). */
#include "config.h"

#include <dirent.h>
#include <ftw.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "temporaries.h"
#include "temporary_name.h"

typedef struct tracked {
    struct tracked *next;
    char path[]; /* the output's path */
} tracked;

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static tracked *outputs = NULL;
static volatile sig_atomic_t stopping = 0;

void ss_temporaries_track(const char *path)
{
    size_t n = strlen(path) + 1;
    tracked *t = malloc(sizeof *t + n);
    if (!t)
        return; /* its temporaries are then removed only by the writer */
    memcpy(t->path, path, n);
    pthread_mutex_lock(&lock);
    t->next = outputs;
    outputs = t;
    pthread_mutex_unlock(&lock);
}

void ss_temporaries_forget(const char *path)
{
    pthread_mutex_lock(&lock);
    for (tracked **p = &outputs; *p; p = &(*p)->next)
        if (strcmp((*p)->path, path) == 0) {
            tracked *gone = *p;
            *p = gone->next;
            free(gone);
            break;
        }
    pthread_mutex_unlock(&lock);
}

void ss_temporaries_stopping(void)
{
    stopping = 1;
}

int ss_temporaries_hold(void)
{
    pthread_mutex_lock(&lock);
    if (!stopping)
        return 1;
    pthread_mutex_unlock(&lock);
    return 0;
}

void ss_temporaries_release(void)
{
    pthread_mutex_unlock(&lock);
}

static int remove_entry(const char *path, const struct stat *st, int type, struct FTW *ftw)
{
    (void)st, (void)type, (void)ftw;
    remove(path);
    return 0;
}

/* Removes dir/.NAME.<pid>.* of output dir/NAME: files, and folders (a
 * format such as Zarr) with what they hold. */
static void remove_temporaries_of(const char *path)
{
    char dir[PATH_MAX], prefix[PATH_MAX];
    if (!ss_temporary_prefix(path, dir, prefix))
        return;
    size_t n = strlen(prefix);
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));) {
        char full[PATH_MAX];
        if (strncmp(e->d_name, prefix, n) == 0 &&
            (size_t)snprintf(full, sizeof full, "%s/%s", dir, e->d_name) < sizeof full)
            nftw(full, remove_entry, 16, FTW_DEPTH | FTW_PHYS);
    }
    if (d)
        closedir(d);
}

void ss_temporaries_abandon(void)
{
    pthread_mutex_lock(&lock); /* never released: the process is ending */
    stopping = 1;
    for (const tracked *t = outputs; t; t = t->next)
        remove_temporaries_of(t->path);
}
