/* The far horizon of --far (horizon_far.h). */
#include "config.h"

#include <stdlib.h>
#include <string.h>

#include "horizon_far.h"

struct horizon_far {
    ss_ctx *ctx;
    ss_dem dem;
    ss_dem_frame frame;
    int have_frame;
    ss_site_frame *sf;
    ss_point_grid *pg;
    ss_point_site *sites;
    double *ground_m;
    int n_sites, directions;
    ss_point_horizon_result *profile; /* one site's far profile */
    double *col, *row, *lon, *lat;    /* its casting points */
};

ss_status horizon_far_open(ss_ctx *ctx, const char *path, int directions, horizon_far **out)
{
    horizon_far *far = calloc(1, sizeof *far);
    *out = far;
    if (!far)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for the far DEM");
    far->ctx = ctx;
    far->directions = directions;
    const char *paths[] = {path};
    ss_status st = ss_dem_read(ctx, paths, 1, NULL, &far->dem);
    if (st == SS_OK && (st = ss_dem_frame_open(ctx, &far->dem, &far->frame)) != SS_OK)
        ss_dem_free(&far->dem);
    far->have_frame = st == SS_OK;
    if (st == SS_OK)
        st = ss_site_frame_open(ctx, &far->dem, NULL, &far->sf);
    if (st == SS_OK)
        st = ss_point_grid_new(ctx, &far->dem.grid, &far->pg);
    if (st == SS_OK) {
        far->profile = malloc(sizeof *far->profile * (size_t)directions);
        far->col = malloc(sizeof(double) * (size_t)directions * 4);
        if (!far->profile || !far->col)
            st = ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for far profiles");
        else {
            far->row = far->col + directions;
            far->lon = far->row + directions;
            far->lat = far->lon + directions;
        }
    }
    return st;
}

ss_status horizon_far_place(horizon_far *far, const site_rec *sites, int n, int true_north)
{
    far->sites = malloc(sizeof *far->sites * (size_t)n);
    far->ground_m = malloc(sizeof *far->ground_m * (size_t)n);
    if (!far->sites || !far->ground_m)
        return ss_ctx_error(far->ctx, SS_ERR_MEMORY, "out of memory for %d sites", n);
    far->n_sites = n;
    for (int i = 0; i < n; ++i) {
        ss_point_site *p = &far->sites[i];
        p->grid_north_deg = 0.0;
        ss_status st =
            ss_site_locate(far->sf, sites[i].lon_deg, sites[i].lat_deg, &p->col, &p->row);
        if (st == SS_OK)
            st = ss_point_ground_height(far->ctx, far->pg, p->col, p->row, &far->ground_m[i]);
        if (st == SS_OK && true_north)
            st = ss_geo_grid_north(far->frame.geo, p->col, p->row, &p->grid_north_deg);
        if (st != SS_OK)
            return ss_ctx_error(far->ctx, st, "id '%s' on the far DEM %s: %s", sites[i].id,
                                far->dem.description, ss_ctx_message(far->ctx));
        /* An eye below the far terrain (a coarse DTM a little above the
         * DSM's ground) looks from that terrain. */
        double eye = sites[i].ground_m + sites[i].height_m - far->ground_m[i];
        p->observer_height_m = eye > 0.0 ? eye : 0.0;
    }
    return SS_OK;
}

ss_status horizon_far_merge(horizon_far *far, int index, const ss_sweep_options *opt,
                            ss_point_horizon_result *profile, double *cast_lon, double *cast_lat,
                            int *far_wins)
{
    int n = far->directions;
    ss_status st = ss_point_horizon(far->ctx, far->pg, opt, &far->sites[index], far->profile);
    for (int i = 0; i < n && st == SS_OK; ++i) {
        far->col[i] = far->profile[i].cast_col;
        far->row[i] = far->profile[i].cast_row;
    }
    if (st == SS_OK)
        st = ss_site_lonlat(far->sf, n, far->col, far->row, far->lon, far->lat);
    *far_wins = 0;
    for (int i = 0; i < n && st == SS_OK; ++i)
        if (far->profile[i].elevation_deg > profile[i].elevation_deg) {
            profile[i] = far->profile[i];
            cast_lon[i] = far->lon[i];
            cast_lat[i] = far->lat[i];
            ++*far_wins;
        }
    return st;
}

const char *horizon_far_name(const horizon_far *far)
{
    return far->dem.description;
}

void horizon_far_site(const horizon_far *far, int index, double *ground_m, double *eye_m)
{
    *ground_m = far->ground_m[index];
    *eye_m = far->sites[index].observer_height_m;
}

void horizon_far_close(horizon_far *far)
{
    if (!far)
        return;
    ss_point_grid_free(far->pg);
    ss_site_frame_close(far->sf);
    if (far->have_frame) {
        ss_dem_frame_close(&far->frame);
        ss_dem_free(&far->dem);
    }
    free(far->sites);
    free(far->ground_m);
    free(far->profile);
    free(far->col);
    free(far);
}
