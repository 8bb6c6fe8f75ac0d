/* The outputs this process is writing, known by the one rule that names
 * their temporaries: "dir/.NAME.<pid>.*" next to the output dir/NAME. A run
 * stopped by a signal normally removes its own temporaries on its way out;
 * where it cannot get there in time (its thread blocked in a write to a
 * slow disk, or waiting for a device), the command line's stop guard
 * removes them from another thread with ss_temporaries_abandon and ends
 * the process (src/cli/stop_guard.c). */
#ifndef SS_TEMPORARIES_H
#define SS_TEMPORARIES_H

/* path is an output whose temporaries may exist until it is forgotten. */
void ss_temporaries_track(const char *path);
void ss_temporaries_forget(const char *path);

/* Around the renames that move an output's files into place, so that an
 * output is either moved whole or not at all. */
void ss_temporaries_hold(void);
void ss_temporaries_release(void);

/* Waits for renames in progress, keeps any other from starting and removes
 * every tracked output's temporaries. Called once, by a thread about to end
 * the process: it takes no lock a blocked writer could hold but the
 * registry's own, and calls no GDAL. */
void ss_temporaries_abandon(void);

#endif
