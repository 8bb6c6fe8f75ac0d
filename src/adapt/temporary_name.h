/* The one rule that names an output's temporaries: "dir/.NAME.<pid>.KIND[.ext]"
 * next to the output dir/NAME. Hidden, so that nobody picks one up
 * half-written; in the output's folder, so that the final rename is atomic;
 * with the output's extension last, so that GDAL names a format's side-cars
 * (an ENVI .hdr) as the output's name calls for. The raster writer, the
 * site-horizon files and the OpenImageIO and VTK modules name theirs so,
 * and the stop guard finds them by it (temporaries.h). */
#ifndef SS_TEMPORARY_NAME_H
#define SS_TEMPORARY_NAME_H

#include <limits.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Where output path is written: the file a link there points to, followed
 * link by link (a link to nowhere yet: where it points), so that a run
 * writes through a link and leaves it a link; path itself otherwise. No
 * memory is allocated (the stop guard's thread calls it). 0 when it does
 * not fit. */
int ss_output_target(const char *path, char target[PATH_MAX]);

/* Moves the finished temporary tmp over output path's target
 * (ss_output_target), giving it the permission bits of the file it
 * replaces, if there is one. rename's result: 0, or -1 with errno. */
int ss_output_rename(const char *tmp, const char *path);
/* Gives tmp the permission bits of the file at path, if there is one. */
void ss_output_keep_mode(const char *tmp, const char *path);

/* The folder of output path and the start of its temporaries' names,
 * ".NAME.<pid>.", as dirname and basename split its target
 * (ss_output_target; a trailing slash dropped); 0 when either does not
 * fit. */
int ss_temporary_prefix(const char *path, char dir[PATH_MAX], char prefix[PATH_MAX]);

/* path's temporary of this kind ("tmp", "probe"), beside its target; NULL when it does not
 * fit or memory is out. Free it. */
char *ss_temporary_name(const char *path, const char *kind);

#ifdef __cplusplus
}

#include <cstdlib>
#include <new>
#include <string>

/* The same for the C++ modules: "tmp", and a name that does not fit is
 * thrown as memory that is out, which their entry points' catch reports. */
inline std::string ss_temporary_name_cxx(const std::string &path)
{
    char *name = ss_temporary_name(path.c_str(), "tmp");
    if (!name)
        throw std::bad_alloc();
    std::string tmp = name;
    std::free(name);
    return tmp;
}
#endif

#endif
