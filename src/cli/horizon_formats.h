/* Horizon files for PV software (doc/pv-horizons.md, Formats): one site's
 * profile written in the layout and azimuth convention of the tool that
 * reads it. skysweep's profile has azimuths clockwise from true north at
 * equal steps from 0; each writer turns them into its tool's convention. */
#ifndef SS_CLI_HORIZON_FORMATS_H
#define SS_CLI_HORIZON_FORMATS_H

#include <stdio.h>

#include "skysweep_sites.h"

/* What a file may say about its site and where its horizon came from. */
typedef struct {
    const char *id;
    double lon_deg, lat_deg;
    const char *sources; /* "dem.tif" or "near dsm.tif, far terrain dtm.tif (...)" */
} horizon_file_site;

typedef struct {
    const char *name;      /* --format NAME */
    const char *extension; /* of the per-site files of --points (with the dot) */
    /* Writes one site's n-direction profile; write errors show in ferror(f). */
    void (*write)(FILE *f, const horizon_file_site *site, const ss_point_horizon_result *p, int n);
} horizon_file_format;

/* The per-site file format named name (pvgis, pvsyst, pvsol, helioscope,
 * sam); NULL for csv, json or an unknown name. */
const horizon_file_format *horizon_file_format_named(const char *name);

/* Writes one site's file at path under a temporary name, renamed when
 * complete (horizon_points.c); nothing is left after a failure, whose
 * message is in ctx (SS_ERR_OUTPUT, SS_ERR_CANCELLED). */
ss_status horizon_file_write(ss_ctx *ctx, const horizon_file_format *format, const char *path,
                             const horizon_file_site *site, const ss_point_horizon_result *p,
                             int n);

#endif
