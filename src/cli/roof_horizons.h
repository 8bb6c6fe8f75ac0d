/* skysweep roofs --horizon-files DIR: a horizon file for PV software
 * (horizon_formats.h) per roof plane, seen from the plane's centre
 * (doc/pv-horizons.md, Roof planes). */
#ifndef SS_CLI_ROOF_HORIZONS_H
#define SS_CLI_ROOF_HORIZONS_H

#include <stddef.h>

#include "run.h"

#define ROOF_HORIZON_FORMATS "pvgis|pvsyst|pvsol|helioscope|sam"

typedef struct {
    const char *building_id;
    int plane;       /* 1.. within the building */
    double col, row; /* its centre, cell-centre coordinates of the DSM */
} roof_horizon_site;

/* The cell of plane p (labels as roof_planes_find gives them for cells,
 * row * width + col) nearest the mean of the plane's cells: a cell of the
 * plane even where the plane bends round (an L). */
void roof_plane_centre(const int *cells, const int *label, size_t n_cells, int width, int p,
                       double *col, double *row);

/* 0, or the usage error's exit code when folder is not an existing folder. */
int roof_horizon_check(const char *folder);

/* Writes folder/BUILDING_PLANE.ext for each site in format (an index into
 * ROOF_HORIZON_FORMATS): the DSM's horizon at 1 degree steps from true
 * north, the eye on the roof at the centre cell. Building ids are made file
 * names (characters other than letters, digits, '-', '_' and '.' become
 * '_'); two sites that would share a name are refused. */
ss_status roof_horizon_files(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                             const char *folder, int format, const roof_horizon_site *sites,
                             size_t n);

#endif
