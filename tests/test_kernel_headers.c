/* Every header in kernels/ compiles as OpenCL C on its own, as the C twin
 * compiles it as C: the headers that the kernels and the C twin share
 * cannot hold C that only the host accepts, even those no kernel includes
 * yet (ss_sun.h, ss_insolation.h). Each is built on the default OpenCL
 * device from "#include NAME" and an empty kernel; skipped without one. */
#include "config.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include "tap.h"

static int first_device(cl_platform_id *platform, cl_device_id *device)
{
    cl_uint n = 0;
    if (clGetPlatformIDs(1, platform, &n) != CL_SUCCESS || n == 0)
        return 0;
    return clGetDeviceIDs(*platform, CL_DEVICE_TYPE_ALL, 1, device, NULL) == CL_SUCCESS;
}

static int is_header(const char *name)
{
    size_t n = strlen(name);
    return n > 2 && strcmp(name + n - 2, ".h") == 0;
}

int main(void)
{
    const char *top = getenv("TOP_SRCDIR");
    char dir[4096];
    snprintf(dir, sizeof dir, "%s/kernels", top ? top : ".");
    DIR *d = opendir(dir);
    if (!tap_ok(d != NULL, "kernels/ folder found at %s", dir))
        return tap_done();
    cl_platform_id platform;
    cl_device_id device;
    if (!first_device(&platform, &device)) {
        tap_skip("kernel headers as OpenCL C", "no OpenCL device");
        closedir(d);
        return tap_done();
    }
    cl_int err;
    cl_context ctx = clCreateContext(NULL, 1, &device, NULL, NULL, &err);
    char options[4200];
    snprintf(options, sizeof options, "-cl-std=CL1.2 -I %s", dir);
    int headers = 0;
    struct dirent *e;
    while (ctx && (e = readdir(d)) != NULL) {
        if (!is_header(e->d_name))
            continue;
        headers++;
        char source[512];
        snprintf(source, sizeof source,
                 "#include \"%s\"\n__kernel void header_compiles(__global int *x) { *x = 1; }\n",
                 e->d_name);
        const char *src = source;
        cl_program p = clCreateProgramWithSource(ctx, 1, &src, NULL, &err);
        cl_int built = p ? clBuildProgram(p, 1, &device, options, NULL, NULL) : err;
        char log[2048] = "";
        if (p && built != CL_SUCCESS)
            clGetProgramBuildInfo(p, device, CL_PROGRAM_BUILD_LOG, sizeof log - 1, log, NULL);
        for (char *c = log; *c; ++c)
            if (*c == '\n')
                *c = ' ';
        tap_ok(built == CL_SUCCESS, "kernels/%s compiles as OpenCL C 1.2 (%d)%s%.300s",
               e->d_name, (int)built, log[0] ? ": " : "", log);
        if (p)
            clReleaseProgram(p);
    }
    closedir(d);
    tap_ok(ctx && headers >= 7, "%d headers in kernels/ (at least the 7 the sweep is made of)",
           headers);
    if (ctx)
        clReleaseContext(ctx);
    return tap_done();
}
