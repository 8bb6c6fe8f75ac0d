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

/* The folder of output path and the start of its temporaries' names,
 * ".NAME.<pid>.", as dirname and basename split it (a trailing slash
 * dropped); 0 when either does not fit. */
int ss_temporary_prefix(const char *path, char dir[PATH_MAX], char prefix[PATH_MAX]);

/* path's temporary of this kind ("tmp", "probe"); NULL when it does not
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
