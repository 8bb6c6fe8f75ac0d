/* Per-cell sun positions by rotation on a lattice (see sun_field.h). */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ctx_internal.h"
#include "sun_field.h"

/* Lattice spacing on the ground: sun angles change by ~0.009 deg/km, and
 * linear interpolation over 1 km errs by far less than 0.001 deg even with
 * the sun near the zenith, where its azimuth turns fastest. */
#define SS_SUN_LATTICE_M 1000.0

static double wrap180(double a)
{
    a = fmod(a + 180.0, 360.0);
    return (a < 0 ? a + 360.0 : a) - 180.0;
}

void ss_sun_field_fixed(const ss_dem_frame *frame, int width, int height, double azimuth_deg,
                        double apparent_elevation_deg, ss_sun_field *field)
{
    memset(field, 0, sizeof *field);
    field->width = width;
    field->height = height;
    field->centre.azimuth_deg = azimuth_deg;
    field->centre.apparent_elevation_deg = apparent_elevation_deg;
    field->centre.elevation_deg = apparent_elevation_deg;
    field->centre.zenith_deg = 90.0 - apparent_elevation_deg;
    field->centre_grid_azimuth_deg = azimuth_deg - (frame ? frame->grid_north_deg : 0.0);
}

/* Lattice node positions along one axis: 0, step, 2 step, ..., n - 1;
 * always at least two nodes (both 0 on a one-cell axis). */
static int lattice_nodes(int n, int step, int *nodes)
{
    int k = 0;
    for (int i = 0; i < n - 1; i += step)
        nodes[k++] = i;
    if (k == 0)
        nodes[k++] = 0;
    nodes[k++] = n - 1;
    return k;
}

/* Position of x between nodes a and b, 0..1 (0 when they coincide). */
static double between(int x, int a, int b)
{
    return b > a ? (double)(x - a) / (b - a) : 0.0;
}

ss_status ss_sun_field_compute(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                               double unix_s, const ss_spa_params *params, int per_cell,
                               ss_sun_field *field)
{
    memset(field, 0, sizeof *field);
    const ss_grid *g = &dem->grid;
    field->width = g->width;
    field->height = g->height;
    if (!frame->georeferenced)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "the DEM has no CRS, so the sun's position for a time is unknown: give "
                       "the sun as --sun-azimuth and --sun-elevation");
    ss_spa_params p = *params;
    p.elevation_m = g->z_origin_m;
    ss_status st = ss_spa(ctx, unix_s, frame->centre_lat_deg, frame->centre_lon_deg, &p,
                          &field->centre);
    if (st != SS_OK)
        return st;
    field->centre_grid_azimuth_deg = field->centre.azimuth_deg - frame->grid_north_deg;
    if (!per_cell)
        return SS_OK;

    int step_c = (int)fmax(1.0, floor(SS_SUN_LATTICE_M / g->cell_x_m));
    int step_r = (int)fmax(1.0, floor(SS_SUN_LATTICE_M / g->cell_y_m));
    int *cols = malloc(sizeof(int) * (g->width / step_c + 3));
    int *rows = malloc(sizeof(int) * (g->height / step_r + 3));
    int nc = cols ? lattice_nodes(g->width, step_c, cols) : 0;
    int nr = rows ? lattice_nodes(g->height, step_r, rows) : 0;
    double *node_az = malloc(sizeof(double) * (size_t)nc * nr);
    double *node_e0 = malloc(sizeof(double) * (size_t)nc * nr);
    size_t n = (size_t)g->width * g->height;
    field->grid_azimuth_deg = malloc(sizeof(float) * n);
    field->elevation_deg = malloc(sizeof(float) * n);
    field->apparent_elevation_deg = malloc(sizeof(float) * n);
    if (!cols || !rows || !node_az || !node_e0 || !field->grid_azimuth_deg ||
        !field->elevation_deg || !field->apparent_elevation_deg)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for per-cell sun positions");
    /* Exact positions at the lattice nodes: the centre's geocentric sun
     * direction seen from each node, parallax included. */
    for (int j = 0; j < nr && st == SS_OK; ++j)
        for (int i = 0; i < nc && st == SS_OK; ++i) {
            double lon, lat, north, az, e0;
            size_t cell = (size_t)rows[j] * g->width + cols[i];
            double h = isfinite(g->z[cell]) ? g->z[cell] + g->z_origin_m : g->z_origin_m;
            st = ss_geo_lonlat(frame->geo, cols[i], rows[j], &lon, &lat);
            if (st == SS_OK)
                st = ss_geo_grid_north(frame->geo, cols[i], rows[j], &north);
            if (st == SS_OK)
                st = ss_geo_sun_local(frame->geo, lat, lon, h, field->centre.sun_ecef,
                                      field->centre.earth_sun_distance_au, &az, &e0);
            if (st != SS_OK)
                break;
            /* Unwrapped around the centre's, so interpolation never crosses 0/360. */
            double grid_az = field->centre_grid_azimuth_deg +
                             wrap180(az - north - field->centre_grid_azimuth_deg);
            node_az[(size_t)j * nc + i] = grid_az;
            node_e0[(size_t)j * nc + i] = e0;
            double d_e = e0 - field->centre.elevation_deg;
            double d_a = wrap180(grid_az - field->centre_grid_azimuth_deg) *
                         cos(e0 * M_PI / 180.0);
            double spread = sqrt(d_e * d_e + d_a * d_a);
            field->spread_deg = spread > field->spread_deg ? spread : field->spread_deg;
        }
    /* Bilinear between nodes; refraction per cell, since it bends sharply
     * near the horizon. */
    for (int j = 0; j + 1 < nr && st == SS_OK; ++j)
        for (int r = rows[j]; r <= rows[j + 1]; ++r) {
            double ty = between(r, rows[j], rows[j + 1]);
            for (int i = 0; i + 1 < nc; ++i)
                for (int c = cols[i]; c <= cols[i + 1]; ++c) {
                    double tx = between(c, cols[i], cols[i + 1]);
                    size_t a = (size_t)j * nc + i, b = a + 1, d = a + nc, e = d + 1;
                    double az = (1 - ty) * ((1 - tx) * node_az[a] + tx * node_az[b]) +
                                ty * ((1 - tx) * node_az[d] + tx * node_az[e]);
                    double e0 = (1 - ty) * ((1 - tx) * node_e0[a] + tx * node_e0[b]) +
                                ty * ((1 - tx) * node_e0[d] + tx * node_e0[e]);
                    size_t cell = (size_t)r * g->width + c;
                    field->grid_azimuth_deg[cell] = (float)az;
                    field->elevation_deg[cell] = (float)e0;
                    field->apparent_elevation_deg[cell] =
                        (float)(e0 + ss_spa_refraction_deg(e0, p.pressure_hpa, p.temperature_c,
                                                           p.atmos_refract_deg));
                }
        }
    free(cols);
    free(rows);
    free(node_az);
    free(node_e0);
    if (st != SS_OK)
        ss_sun_field_free(field);
    return st;
}

void ss_sun_field_free(ss_sun_field *field)
{
    free(field->grid_azimuth_deg);
    free(field->elevation_deg);
    free(field->apparent_elevation_deg);
    field->grid_azimuth_deg = field->elevation_deg = field->apparent_elevation_deg = NULL;
}
