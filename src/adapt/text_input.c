/* The size cap on text inputs (text_input.h). */
#include "config.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "text_input.h"

/* stat, not open: opening a FIFO without a writer would block. */
int ss_text_input_ok(const char *path, const char *what, long long max_bytes, char *why,
                     size_t why_size)
{
    struct stat st;
    char cap[32];
    long long mib = max_bytes >> 20;
    snprintf(cap, sizeof cap, "%lld %s", mib > 0 ? mib : max_bytes >> 10, mib > 0 ? "MiB" : "KiB");
    if (stat(path, &st) != 0)
        snprintf(why, why_size, "cannot read %s '%s': %s", what, path, strerror(errno));
    else if (!S_ISREG(st.st_mode))
        snprintf(why, why_size, "%s '%s' is not a regular file; a %s must be one of at most %s",
                 what, path, what, cap);
    else if ((long long)st.st_size > max_bytes)
        snprintf(why, why_size, "%s '%s' is over %s, the cap on a %s", what, path, cap, what);
    else
        return 1;
    return 0;
}
