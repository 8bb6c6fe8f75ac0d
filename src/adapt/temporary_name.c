/* The temporaries' naming rule (temporary_name.h). */
#include "config.h"

#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "temporary_name.h"

/* path's folder and file name as dirname and basename give them; 0 when
 * either does not fit. */
static int split(const char *path, char dir[PATH_MAX], char base[PATH_MAX])
{
    char a[PATH_MAX], b[PATH_MAX];
    if ((size_t)snprintf(a, sizeof a, "%s", path) >= sizeof a)
        return 0;
    memcpy(b, a, sizeof b);
    return (size_t)snprintf(dir, PATH_MAX, "%s", dirname(a)) < PATH_MAX &&
           (size_t)snprintf(base, PATH_MAX, "%s", basename(b)) < PATH_MAX;
}

int ss_temporary_prefix(const char *path, char dir[PATH_MAX], char prefix[PATH_MAX])
{
    char base[PATH_MAX];
    return split(path, dir, base) &&
           (size_t)snprintf(prefix, PATH_MAX, ".%s.%ld.", base, (long)getpid()) < PATH_MAX;
}

char *ss_temporary_name(const char *path, const char *kind)
{
    char dir[PATH_MAX], base[PATH_MAX];
    if (!split(path, dir, base))
        return NULL;
    const char *dot = strrchr(base, '.'), *ext = dot && dot > base ? dot : "";
    size_t n = strlen(dir) + 2 * strlen(base) + strlen(kind) + 40;
    char *name = malloc(n);
    if (name)
        snprintf(name, n, "%s/.%s.%ld.%s%s", dir, base, (long)getpid(), kind, ext);
    return name;
}
