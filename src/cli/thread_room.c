/* Threads the process can start (thread_room.h). */
#include "config.h"

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "thread_room.h"

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t done_cond = PTHREAD_COND_INITIALIZER;
static int done;

/* Holds its thread (and so its stack) until every probe has started. */
static void *wait_for_done(void *unused)
{
    (void)unused;
    pthread_mutex_lock(&lock);
    while (!done)
        pthread_cond_wait(&done_cond, &lock);
    pthread_mutex_unlock(&lock);
    return NULL;
}

/* The threads of this process the kernel still counts (Linux), or -1. */
static int threads_counted(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[128];
    int n = -1;
    while (f && n < 0 && fgets(line, sizeof line, f))
        if (sscanf(line, "Threads: %d", &n) != 1)
            n = -1;
    if (f)
        fclose(f);
    return n;
}

int thread_room_probe(int want)
{
    int before = threads_counted();
    pthread_t *threads = want > 0 ? malloc((size_t)want * sizeof *threads) : NULL;
    if (!threads)
        return 0;
    done = 0;
    int started = 0;
    while (started < want && pthread_create(&threads[started], NULL, wait_for_done, NULL) == 0)
        ++started;
    pthread_mutex_lock(&lock);
    done = 1;
    pthread_cond_broadcast(&done_cond);
    pthread_mutex_unlock(&lock);
    for (int i = 0; i < started; ++i)
        pthread_join(threads[i], NULL);
    free(threads);
    /* A joined thread still counts against ulimit -u for a moment, until the
     * kernel has released it: the pools that start next must not meet it. */
    struct timespec ms = {0, 1000000};
    for (int i = 0; i < 1000 && before >= 0 && threads_counted() > before; ++i)
        nanosleep(&ms, NULL);
    return started;
}
