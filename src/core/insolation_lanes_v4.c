/* A step's irradiance over a run of cells, the copy for CPUs with
 * AVX-512 (F, VL, BW, DQ: exactly what ss_lane_cells tests for), which
 * ss_lane_cells picks at run time before the AVX2 copy
 * (insolation_lanes_body.h). The condition is SS_LANES_V3's
 * (insolation_lanes.h), tested before any header so that the pragma covers
 * every inline function the copy takes in; elsewhere this file compiles to
 * nothing. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
/* Eight lanes still (256-bit vectors, GCC's choice under Ice Lake's
 * tuning, which also gathers the tables natively), but with AVX-512's
 * masks and masked gathers for the selects. Measured on 2 cores of an AMD
 * EPYC (2026-12-03; ten January days, interpolated, one thread): the
 * copy's share of the run's samples against the sweep's fell by about a
 * quarter from the AVX2 copy's (medians of 3 perf records), and the run by
 * about 6 % (medians of 9 alternated runs); with 512-bit vectors, by
 * less. */
#pragma GCC target("avx512f", "avx512vl", "avx512bw", "avx512dq", "avx2", "fma", \
                   "tune=icelake-server")
#define SS_LANE_ENTRY ss_lane_cells_v4
#include "insolation_lanes_body.h"
#endif
