/* Scenes with trees shared by the tests of the crowns' sweeps
 * (test_vegetation, test_vegetation_sky). */
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

#endif
