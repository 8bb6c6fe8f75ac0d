/* A step's irradiance over a run of cells, in SIMD lanes: the copy for any
 * CPU, and the choice of the AVX-512 or AVX2 copy where the CPU has it
 * (insolation_lanes_body.h). */
#define SS_LANE_ENTRY ss_lane_cells_any
#include "insolation_lanes_body.h"

void ss_lane_cells(const ss_lane_step *s, const ss_lane_suns *suns, const float *own_z,
                   const ss_cell_terms *terms, size_t c0, int n, ss_lane_adds *out)
{
#if SS_LANES_V3
    if (ss_lanes_have_v4()) {
        ss_lane_cells_v4(s, suns, own_z, terms, c0, n, out);
        return;
    }
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
        ss_lane_cells_v3(s, suns, own_z, terms, c0, n, out);
        return;
    }
#endif
    ss_lane_cells_any(s, suns, own_z, terms, c0, n, out);
}
