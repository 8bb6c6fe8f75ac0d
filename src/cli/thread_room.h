/* Threads the process can start, probed before a run relies on them. The
 * pools that start them do not survive a refusal (ulimit -u counts a user's
 * threads, ulimit -v their stacks): GDAL's compression pool waits for ever
 * for a worker that never started, libgomp exits 1 and PoCL aborts. */
#ifndef SS_THREAD_ROOM_H
#define SS_THREAD_ROOM_H

/* How many of want threads this process could start at once (each with
 * the default stack, as the pools take it), started and ended here. */
int thread_room_probe(int want);

#endif
