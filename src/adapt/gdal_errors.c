/* GDAL's error handler and what it keeps (gdal_errors.h). */
#include "config.h"

#include <errno.h>
#include <pthread.h>
#include <stdio.h>
#include <string.h>

#include <cpl_error.h>

#include "gdal_errors.h"

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static char first_message[1024];
static int first_errno, first_number, failed;

static void keep_first_failure(CPLErr level, CPLErrorNum number, const char *message)
{
    int saved_errno = errno;
    if (level < CE_Failure)
        return;
    pthread_mutex_lock(&lock);
    if (!failed) {
        failed = 1;
        first_errno = saved_errno;
        first_number = number;
        snprintf(first_message, sizeof first_message, "%s", message ? message : "");
    }
    pthread_mutex_unlock(&lock);
}

void ss_gdal_errors_install(void)
{
    CPLSetErrorHandler(keep_first_failure);
}

void ss_gdal_errors_reset(void)
{
    pthread_mutex_lock(&lock);
    failed = 0;
    first_errno = 0;
    first_number = 0;
    first_message[0] = '\0';
    pthread_mutex_unlock(&lock);
    CPLErrorReset();
}

int ss_gdal_failed(void)
{
    pthread_mutex_lock(&lock);
    int f = failed;
    pthread_mutex_unlock(&lock);
    return f;
}

const char *ss_gdal_message(void)
{
    const char *m = CPLGetLastErrorMsg();
    return m && *m ? m : "no details from GDAL";
}

/* What a user can do something about, from errno or from the words libtiff
 * and the other drivers copy from strerror. */
static const char *cause_of(int err, const char *message)
{
    if (err == ENOSPC || strstr(message, "No space left"))
        return "no space left on the device";
    if (err == EFBIG || strstr(message, "File too large"))
        return "the file size limit is reached (ulimit -f)";
#ifdef EDQUOT
    if (err == EDQUOT || strstr(message, "quota exceeded"))
        return "the disk quota is exceeded";
#endif
    if (err == EROFS || strstr(message, "Read-only file system"))
        return "the file system is read-only";
    return NULL;
}

const char *ss_gdal_io_cause(void)
{
    pthread_mutex_lock(&lock);
    const char *cause = failed ? cause_of(first_errno, first_message) : NULL;
    pthread_mutex_unlock(&lock);
    return cause;
}

int ss_gdal_out_of_memory(void)
{
    pthread_mutex_lock(&lock);
    /* libtiff's codecs say so in words only ("Cannot allocate compressor"). */
    int oom = failed && (first_number == CPLE_OutOfMemory || strcasestr(first_message, "cannot allocate") ||
                         strcasestr(first_message, "out of memory"));
    pthread_mutex_unlock(&lock);
    return oom;
}

const char *ss_gdal_failure(char *buf, size_t size)
{
    int err_now = errno; /* a driver that fails without a word leaves the system's */
    pthread_mutex_lock(&lock);
    const char *message = failed && first_message[0] ? first_message : ss_gdal_message();
    const char *cause = cause_of(failed ? first_errno : err_now, message);
    if (cause)
        snprintf(buf, size, "%s (GDAL: %s)", cause, message);
    else
        snprintf(buf, size, "%s", message);
    pthread_mutex_unlock(&lock);
    return buf;
}
