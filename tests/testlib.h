/* Helpers for the test programs: grids, deterministic random terrain, and
 * an independent brute-force horizon to check the sweep against. */
#ifndef SS_TESTLIB_H
#define SS_TESTLIB_H

#include "skysweep.h"

/* Allocates a grid or exits the test with an error. */
ss_grid test_grid(int width, int height, double cell_x_m, double cell_y_m);

typedef enum {
    TERRAIN_NOISE,    /* independent random heights */
    TERRAIN_SMOOTH,   /* sum of random sines: hills and valleys */
    TERRAIN_PLATEAUS, /* heights quantised to a few levels: many exact ties */
    TERRAIN_SPIKES    /* flat with a few tall single-cell spikes */
} terrain_kind;

void test_fill(ss_grid *g, terrain_kind kind, unsigned seed, double relief_m);
/* Sets random rectangular holes of nodata. */
void test_holes(ss_grid *g, unsigned seed, int n_holes, int max_size);

/* Brute force of the digital-line model: every cell scans every cell ahead
 * of it on its line, in double precision. angle_rad is -pi/2 where nothing
 * lies ahead, NAN at nodata; dist_m is the distance to the highest cell
 * (the farthest of exact ties). curv_k = 1/(2 R_eff) or 0. If claimed_dist
 * is given, claimed_angle_rad receives the angle to the cell at that
 * distance on the line (NAN if no cell is there), to check that a reported
 * casting cell really casts the horizon. */
void test_brute_horizon(const ss_grid *g, double azimuth_deg, double curv_k,
                        const float *claimed_dist, double *angle_rad, double *dist_m,
                        double *claimed_angle_rad);

/* The library's horizon for one azimuth, on the device given ("reference"
 * or NULL for the default OpenCL device). Returns the status. */
ss_status test_lib_horizon(const char *device, const ss_grid *g, double azimuth_deg,
                           double earth_radius_m, double refraction_k, float *angle_deg,
                           float *dist_m, char *err, size_t err_size);

/* Path of a file in ../shared/data, or NULL if that folder is absent. */
const char *test_shared_data(const char *name);

#endif
