/* skysweep horizon --far DEM: the far (terrain) horizon of each site,
 * computed on a second DEM in any CRS and grid, merged with the near
 * (DSM) horizon by the larger elevation per azimuth (doc/pv-horizons.md,
 * Near and far). */
#ifndef SS_CLI_HORIZON_FAR_H
#define SS_CLI_HORIZON_FAR_H

#include "horizon_points.h"

typedef struct horizon_far horizon_far;

/* Reads the far DEM (one without a CRS is refused as it is read) for profiles of `directions`
 * azimuths; failures leave their message in ctx. */
ss_status horizon_far_open(ss_ctx *ctx, const char *path, int directions, horizon_far **out);

/* Places every site (already placed on the near DEM: lon_deg, lat_deg,
 * ground_m) on the far DEM, its eye at the same absolute height, ground_m +
 * height_m: the two DEMs share a vertical datum. A site outside the far DEM
 * or on its nodata is SS_ERR_ARGUMENT. */
ss_status horizon_far_place(horizon_far *far, const site_rec *sites, int n, int true_north);

/* Site index's far profile merged into its near profile: where the far
 * terrain stands higher, its elevation, distance, casting height and
 * casting point (cast_lon, cast_lat, WGS84) replace the near ones.
 * *far_wins counts those azimuths. */
ss_status horizon_far_merge(horizon_far *far, int index, const ss_sweep_options *opt,
                            ss_point_horizon_result *profile, double *cast_lon, double *cast_lat,
                            int *far_wins);

const char *horizon_far_name(const horizon_far *far);
/* The far DEM's ground height and the eye above it at site index. */
void horizon_far_site(const horizon_far *far, int index, double *ground_m, double *eye_m);
void horizon_far_close(horizon_far *far);

#endif
