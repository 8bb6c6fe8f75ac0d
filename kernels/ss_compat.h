/* Lets one header be compiled both as OpenCL C (the kernels/ .cl files) and as C11 (the
 * host reference), so the kernels and their C twin cannot drift apart.
 * Only the few spellings that differ between the two languages live here. */
#ifndef SS_COMPAT_H
#define SS_COMPAT_H

#ifdef __OPENCL_VERSION__
#define SS_GLOBAL __global
#define SS_FN inline __attribute__((always_inline))
typedef long ss_i64;
#define SS_SQRT(x) sqrt(x)
#define SS_FABS(x) fabs(x)
#define SS_ATAN(x) atan(x)
#define SS_ATAN2(y, x) atan2((y), (x))
#define SS_SIN(x) sin(x)
#define SS_COS(x) cos(x)
#define SS_FMAX(a, b) fmax((a), (b))
#define SS_FMIN(a, b) fmin((a), (b))
#define SS_POW(x, y) pow((x), (y))
#define SS_EXP(x) exp(x)
#define SS_ISFINITE(x) isfinite(x)
/* Global int atomics (OpenCL 1.1 core): return the value before. */
#define SS_ATOMIC_ADD(p, v) atomic_add((p), (v))
#define SS_ATOMIC_MAX(p, v) atomic_max((p), (v))
#else
#include <math.h>
#include <stdint.h>
#define SS_GLOBAL
#define SS_FN static inline __attribute__((always_inline))
typedef int64_t ss_i64;
#define SS_SQRT(x) sqrtf(x)
#define SS_FABS(x) fabsf(x)
#define SS_ATAN(x) atanf(x)
#define SS_ATAN2(y, x) atan2f((y), (x))
#define SS_SIN(x) sinf(x)
#define SS_COS(x) cosf(x)
#define SS_FMAX(a, b) fmaxf((a), (b))
#define SS_FMIN(a, b) fminf((a), (b))
#define SS_POW(x, y) powf((x), (y))
#define SS_EXP(x) expf(x)
#define SS_ISFINITE(x) isfinite(x)
#define SS_ATOMIC_ADD(p, v) __atomic_fetch_add((p), (v), __ATOMIC_RELAXED)
#define SS_ATOMIC_MAX(p, v) ss_atomic_max_int((p), (v))
static inline int ss_atomic_max_int(int *p, int v)
{
    int old = __atomic_load_n(p, __ATOMIC_RELAXED);
    while (old < v && !__atomic_compare_exchange_n(p, &old, v, 1, __ATOMIC_RELAXED,
                                                   __ATOMIC_RELAXED))
        ;
    return old;
}
#endif

#define SS_PI_F 3.14159265358979323846f
#define SS_DEG_PER_RAD_F 57.295779513082320876f
/* Value written where the input is nodata (DESIGN.md: outputs use -9999). */
#define SS_NODATA_OUT (-9999.0f)

#endif
