/* Helpers for the test programs: grids, deterministic random terrain, and
 * an independent brute-force horizon to check the sweep against. */
#ifndef SS_TESTLIB_H
#define SS_TESTLIB_H

#include "skysweep.h"
#include "ss_lines.h"

/* Allocates a grid or exits the test with an error. */
ss_grid test_grid(int width, int height, double cell_x_m, double cell_y_m);

typedef enum {
    TERRAIN_NOISE,    /* independent random heights */
    TERRAIN_SMOOTH,   /* sum of random sines: hills and valleys */
    TERRAIN_PLATEAUS, /* heights quantised to a few levels: many exact ties */
    TERRAIN_SPIKES    /* flat with a few tall single-cell spikes */
} terrain_kind;

void test_fill(ss_grid *g, terrain_kind kind, unsigned seed, double relief_m);
/* A plane of slope S degrees falling toward aspect A (0 0: flat ground at
 * height 0), level with 0 at the grid's centre cell. */
void test_plane(ss_grid *g, double slope_deg, double aspect_deg);
/* Sets random rectangular holes of nodata. */
void test_holes(ss_grid *g, unsigned seed, int n_holes, int max_size);

/* Brute force of a line model (SS_LINE_MODEL_INTERPOLATED or _DIGITAL): every
 * sample scans every sample ahead of it on its line, in double precision,
 * and its angle goes to its cells with the model's weights. Per cell:
 * angle_deg = the weighted mean of the horizons of its samples that have
 * terrain ahead, weights renormalised, -90 where none has (NAN at nodata);
 * near_angle_rad = the horizon of the sample that names the cell's
 * distance: the nearest to the cell among those with terrain ahead, else
 * the nearest (-pi/2 then); if claimed_dist is given, claimed_angle_rad =
 * the angle from that sample to the sample at the claimed distance (NAN if
 * none is there), to check that a reported casting sample really casts the
 * horizon. curv_k = 1/(2 R_eff) or 0. */
void test_brute_horizon(const ss_grid *g, double azimuth_deg, double curv_k, int model,
                        const float *claimed_dist, double *angle_deg, double *near_angle_rad,
                        double *claimed_angle_rad);

/* Per cell, the height (relative to the grid's stored zero) of the sample
 * at the claimed distance ahead of the cell's distance-naming sample (as
 * for claimed_angle_rad), NAN where no sample lies there: what the
 * horizon-casting point's height must be. */
void test_brute_caster_height(const ss_grid *g, double azimuth_deg, double curv_k, int model,
                              const float *claimed_dist, double *claimed_height_m);

/* The same without curvature, with none_deg (instead of -90) where nothing
 * lies ahead, as shadows take it. */
void test_brute_horizon_none(const ss_grid *g, double azimuth_deg, int model, double none_deg,
                             double *angle_deg, double *near_angle_rad, double *claimed_angle_rad);

/* Every sample's angle, none_deg where nothing lies ahead (within radius_m
 * if > 0; curv_k as for test_brute_horizon), weighted into its cells as a
 * term: the per-direction elevation term of openness, whose mean over
 * samples counts open sky as none_deg. */
void test_brute_horizon_terms(const ss_grid *g, double azimuth_deg, double curv_k,
                              double radius_m, int model, double none_deg, double *angle_deg);

/* The library's horizon for one azimuth, on the device given ("reference"
 * or NULL for the default OpenCL device). Returns the status. */
ss_status test_lib_horizon(const char *device, const ss_grid *g, double azimuth_deg,
                           double earth_radius_m, double refraction_k, int model,
                           float *angle_deg, float *dist_m, char *err, size_t err_size);
/* The same with the casting points' heights too (z_origin_m included,
 * SS_NODATA where none), if cast_height_m is given. */
ss_status test_lib_caster(const char *device, const ss_grid *g, double azimuth_deg,
                          double earth_radius_m, double refraction_k, int model, float *angle_deg,
                          float *dist_m, float *cast_height_m, char *err, size_t err_size);

/* A source for the row-wise calls that reads g's rows through read (user:
 * what read gets), in bands of band_rows (0: one band). */
ss_source test_source(const ss_grid *g, ss_rows_read read, void *user, int band_rows,
                      ss_band_stats *stats);

/* Whether a PoCL device is listed (the tests that need PoCL itself). */
int test_have_pocl(void);

/* Path of a file in ../shared/data, or NULL if that folder is absent. */
const char *test_shared_data(const char *name);

#endif
