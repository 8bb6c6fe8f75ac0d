/* An OpenCL program's build that a cancelled run does not wait for. */
#ifndef SS_OCL_BUILD_H
#define SS_OCL_BUILD_H

#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>

#include "ctx_internal.h"

/* Builds *program for device with options, in a thread of its own, while
 * this one reports progress every 20 ms. PoCL's first compile of the
 * kernels on a machine takes seconds and cannot be interrupted, and Ctrl-C
 * must stop a run within a second. Returns SS_OK with the build's own
 * result in *err, or SS_ERR_CANCELLED (the context's message set). A build
 * still running then is left to finish alone: it owns and releases the
 * program, and *program is NULL. */
ss_status ss_ocl_build(ss_ctx *ctx, cl_program *program, cl_device_id device,
                       const char *options, cl_int *err);

#endif
