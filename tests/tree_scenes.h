/* Scenes with trees shared by the tests of the crowns' sweeps
 * (test_vegetation, test_vegetation_sky, test_insolation_crowns), and the
 * brute-force paths of rays through them. */
#ifndef SS_TREE_SCENES_H
#define SS_TREE_SCENES_H

#include "dem_io.h"
#include "skysweep.h"

/* A crown's bottom above the ground, by the canopy's trunk rule. */
double tree_trunk_at(const ss_canopy *cn, size_t i);

/* Random round crowns of 2..6 m radius, 4..20 m tall, anywhere on the
 * grid: canopy heights above the ground, 0 elsewhere. */
void tree_plant(const ss_grid *g, float *height, unsigned seed, int n_trees);

/* The Gothenburg 1 m DSM and its canopy heights (CDSM, nodata and
 * negatives taken as 0) from ../shared/data: 1 when read, 0 when the files
 * are not there (the caller skips), -1 when they cannot be read (tap_ok
 * has failed with the reason). Free with ss_dem_free and free. */
int tree_gothenburg(ss_dem *dsm, float **height);

/* Flat ground at height 0 with one cylindrical crown, `top` metres tall,
 * over the cells whose centres lie within R cells of (cx, cy) (in cells
 * from the grid's north-west corner); canopy heights 0 elsewhere. */
void tree_cylinder(ss_grid *g, float *height, double cx, double cy, double R, double top);

/* Flat ground at height 0 with a hedge one cell thick, `top` metres tall,
 * along the whole column `col`; canopy heights 0 elsewhere. */
void tree_hedge(ss_grid *g, float *height, int col, double top);

/* The path (m) of the ray from each cell toward the sun (grid azimuth az,
 * elevation el) inside crowns, by brute force on the engine's digital
 * lines: every cell against every crown cell ahead of it on its line, the
 * ray's level strictly inside the crown's interval (trunk to top), each
 * crossing the ray's run through one cell of the line (the major axis's
 * cell over the cosine of the azimuth from it) over cos(el). Cells
 * without a height get 0. */
void tree_brute_paths(const ss_grid *g, const ss_canopy *cn, double az, double el, double *path);

#endif
