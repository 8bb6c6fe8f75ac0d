/* City DSMs as flat-topped columns (the box model of UMEP and SOLWEIG):
 * an independent ray march from a cell's top centre through every column
 * the sun's ray crosses (an exact cell traversal, Amanatides & Woo 1987),
 * sharing no code with kernels/ or src/core, and the share of cells on
 * which skysweep's cast shadows agree with it. Used by tests/test_box_model
 * and doc/box_lines_driver. */
#ifndef SS_BOX_MARCH_H
#define SS_BOX_MARCH_H

#include "skysweep.h"

/* 1 where the box-model ray from cell (r, c) toward the sun (azimuth az
 * clockwise from the grid's north, elevation el, degrees) passes above
 * every column it crosses, else 0; z_max: the grid's highest height. */
int box_march_lit(const ss_grid *g, int r, int c, double az, double el, double z_max);
/* The same with the earth's curvature: a column's top lowered by curv_k
 * t^2 at distance t (curv_k = 1 / (2 R_eff)). */
int box_march_lit_curved(const ss_grid *g, int r, int c, double az, double el, double z_max,
                         double curv_k);

/* 1 where the box-model ray from cell (r, c)'s centre toward the sun
 * (0 < el < 90) passes strictly inside the crown of a square it crosses,
 * its own not counted: cell j's crown is the open interval of heights
 * (z_j + bottom_m[j], z_j + top_m[j]) over its square, none where top_m[j]
 * <= bottom_m[j]. z_max: the highest crown top. */
int box_march_crossed(const ss_grid *g, const float *top_m, const float *bottom_m, int r, int c,
                      double az, double el, double z_max);

/* Sun azimuths (degrees) that try each cell's own ray: the axes and the
 * diagonals, a hundredth of a degree either side of them, and others
 * between (tests/test_box_shadow.c, tests/test_box_crowns.c). */
#define BOX_MARCH_AZIMUTHS 40
extern const double box_march_azimuths[BOX_MARCH_AZIMUTHS];

/* The box-model horizon (degrees) from cell (r, c) toward azimuth az: the
 * largest elevation of the column tops its ray crosses, the cell's own top
 * (0 deg) included. */
double box_march_horizon_deg(const ss_grid *g, int r, int c, double az);
/* The same with the earth's curvature: a column's top lowered by curv_k
 * t^2 at the distance t it shows at. */
double box_march_horizon_curved_deg(const ss_grid *g, int r, int c, double az, double curv_k);

/* A point a box-model ray shows a column top at: the cell's own edge
 * (0 deg), or the near edge of a column above the eye. */
typedef struct {
    double dist_m, height_m, elevation_deg;
} box_march_point;

/* The point of the ray from cell (r, c) toward azimuth az (curved as
 * box_march_horizon_curved_deg) nearest to dist_m from the cell's centre,
 * of two a float cannot tell apart (at a corner) the one nearer height_m, into *p
 * (looking no farther than twice dist_m and two cells). */
void box_march_point_near(const ss_grid *g, int r, int c, double az, double curv_k,
                          double dist_m, double height_m, box_march_point *p);

/* Box lines, each cell's own ray by default, in `directions` directions
 * from offset_deg, on a grid whose north is grid_north_deg from true
 * north, its heights lowered by curv_k t^2 (k = 0; curv_k 0: flat). */
ss_sweep_options box_march_options(int directions, double offset_deg, double grid_north_deg,
                                   double curv_k);

/* The grid's highest finite height. */
double box_march_top(const ss_grid *g);

/* A synthetic city of n x n 1 m cells: flat ground at 0 with boxes of
 * 6..40 m sides and 4..45 m heights. */
ss_grid box_march_city(int n);
/* Holes of nodata in every 37th cell of g, which neither cast nor
 * receive, and its cells half as long again north-south (1.5 m). */
void box_march_holes(ss_grid *g);
/* A strip of width x height 1 m cells (one row or one column, or a few
 * rows), heights 0..22 m in no order. */
ss_grid box_march_strip(int width, int height);
/* One 80 m tower on a plain of 90 x 70 cells of 2 m. */
ss_grid box_march_tower(void);
/* Rolling hills on a slope, 120 x 100 cells of 2 m, with a ridge: low
 * horizons, so the rays pass over the blocks that cannot rise above them,
 * and walk on far up the slope. */
ss_grid box_march_hills(void);

/* The share of valid cells where ss_cast_shadow with opt on the C twin
 * equals the march, for a sun at (az, el); NAN after a failure, whose
 * message goes to err (300 bytes). */
double box_march_agreement(const ss_grid *g, const ss_sweep_options *opt, double az, double el,
                           char *err);

/* The mean over valid cells of |geometric SVF - the box model's|, the
 * latter from box_march_horizon_deg over opt's directions (the C twin),
 * and in *p95 (may be NULL) its 95th percentile over the cells (nearest
 * rank); NAN after a failure, whose message goes to err (300 bytes). */
double box_march_svf_error(const ss_grid *g, const ss_sweep_options *opt, double *p95, char *err);

#endif
