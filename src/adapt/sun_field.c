/* Per-cell sun positions by rotation on a lattice (see sun_field.h). */
#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "skysweep.h"
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

ss_status ss_sun_nodes_make(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                            ss_rows_read read, void *user, ss_sun_nodes *nodes)
{
    memset(nodes, 0, sizeof *nodes);
    const ss_grid *g = &dem->grid;
    if (!frame->georeferenced)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "the DEM has no CRS, so the sun's position for a time is unknown: give "
                       "the sun as --sun-azimuth and --sun-elevation");
    int step_c = (int)fmax(1.0, floor(SS_SUN_LATTICE_M / g->cell_x_m));
    int step_r = (int)fmax(1.0, floor(SS_SUN_LATTICE_M / g->cell_y_m));
    int *cols = nodes->cols = malloc(sizeof(int) * (g->width / step_c + 3));
    int *rows = nodes->rows = malloc(sizeof(int) * (g->height / step_r + 3));
    int nc = nodes->n_cols = cols ? lattice_nodes(g->width, step_c, cols) : 0;
    int nr = nodes->n_rows = rows ? lattice_nodes(g->height, step_r, rows) : 0;
    size_t n = (size_t)nc * nr;
    nodes->lon_deg = malloc(sizeof(double) * n);
    nodes->lat_deg = malloc(sizeof(double) * n);
    nodes->north_deg = malloc(sizeof(double) * n);
    nodes->height_m = malloc(sizeof(double) * n);
    float *row_z = read ? malloc(sizeof(float) * (size_t)g->width) : NULL;
    ss_status st = SS_OK;
    if (!cols || !rows || !nodes->lon_deg || !nodes->lat_deg || !nodes->north_deg ||
        !nodes->height_m || (read && !row_z))
        st = ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for per-cell sun positions");
    for (int j = 0; j < nr && st == SS_OK; ++j) {
        if (read && (st = read(user, rows[j], 1, row_z)) != SS_OK)
            break;
        const float *z = read ? row_z : g->z + (size_t)rows[j] * g->width;
        for (int i = 0; i < nc && st == SS_OK; ++i) {
            size_t k = (size_t)j * nc + i;
            nodes->height_m[k] = isfinite(z[cols[i]]) ? z[cols[i]] + g->z_origin_m : g->z_origin_m;
            st = ss_geo_lonlat(frame->geo, cols[i], rows[j], &nodes->lon_deg[k], &nodes->lat_deg[k]);
            if (st == SS_OK)
                st = ss_geo_grid_north(frame->geo, cols[i], rows[j], &nodes->north_deg[k]);
        }
    }
    free(row_z);
    if (st != SS_OK)
        ss_sun_nodes_free(nodes);
    return st;
}

void ss_sun_nodes_free(ss_sun_nodes *nodes)
{
    free(nodes->cols);
    free(nodes->rows);
    free(nodes->lon_deg);
    free(nodes->lat_deg);
    free(nodes->north_deg);
    free(nodes->height_m);
    memset(nodes, 0, sizeof *nodes);
}

ss_status ss_sun_field_lattice(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                               double unix_s, const ss_spa_params *params, int per_cell,
                               int row_lo, int row_hi, const ss_sun_nodes *nodes,
                               ss_sun_field *field)
{
    memset(field, 0, sizeof *field);
    const ss_grid *g = &dem->grid;
    field->width = g->width;
    field->height = g->height;
    if (!frame->georeferenced)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "the DEM has no CRS, so the sun's position for a time is unknown: give "
                       "the sun as --sun-azimuth and --sun-elevation");
    ss_spa_params p = *params;
    p.elevation_m = g->z_origin_m;
    field->params = p;
    ss_status st = ss_spa(ctx, unix_s, frame->centre_lat_deg, frame->centre_lon_deg, &p,
                          &field->centre);
    if (st != SS_OK)
        return st;
    field->centre_grid_azimuth_deg = field->centre.azimuth_deg - frame->grid_north_deg;
    if (!per_cell)
        return SS_OK;

    /* The lattice rows that rows [row_lo, row_hi) lie between. */
    int nc = nodes->n_cols, nr = nodes->n_rows;
    int j_lo = 0, j_hi = nr - 1;
    while (j_lo + 1 < nr && nodes->rows[j_lo + 1] <= row_lo)
        ++j_lo;
    while (j_hi - 1 >= 0 && nodes->rows[j_hi - 1] >= row_hi - 1)
        --j_hi;
    if (j_hi < j_lo) { /* a one-row DEM, whose two nodes both lie on row 0 */
        j_lo = 0;
        j_hi = nr - 1;
    }
    if (j_hi == j_lo && nr > 1)
        j_hi < nr - 1 ? ++j_hi : --j_lo;
    int n_rows = j_hi - j_lo + 1;
    int *cols = field->lattice_cols = malloc(sizeof(int) * (size_t)nc);
    int *rows = field->lattice_rows = malloc(sizeof(int) * (size_t)n_rows);
    field->n_lattice_cols = nc;
    field->n_lattice_rows = n_rows;
    double *node_az = field->node_azimuth_deg = malloc(sizeof(double) * (size_t)nc * n_rows);
    double *node_e0 = field->node_elevation_deg = malloc(sizeof(double) * (size_t)nc * n_rows);
    double *node_refr = field->node_refraction_deg = malloc(sizeof(double) * (size_t)nc * n_rows);
    if (!cols || !rows || !node_az || !node_e0 || !node_refr) {
        ss_sun_field_free(field);
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for per-cell sun positions");
    }
    memcpy(cols, nodes->cols, sizeof(int) * (size_t)nc);
    memcpy(rows, nodes->rows + j_lo, sizeof(int) * (size_t)n_rows);
    /* Exact positions at the lattice nodes: the centre's geocentric sun
     * direction seen from each node, parallax included. */
    for (int j = 0; j < n_rows && st == SS_OK; ++j) {
        for (int i = 0; i < nc && st == SS_OK; ++i) {
            size_t at = (size_t)(j_lo + j) * nc + i, k = (size_t)j * nc + i;
            double az, e0;
            st = ss_geo_sun_local(frame->geo, nodes->lat_deg[at], nodes->lon_deg[at],
                                  nodes->height_m[at], field->centre.sun_ecef,
                                  field->centre.earth_sun_distance_au, &az, &e0);
            if (st != SS_OK)
                break;
            /* Unwrapped around the centre's, so interpolation never crosses 0/360. */
            double grid_az = field->centre_grid_azimuth_deg +
                             wrap180(az - nodes->north_deg[at] - field->centre_grid_azimuth_deg);
            node_az[k] = grid_az;
            node_e0[k] = e0;
            node_refr[k] =
                ss_spa_refraction_deg(e0, p.pressure_hpa, p.temperature_c, p.atmos_refract_deg);
            double d_e = e0 - field->centre.elevation_deg;
            double d_a = wrap180(grid_az - field->centre_grid_azimuth_deg) *
                         cos(e0 * M_PI / 180.0);
            double spread = sqrt(d_e * d_e + d_a * d_a);
            field->spread_deg = spread > field->spread_deg ? spread : field->spread_deg;
        }
    }
    if (st != SS_OK)
        ss_sun_field_free(field);
    return st;
}

void ss_sun_field_lattice_of(const ss_sun_field *field, ss_sun_lattice *lattice)
{
    *lattice = (ss_sun_lattice){.n_cols = field->n_lattice_cols,
                                .n_rows = field->n_lattice_rows,
                                .cols = field->lattice_cols,
                                .rows = field->lattice_rows,
                                .grid_azimuth_deg = field->node_azimuth_deg,
                                .elevation_deg = field->node_elevation_deg,
                                .refraction_deg = field->node_refraction_deg,
                                .pressure_hpa = field->params.pressure_hpa,
                                .temperature_c = field->params.temperature_c,
                                .atmos_refract_deg = field->params.atmos_refract_deg};
}

ss_status ss_sun_field_rows(ss_ctx *ctx, ss_sun_field *field, int row0, int n_rows)
{
    if (!field->node_azimuth_deg)
        return SS_OK;
    const int *lattice_rows = field->lattice_rows;
    int last = field->n_lattice_rows - 1;
    if (row0 < 0 || n_rows < 1 || row0 + n_rows > field->height || row0 < lattice_rows[0] ||
        row0 + n_rows - 1 > lattice_rows[last])
        return ss_ctx_error(ctx, SS_ERR_INTERNAL,
                       "sun positions asked for rows %d..%d, outside the lattice's %d..%d", row0,
                       row0 + n_rows - 1, lattice_rows[0], lattice_rows[last]);
    size_t n = (size_t)field->width * (size_t)n_rows;
    if (n_rows > field->rows || !field->grid_azimuth_deg) {
        free(field->grid_azimuth_deg);
        free(field->elevation_deg);
        free(field->apparent_elevation_deg);
        field->grid_azimuth_deg = malloc(sizeof(float) * n);
        field->elevation_deg = malloc(sizeof(float) * n);
        field->apparent_elevation_deg = malloc(sizeof(float) * n);
        if (!field->grid_azimuth_deg || !field->elevation_deg ||
            !field->apparent_elevation_deg) {
            ss_sun_field_free(field);
            return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for per-cell sun positions");
        }
    }
    field->row0 = row0;
    field->rows = n_rows;
    ss_sun_lattice lattice;
    ss_sun_field_lattice_of(field, &lattice);
    double *tx = malloc(sizeof(double) * ss_sun_lattice_tx_count(&lattice));
    if (!tx) {
        ss_sun_field_free(field); /* as above: no rows half made */
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory for per-cell sun positions");
    }
    ss_sun_lattice_tx(&lattice, tx);
    /* Rows are independent: the cores share them. */
#pragma omp parallel for schedule(static)
    for (int r = row0; r < row0 + n_rows; ++r) {
        size_t at = (size_t)(r - row0) * field->width;
        ss_sun_lattice_cells(&lattice, tx, r, 0, field->width, field->grid_azimuth_deg + at,
                             field->elevation_deg + at, field->apparent_elevation_deg + at);
    }
    free(tx);
    return SS_OK;
}

ss_status ss_sun_field_compute(ss_ctx *ctx, const ss_dem *dem, const ss_dem_frame *frame,
                               double unix_s, const ss_spa_params *params, int per_cell,
                               ss_sun_field *field)
{
    ss_sun_nodes nodes = {0};
    ss_status st = per_cell ? ss_sun_nodes_make(ctx, dem, frame, NULL, NULL, &nodes) : SS_OK;
    if (st == SS_OK)
        st = ss_sun_field_lattice(ctx, dem, frame, unix_s, params, per_cell, 0,
                                  dem->grid.height, &nodes, field);
    ss_sun_nodes_free(&nodes);
    if (st == SS_OK && per_cell)
        st = ss_sun_field_rows(ctx, field, 0, dem->grid.height);
    return st;
}

void ss_sun_field_free(ss_sun_field *field)
{
    free(field->grid_azimuth_deg);
    free(field->elevation_deg);
    free(field->apparent_elevation_deg);
    field->grid_azimuth_deg = field->elevation_deg = field->apparent_elevation_deg = NULL;
    free(field->lattice_cols);
    free(field->lattice_rows);
    free(field->node_azimuth_deg);
    free(field->node_elevation_deg);
    free(field->node_refraction_deg);
    field->lattice_cols = field->lattice_rows = NULL;
    field->node_azimuth_deg = field->node_elevation_deg = field->node_refraction_deg = NULL;
}
