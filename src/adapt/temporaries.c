/* The temporaries' names and registry, and their removal by a thread other
 * than the writer's (temporaries.h). */
#include "config.h"

#include <dirent.h>
#include <ftw.h>
#include <libgen.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "temporaries.h"

typedef struct tracked {
    struct tracked *next;
    char path[]; /* the output's path */
} tracked;

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static tracked *outputs = NULL;
static volatile sig_atomic_t stopping = 0;

/* path's folder and file name as dirname and basename give them (a
 * trailing slash dropped); 0 when either does not fit. */
static int split(const char *path, char dir[PATH_MAX], char base[PATH_MAX])
{
    char a[PATH_MAX], b[PATH_MAX];
    if ((size_t)snprintf(a, sizeof a, "%s", path) >= sizeof a)
        return 0;
    memcpy(b, a, sizeof b);
    return (size_t)snprintf(dir, PATH_MAX, "%s", dirname(a)) < PATH_MAX &&
           (size_t)snprintf(base, PATH_MAX, "%s", basename(b)) < PATH_MAX;
}

char *ss_temporaries_name(const char *path, const char *kind)
{
    char dir[PATH_MAX], base[PATH_MAX];
    if (!split(path, dir, base))
        return NULL;
    const char *dot = strrchr(base, '.'), *ext = dot && dot > base ? dot : "";
    size_t n = strlen(dir) + 2 * strlen(base) + strlen(kind) + 40;
    char *name = malloc(n);
    if (name)
        snprintf(name, n, "%s/.%s.%ld.%s%s", dir, base, (long)getpid(), kind, ext);
    return name;
}

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
    char dir[PATH_MAX], base[PATH_MAX], prefix[PATH_MAX];
    if (!split(path, dir, base))
        return;
    int n = snprintf(prefix, sizeof prefix, ".%s.%ld.", base, (long)getpid());
    DIR *d = n > 0 && (size_t)n < sizeof prefix ? opendir(dir) : NULL;
    for (struct dirent *e; d && (e = readdir(d));) {
        char full[PATH_MAX];
        if (strncmp(e->d_name, prefix, (size_t)n) == 0 &&
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
