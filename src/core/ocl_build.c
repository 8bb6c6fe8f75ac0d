#include "config.h"

#include <pthread.h>
#include <stdlib.h>
#include <time.h>

#include "ocl_build.h"

#define BUILD_POLL_NS 20000000L

/* One build, shared by the thread that runs it and the one that waits:
 * whichever of them lets go last frees it. */
typedef struct {
    pthread_mutex_t lock;
    pthread_cond_t done_cv;
    cl_program program;
    cl_device_id device;
    const char *options;
    cl_int err;
    int done;      /* the build has returned */
    int abandoned; /* the waiting side has gone */
} build_job;

static void job_free(build_job *job)
{
    pthread_cond_destroy(&job->done_cv);
    pthread_mutex_destroy(&job->lock);
    free(job);
}

static void *build_thread(void *arg)
{
    build_job *job = arg;
    cl_int err = clBuildProgram(job->program, 1, &job->device, job->options, NULL, NULL);
    pthread_mutex_lock(&job->lock);
    job->err = err;
    job->done = 1;
    int abandoned = job->abandoned;
    pthread_cond_signal(&job->done_cv);
    pthread_mutex_unlock(&job->lock);
    if (abandoned) {
        /* The program holds its context; releasing it releases both. */
        clReleaseProgram(job->program);
        job_free(job);
    }
    return NULL;
}

/* Starts the build's thread; 0 when it could not be started. */
static int job_start(build_job *job)
{
    pthread_attr_t attr;
    pthread_t thread;
    if (pthread_attr_init(&attr) != 0)
        return 0;
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    int started = pthread_create(&thread, &attr, build_thread, job) == 0;
    pthread_attr_destroy(&attr);
    return started;
}

/* The wait's clock: one that no change of the date can step. */
static int job_init(build_job *job)
{
    pthread_condattr_t attr;
    if (pthread_condattr_init(&attr) != 0)
        return 0;
    int ok = pthread_condattr_setclock(&attr, CLOCK_MONOTONIC) == 0 &&
             pthread_cond_init(&job->done_cv, &attr) == 0;
    pthread_condattr_destroy(&attr);
    if (ok && pthread_mutex_init(&job->lock, NULL) != 0) {
        pthread_cond_destroy(&job->done_cv);
        ok = 0;
    }
    return ok;
}

ss_status ss_ocl_build(ss_ctx *ctx, cl_program *program, cl_device_id device,
                       const char *options, cl_int *err)
{
    build_job *job = ss_calloc(1, sizeof *job);
    if (job && !job_init(job)) {
        free(job);
        job = NULL;
    }
    if (!job)
        return ss_fail(ctx, SS_ERR_MEMORY, "out of memory building the OpenCL kernels");
    job->program = *program;
    job->device = device;
    job->options = options;
    if (!job_start(job)) {
        job_free(job);
        /* No thread to spare: build here, as a cancel would have to wait anyway. */
        *err = clBuildProgram(*program, 1, &device, options, NULL, NULL);
        return SS_OK;
    }
    ss_status st = SS_OK;
    pthread_mutex_lock(&job->lock);
    while (!job->done && st == SS_OK) {
        struct timespec until;
        clock_gettime(CLOCK_MONOTONIC, &until);
        until.tv_nsec += BUILD_POLL_NS;
        if (until.tv_nsec >= 1000000000L) {
            until.tv_sec += 1;
            until.tv_nsec -= 1000000000L;
        }
        pthread_cond_timedwait(&job->done_cv, &job->lock, &until);
        if (!job->done) {
            /* The progress callback may print or cancel: not under the lock. */
            pthread_mutex_unlock(&job->lock);
            st = ss_progress(ctx, 0.0, "the kernel build");
            pthread_mutex_lock(&job->lock);
        }
    }
    int done = job->done;
    job->abandoned = !done;
    *err = job->err;
    pthread_mutex_unlock(&job->lock);
    if (!done) {
        *program = NULL;
        return st;
    }
    job_free(job);
    return st; /* a cancel as the build ended still stops the run */
}
