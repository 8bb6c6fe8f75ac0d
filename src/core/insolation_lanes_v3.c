/* A step's irradiance over a run of cells, the copy for CPUs with AVX2 and
 * FMA (exactly what ss_lane_cells tests for), which ss_lane_cells picks at run time
 * (insolation_lanes_body.h). The condition is SS_LANES_V3's
 * (insolation_lanes.h), tested before any header so that the pragma covers
 * every inline function the copy takes in; elsewhere this file compiles to
 * nothing. */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
/* Tuned for Haswell, whose tuning lets GCC use AVX2's gather loads for the
 * sun's tables (the generic tuning emulates them element by element): an
 * interpolated month on the sample took 1.99 s against 2.08 s here. */
#pragma GCC target("avx2", "fma", "tune=haswell")
#define SS_LANE_ENTRY ss_lane_cells_v3
#include "insolation_lanes_body.h"
#endif
