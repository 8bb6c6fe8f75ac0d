/* The stop guard's thread (stop_guard.h). */
#include "config.h"

#include <fcntl.h>
#include <pthread.h>
#include <semaphore.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "stop_guard.h"
#include "temporaries.h"

/* How long the run's own thread has to stop before the guard does it:
 * it takes tens of milliseconds when nothing holds it. */
#define STOP_GRACE_NS 500000000L

static sem_t signalled;
static atomic_int stop_signal = 0; /* lock-free here, so the handler may use it */
static atomic_flag reported = ATOMIC_FLAG_INIT;
static char command_name[64];
static volatile sig_atomic_t armed = 0, speaking = 1, line_open = 0;
/* Standard error as the run began, for the one line; after a signal the
 * process's own standard error goes to /dev/null: what libraries print
 * about the interruption itself (PoCL's compiler failing once LLVM's
 * handler has removed its temporaries) is not the run's to say. */
static int report_fd = STDERR_FILENO, null_fd = -1;

void stop_guard_report(void)
{
    if (!speaking || atomic_flag_test_and_set(&reported))
        return;
    char line[160];
    int n =
        snprintf(line, sizeof line, "skysweep %s: interrupted by signal %d; no output written\n",
                 command_name, atomic_load(&stop_signal));
    if (line_open) /* the progress bar's line on standard output ends first */
        (void)!write(STDOUT_FILENO, "\n", 1);
    if (n > 0)
        (void)!write(report_fd, line, (size_t)n);
}

static void *guard(void *unused)
{
    (void)unused;
    while (sem_wait(&signalled) != 0)
        ;
    struct timespec grace = {0, STOP_GRACE_NS};
    while (nanosleep(&grace, &grace) != 0)
        ;
    ss_temporaries_abandon();
    stop_guard_report();
    _exit(128 + atomic_load(&stop_signal));
}

void stop_guard_arm(const char *command, int speaks)
{
    snprintf(command_name, sizeof command_name, "%s", command);
    speaking = speaks;
    if (armed || sem_init(&signalled, 0, 0) != 0)
        return;
    int saved = fcntl(STDERR_FILENO, F_DUPFD_CLOEXEC, 3);
    null_fd = open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved >= 0 && null_fd >= 0)
        report_fd = saved;
    else if (saved >= 0) /* no /dev/null: standard error stays as it is */
        close(saved);
    /* The signals go to the run's thread, never to the guard's wait. */
    sigset_t block, old;
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigaddset(&block, SIGHUP);
    sigaddset(&block, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &block, &old);
    pthread_attr_t attr;
    pthread_t thread;
    if (pthread_attr_init(&attr) == 0) {
        pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
        armed = pthread_create(&thread, &attr, guard, NULL) == 0;
        pthread_attr_destroy(&attr);
    }
    pthread_sigmask(SIG_SETMASK, &old, NULL);
}

void stop_guard_line_open(int open)
{
    line_open = open;
}

int stop_guard_signalled(void)
{
    return atomic_load(&stop_signal);
}

void stop_guard_signal(int sig)
{
    int none = 0;
    ss_temporaries_stopping();
    /* The first signal starts the grace; a second does not restart it. */
    if (!atomic_compare_exchange_strong(&stop_signal, &none, sig))
        return;
    if (report_fd != STDERR_FILENO)
        dup2(null_fd, STDERR_FILENO);
    if (armed)
        sem_post(&signalled);
}
