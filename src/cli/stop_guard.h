/* Ctrl-C (SIGINT), SIGTERM, SIGHUP or SIGPIPE ends a run within a second. The run's own
 * thread sees the cancel between lines or batches, cleans up and reports;
 * where it cannot within half a second (behind work queued on a device,
 * which cannot be stopped, or in a slow write), this guard does it from a
 * thread of its own: it removes the outputs' temporaries (temporaries.h),
 * prints the run's one line and ends the process. On a disk that has
 * stalled altogether, its own removals wait too. */
#ifndef SS_STOP_GUARD_H
#define SS_STOP_GUARD_H

/* Starts the guard's thread (once a process) for a run of command; speaks
 * 0 keeps its line unprinted (an MPI rank other than 0). */
void stop_guard_arm(const char *command, int speaks);

/* Called by the signal handler (async-signal-safe): starts the grace; no
 * output is moved into place from now on, and nothing but the run's line
 * reaches standard error. */
void stop_guard_signal(int sig);

/* The signal that stopped the run, or 0. */
int stop_guard_signalled(void);

/* Whether a progress bar's line is open on standard output: it is ended
 * before the run's line is printed. */
void stop_guard_line_open(int open);

/* Prints the interrupted run's one line to standard error unless it was
 * printed already; both the run and the guard report through it. */
void stop_guard_report(void);

#endif
