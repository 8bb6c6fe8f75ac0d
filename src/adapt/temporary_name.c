/* The temporaries' naming rule (temporary_name.h). */
#include "config.h"

#include <errno.h>
#include <libgen.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "temporary_name.h"

/* Links followed before one is taken for a loop. */
#define LINKS_MAX 40

int ss_output_target(const char *path, char target[PATH_MAX])
{
    char link[PATH_MAX], dir[PATH_MAX];
    struct stat st;
    if ((size_t)snprintf(target, PATH_MAX, "%s", path) >= PATH_MAX)
        return 0;
    for (int depth = 0; depth < LINKS_MAX && lstat(target, &st) == 0 && S_ISLNK(st.st_mode);
         ++depth) {
        ssize_t n = readlink(target, link, sizeof link - 1);
        if (n < 0)
            return 1;
        link[n] = '\0';
        memcpy(dir, target, PATH_MAX);
        /* A relative link is relative to the link's folder. */
        int fits = link[0] == '/'
                       ? (size_t)snprintf(target, PATH_MAX, "%s", link) < PATH_MAX
                       : (size_t)snprintf(target, PATH_MAX, "%s/%s", dirname(dir), link) <
                             PATH_MAX;
        if (!fits)
            return 0;
    }
    return 1;
}

void ss_output_keep_mode(const char *tmp, const char *path)
{
    struct stat st;
    if (stat(path, &st) == 0 && S_ISREG(st.st_mode))
        chmod(tmp, st.st_mode & 07777);
}

int ss_output_rename(const char *tmp, const char *path)
{
    char target[PATH_MAX];
    if (!ss_output_target(path, target)) {
        errno = ENAMETOOLONG;
        return -1;
    }
    ss_output_keep_mode(tmp, target);
    return rename(tmp, target);
}

/* The folder and file name of path's target as dirname and basename give
 * them; 0 when either does not fit. */
static int split(const char *path, char dir[PATH_MAX], char base[PATH_MAX])
{
    char a[PATH_MAX], b[PATH_MAX];
    if (!ss_output_target(path, a))
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
