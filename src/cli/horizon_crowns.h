/* The crowns' horizon of a site (horizon --point/--points --canopy,
 * doc/pv-horizons.md): per azimuth, the elevation of the highest crown top
 * ahead seen from the observer's eye. */
#ifndef SS_CLI_HORIZON_CROWNS_H
#define SS_CLI_HORIZON_CROWNS_H

#include "skysweep_sites.h"
#include "trees.h"

/* Elevation (degrees) of the crowns ahead of the site toward each of the
 * options' directions (true azimuths), -90 where no crown lies ahead.
 * ground: the DSM the crowns stand on (trees_ground's heights); eye_m:
 * the observer's absolute height (the site's ground + its height). The
 * ray from the site crosses each cell exactly (the cells as flat-topped
 * columns of ground + canopy, each seen at the point where the ray enters
 * it); the site's own cell is left out, as in the raster canopy horizon.
 * max_top_m: the highest crown top of the grid (crowns_max_top), which ends
 * a ray once no crown farther can rise above the best so far. */
void crowns_profile(const ss_grid *ground, const ss_canopy *canopy, const ss_point_site *site,
                    double eye_m, double max_top_m, const ss_sweep_options *opt, double *deg);
/* The highest crown top (ground + canopy height, absolute), -INFINITY
 * where the canopy holds no tree. */
double crowns_max_top(const ss_grid *ground, const ss_canopy *canopy);

#endif
