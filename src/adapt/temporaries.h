/* The outputs this process is writing. A run stopped by a signal normally
 * removes its own temporaries (temporary_name.h) on its way out; where its
 * thread cannot get there in time (waiting for work queued on a device, or
 * for a slow disk), the command line's stop guard removes them from a
 * thread of its own with ss_temporaries_abandon and ends the process
 * (src/cli/stop_guard.c). */
#ifndef SS_TEMPORARIES_H
#define SS_TEMPORARIES_H

/* path is an output whose temporaries may exist until it is forgotten. */
void ss_temporaries_track(const char *path);
void ss_temporaries_forget(const char *path);

/* The process is stopping: no rename starts from now on. Async-signal-safe. */
void ss_temporaries_stopping(void);

/* Around the renames that move an output's files into place, and nothing
 * else, so that an output is moved whole or not at all. hold returns 0,
 * and takes nothing, once the process is stopping. */
int ss_temporaries_hold(void);
void ss_temporaries_release(void);

/* Waits for renames under way, keeps any other from starting and removes
 * every tracked output's temporaries. Called once, by a thread about to
 * end the process: it takes no lock but the registry's and calls no GDAL.
 * Files a still-running writer creates after it has looked are not seen. */
void ss_temporaries_abandon(void);

#endif
