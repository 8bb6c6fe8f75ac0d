/* Text inputs (scene files, weather files, sites files) are regular files
 * of a stated size at most, checked before they are opened: a device such
 * as /dev/zero would be read for ever, a FIFO would block and a huge file
 * would be held in memory. One check for all, so that each input is
 * refused the same way, in one line naming the cap. */
#ifndef SS_TEXT_INPUT_H
#define SS_TEXT_INPUT_H

#include <stddef.h>

/* Whether path is a regular file of at most max_bytes; else 0, with one
 * line into why: "<what> '<path>' is not a regular file ..." or "... is over
 * <cap>, the cap on a <what>", or that it cannot be read and why. */
int ss_text_input_ok(const char *path, const char *what, long long max_bytes, char *why,
                     size_t why_size);

#endif
