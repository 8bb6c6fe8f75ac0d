/* The stop guard (src/cli/stop_guard.c) ends a run whose thread cannot
 * stop: a child process arms it, tracks an output and makes that output's
 * temporaries (a file, a side-car, a folder as Zarr writes), then blocks
 * as a write to a stalled disk would. After SIGINT it must end within the
 * grace and a little more, with exit 130 and one line on standard error,
 * its temporaries gone, the existing output and another process's
 * temporary untouched. Then the same where the run reported the stop
 * itself after a library spoke of it (still one line), where a rename was under way (the guard
 * waits for it: the output is moved whole), and where the run finished its file after the signal
 * (no rename starts then). Names that only look alike, and an output no longer tracked, keep their
 * files. */
#include "config.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "stop_guard.h"
#include "tap.h"
#include "temporaries.h"

enum { BLOCKED, REPORTED, RENAMING, FINISHING };

static char dir[64];

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static char *read_file(const char *path, char *buf, size_t n)
{
    FILE *f = fopen(path, "r");
    size_t got = f ? fread(buf, 1, n - 1, f) : 0;
    buf[got] = '\0';
    if (f)
        fclose(f);
    return buf;
}

static void on_signal(int sig)
{
    stop_guard_signal(sig);
}

/* Sleeps s seconds whatever signals arrive. */
static void sleep_through(double s)
{
    struct timespec t = {(time_t)s, (long)((s - (double)(time_t)s) * 1e9)};
    while (nanosleep(&t, &t) != 0)
        ;
}

/* The child: a run blocked as the case says, never ending by itself. */
static void child(int how)
{
    char path[128], tmp[160], side[200], folder[160], inner[200];
    snprintf(path, sizeof path, "%s/out.tif", dir);
    snprintf(tmp, sizeof tmp, "%s/.out.tif.%ld.tmp.tif", dir, (long)getpid());
    snprintf(side, sizeof side, "%s.aux.xml", tmp);
    snprintf(folder, sizeof folder, "%s/.out.tif.%ld.probe", dir, (long)getpid());
    snprintf(inner, sizeof inner, "%s/chunk", folder);
    alarm(5); /* a guard that never fires fails the case, not the suite */
    stop_guard_arm("test", 1);
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    ss_temporaries_track(path);
    /* Not this output's temporaries, or not tracked: kept. */
    char keep[3][160];
    snprintf(keep[0], sizeof keep[0], "%s/.out.tif2.%ld.tmp.tif", dir, (long)getpid());
    snprintf(keep[1], sizeof keep[1], "%s/.out.tif.%ld9.tmp.tif", dir, (long)getpid());
    snprintf(keep[2], sizeof keep[2], "%s/.done.tif.%ld.tmp.tif", dir, (long)getpid());
    for (int i = 0; i < 3; ++i)
        write_file(keep[i], "kept");
    char done[160];
    snprintf(done, sizeof done, "%s/done.tif", dir);
    ss_temporaries_track(done);
    ss_temporaries_forget(done);
    write_file(tmp, "new");
    write_file(side, "<PAMDataset/>");
    mkdir(folder, 0755);
    write_file(inner, "chunk");
    if (how == RENAMING)
        ss_temporaries_hold();
    char ready[160];
    snprintf(ready, sizeof ready, "%s/ready", dir);
    write_file(ready, "");
    if (how == REPORTED) {
        while (!stop_guard_signalled())
            sleep_through(0.01);
        fprintf(stderr, "a library's words on the interruption\n");
        stop_guard_report();
    }
    if (how == RENAMING) {
        while (!stop_guard_signalled())
            sleep_through(0.01);
        sleep_through(0.8); /* a rename that runs past the grace */
        rename(tmp, path);
        ss_temporaries_release();
    }
    if (how == FINISHING) {
        while (!stop_guard_signalled())
            sleep_through(0.01);
        if (ss_temporaries_hold()) { /* wrong: the output would be replaced */
            rename(tmp, path);
            ss_temporaries_release();
        }
    }
    for (;;)
        sleep_through(10);
}

static int count_temporaries(long pid)
{
    char prefix[64];
    int n = snprintf(prefix, sizeof prefix, ".out.tif.%ld.", pid), found = 0;
    DIR *d = opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));)
        found += strncmp(e->d_name, prefix, (size_t)n) == 0;
    if (d)
        closedir(d);
    return found;
}

static void run_case(int how, const char *what)
{
    char path[128], other[128], ready[128], err[128], buf[256];
    snprintf(path, sizeof path, "%s/out.tif", dir);
    snprintf(other, sizeof other, "%s/.out.tif.1.tmp.tif", dir); /* init's: never ours */
    snprintf(ready, sizeof ready, "%s/ready", dir);
    snprintf(err, sizeof err, "%s/stderr", dir);
    write_file(path, "precious");
    write_file(other, "another's");
    unlink(ready);
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        int fd = open(err, O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(fd, STDERR_FILENO);
        child(how);
    }
    for (int waited = 0; access(ready, F_OK) != 0 && waited < 500; ++waited)
        sleep_through(0.01);
    double t0 = now();
    kill(pid, SIGINT);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
        ;
    double seconds = now() - t0;
    int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    read_file(err, buf, sizeof buf);
    int lines = 0;
    for (const char *c = buf; *c; ++c)
        lines += *c == '\n';
    const char *line = "skysweep test: interrupted by signal 2; no output written\n";
    double least = how == RENAMING ? 0.8 : 0.5;
    tap_ok(code == 130 && lines == 1 && strcmp(buf, line) == 0,
           "%s: exit %d (want 130), standard error '%.*s'", what, code, (int)strcspn(buf, "\n"),
           buf);
    tap_ok(seconds >= least - 0.05 && seconds < least + 1.0,
           "%s: ended %.3f s after the signal (the grace or the rename, %.1f s, and at most 1 s "
           "more)",
           what, seconds, least);
    tap_ok(count_temporaries(pid) == 0, "%s: its temporaries are removed", what);
    const char *want = how == RENAMING ? "new" : "precious";
    tap_ok(strcmp(read_file(path, buf, sizeof buf), want) == 0,
           "%s: the output holds '%s' (want '%s')", what, buf, want);
    tap_ok(strcmp(read_file(other, buf, sizeof buf), "another's") == 0,
           "%s: another process's temporary is kept", what);
    const char *stems[3] = {".out.tif2.", ".out.tif.", ".done.tif."};
    const char *tails[3] = {".tmp.tif", "9.tmp.tif", ".tmp.tif"};
    int all = 1;
    for (int i = 0; i < 3; ++i) {
        char name[64], full[160];
        snprintf(name, sizeof name, "%s%ld%s", stems[i], (long)pid, tails[i]);
        snprintf(full, sizeof full, "%s/%s", dir, name);
        all &= strcmp(read_file(full, buf, sizeof buf), "kept") == 0;
        unlink(full);
    }
    tap_ok(all, "%s: a longer output's, another pid's and a forgotten output's files are kept",
           what);
}

int main(void)
{
    /* mkdtemp's template (in /tmp, so that every path built from it fits
     * the short buffers below): a folder of this run's own */
    snprintf(dir, sizeof dir, "/tmp/ss-stop-guard.XXXXXX");
    if (!mkdtemp(dir)) {
        tap_skip("the stop guard", "no temporary folder");
        return tap_done();
    }
    run_case(BLOCKED, "a run blocked in a write");
    run_case(REPORTED, "a run that reported the stop, then blocked");
    run_case(RENAMING, "a rename under way at the signal");
    run_case(FINISHING, "a run that finished its file after the signal");
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0)
        tap_diag("could not remove %s", dir);
    return tap_done();
}
