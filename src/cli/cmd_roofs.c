/* skysweep roofs: a solar cadastre per roof plane and per building from a
 * DSM, building footprints and a weather file (doc/roofs.md). The
 * footprints (any OGR source, reprojected, repaired or skipped one by one)
 * are rasterized onto the DSM's grid, each building's roof cells split into
 * planes (roof_planes.h), the per-cell yield is the insolation command's
 * run with --weather and --pv on the same DSM (the same code path, every
 * insolation option passed on), and the planes' unshaded irradiation
 * comes from the same sky model on the plane with no horizon. Results go
 * to a GeoPackage (layers buildings and roof_planes), and a CSV of the
 * planes on request. Its insolation run and skies are in
 * roofs_insolation.c, the layers it writes in roofs_layers.c. */
#include "config.h"

#include <limits.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "commands.h"
#include "mpi_share.h"
#include "roof_horizons.h"
#include "roofs.h"
#include "temporaries.h"

#define SET(field) offsetof(roofs_settings, field)
/* roofs' own options; the others go on to the insolation run. */
static const opt_spec own_options[] = {
    {"buildings", OPT_INPUT, SET(buildings), "FILE", NULL, 0, 0, NULL,
     "building footprints: any vector source OGR reads (Shapefile, GeoPackage, GeoJSON, "
     "OpenStreetMap .osm/.pbf, ...); reprojected to the DSM's CRS (required)"},
    {"buildings-layer", OPT_STRING, SET(buildings_layer), "NAME", NULL, 0, 0, NULL,
     "the layer of --buildings that holds the footprints (default: an OpenStreetMap file's "
     "areas tagged building, else the first layer of polygons)"},
    {"id-field", OPT_STRING, SET(id_field), "NAME", NULL, 0, 0, NULL,
     "the footprints' field that names each building (default: building_id or id where the "
     "layer has one, else the feature id)"},
    {"dtm", OPT_INPUT, SET(dtm), "FILE", NULL, 0, 0, NULL,
     "terrain heights on the DSM's grid: each building's height_m is its highest roof plane "
     "cell above the median ground under its footprint"},
    {"csv", OPT_OUTPUT, SET(csv), "FILE", NULL, 0, 0, NULL,
     "also write the roof planes' rows as CSV"},
    {"min-area", OPT_DOUBLE, SET(min_area_m2), "M2", "5", 0.01, 1e6, NULL,
     "smallest roof plane (true 3D area, m2); smaller regions are not planes"},
    {"plane-angle", OPT_DOUBLE, SET(max_angle_deg), "DEG", "8", 0.5, 45, NULL,
     "a cell joins a plane where its local normal (3 x 3 fit) lies within this angle"},
    {"plane-tolerance", OPT_DOUBLE, SET(tolerance_m), "M", "0.15", 0.001, 10, NULL,
     "a cell joins a plane where its height lies within this of the plane"},
    {"obstacle-height", OPT_DOUBLE, SET(obstacle_m), "M", "0.3", 0.01, 100, NULL,
     "cells of no plane higher than the nearest plane by more are obstacles (chimneys, dormers)"},
    {"setback", OPT_DOUBLE, SET(setback_m), "M", "0.5", 0, 100, NULL,
     "usable cells lie at least this far (horizontally) from their plane's edges and obstacles"},
    {"min-irradiation", OPT_DOUBLE, SET(min_irradiation), "KWH_M2", "700", 0, 5000, NULL,
     "usable cells receive at least this much in the weather file's year (kWh/m2)"},
    {"max-tilt", OPT_DOUBLE, SET(max_tilt_deg), "DEG", "60", 0, 90, NULL,
     "usable planes are tilted at most this much"},
    {"max-off-equator", OPT_DOUBLE, SET(max_off_equator_deg), "DEG", "180", 0, 180, NULL,
     "usable planes face at most this far (azimuth) from the equator: 90 keeps east through "
     "west by the equator's side; planes tilted under 1 degree face it (default 180: any "
     "orientation, left to --min-irradiation)"},
    {"module-size", OPT_STRING, SET(module_size), "LxW", "1.7x1.0", 0, 0, NULL,
     "the modules' long and short sides (m) of the panel layout"},
    {"module-power", OPT_DOUBLE, SET(module_power_w), "W", "400", 1, 5000, NULL,
     "a module's nameplate power (W, STC): kwp = panels x this"},
    {"orientation", OPT_CHOICE, SET(orientation), NULL, "best", 0, 0, "portrait|landscape|best",
     "modules' long side up the slope (portrait), along the rows (landscape), or whichever "
     "fits more modules on each plane (best)"},
    {"module-spacing", OPT_DOUBLE, SET(module_spacing_m), "M", "0.02", 0, 10, NULL,
     "gap between modules of a row (m)"},
    {"row-spacing", OPT_DOUBLE, SET(row_spacing_m), "M", "0.02", 0, 50, NULL,
     "gap between rows on the plane (m; on racked flat roofs the least gap)"},
    {"min-panel-area", OPT_DOUBLE, SET(min_panel_area_m2), "M2", "10", 0, 1e6, NULL,
     "a plane whose modules would cover less than this (m2 of modules) gets none"},
    {"flat-tilt", OPT_DOUBLE, SET(flat_tilt_deg), "DEG", "10", 0, 45, NULL,
     "planes tilted less are flat roofs: modules racked at --rack-tilt facing the equator"},
    {"rack-tilt", OPT_DOUBLE, SET(rack_tilt_deg), "DEG", "10", 0, 60, NULL,
     "tilt of the racks on flat roofs"},
    {"rack-sun-elevation", OPT_DOUBLE, SET(rack_sun_elevation_deg), "DEG", NULL, 1, 90, NULL,
     "racked rows are spaced so that none shades the next with the sun this high toward the "
     "equator (default: the noon sun at the winter solstice at the DSM's centre, 90 - |lat| - "
     "23.44, at least 5)"},
    {"panels", OPT_FLAG, SET(panels_layer), NULL, NULL, 0, 0, NULL,
     "also write the layer panels: each module's footprint on the ground"},
    {"shade-table", OPT_FLAG, SET(shade_table), NULL, NULL, 0, 0, NULL,
     "also write the table plane_shade: each plane's share in direct sun by month and hour "
     "(a shadow sweep per record with the sun up)"},
    {"shade-masks", OPT_OUTPUT, SET(shade_masks), "FILE", NULL, 0, 0, NULL,
     "also write every cell's hourly shade masks (Google's hourlyShade): a GeoTIFF of 288 "
     "UInt32 bands, month x hour, bit d - 1 set where the cell is sunlit at that hour of day d"},
    {"cell-raster", OPT_OUTPUT, SET(cell_raster), "FILE", NULL, 0, 0, NULL,
     "also keep the per-cell results the planes are summed from: the insolation run's GeoTIFF "
     "on the DSM's grid, every band with its name and unit (global kWh/m2 of the period and of "
     "each month, DC and AC PV yield per kWp, ...; doc/insolation.md)"},
    {"horizon-files", OPT_STRING, SET(horizon_dir), "DIR", NULL, 0, 0, NULL,
     "also write a horizon file for PV software per roof plane, seen from its centre, into "
     "this existing folder as BUILDING_PLANE.ext (doc/pv-horizons.md)"},
    {"horizon-format", OPT_CHOICE, SET(horizon_format), NULL, "pvgis", 0, 0,
     ROOF_HORIZON_FORMATS, "format of --horizon-files (as horizon --format)"},
    OPT_END};
static const opt_spec passed_on[] = {
    {"weather", OPT_INPUT, SET(weather), "FILE", NULL, 0, 0, NULL,
     "the weather records (EPW, TMY3, PVGIS, NSRDB PSM or CSV); --time selects records as for "
     "insolation (default: a clear sky, hourly over --time or the year 2025)"},
    {"weather-far-ok", OPT_FLAG, SET(weather_far_ok), NULL, NULL, 0, 0, NULL,
     "use a weather file whose site lies farther than 100 km from the DSM's centre (as for "
     "insolation)"},
    {"weather-zone", OPT_STRING, SET(weather_zone), "+HH:MM", NULL, 0, 0, NULL,
     "the zone the weather file's local stamps are in (as for insolation; needed for a "
     "UMEP/SUEWS met file)"},
    OPT_END};

/* ---- per plane and per building ------------------------------------------- */

/* Whether window cell (c, r) of plane p lies at least setback from every
 * cell that is not p's (outside the building's window included). */
static int clear_of_edges(const int *plane_at, int cols, int rows, int c, int r, int p,
                          double setback_m, double cx, double cy)
{
    int reach_c = (int)ceil(setback_m / cx + 0.5), reach_r = (int)ceil(setback_m / cy + 0.5);
    for (int dr = -reach_r; dr <= reach_r; ++dr)
        for (int dc = -reach_c; dc <= reach_c; ++dc) {
            int cc = c + dc, rr = r + dr;
            int other = cc < 0 || rr < 0 || cc >= cols || rr >= rows || plane_at[rr * cols + cc] != p;
            double d = hypot(fmax(0.0, fabs((double)dc) - 0.5) * cx,
                             fmax(0.0, fabs((double)dr) - 0.5) * cy);
            if (other && d < setback_m)
                return 0;
        }
    return 1;
}

/* How far azimuth (clockwise from true north) turns from the equator's
 * direction at latitude lat: 0 facing it, 180 facing the pole. */
static double off_equator_deg(double azimuth_deg, double lat_deg)
{
    return fabs(fmod(azimuth_deg - (lat_deg >= 0 ? 180.0 : 0.0) + 540.0, 360.0) - 180.0);
}

/* Plane p's sums over its cells (label p, p + 1 in plane_at): the inner
 * ones (clear of the edges) give its irradiation; the usable ones (inner,
 * bright enough, not too steep, not facing too far from the equator) its
 * usable area, and are marked 1 in
 * usable (the building's window, zeroed by the caller). */
static void plane_irradiation(const sweep_job *job, const roofs_settings *set,
                              const roof_window *y, const ss_footprint *fp, const int *label,
                              const int *plane_at, int p, plane_row *row, unsigned char *usable)
{
    double cx = job->dem.grid.cell_x_m, cy = job->dem.grid.cell_y_m;
    double cell_m2 = cx * cy / cos(row->tilt_deg * M_PI / 180.0);
    double inner_kwh = 0;
    size_t n_inner = 0, n_usable = 0, n_all = 0;
    double all_kwh = 0;
    for (size_t i = 0; i < fp->n_cells; ++i) {
        if (label[i] != p)
            continue;
        int cell = fp->cells[i], width = job->dem.grid.width;
        double g = y->global[cell - y->base];
        if (!isfinite(g) || g < 0)
            continue;
        n_all++, all_kwh += g;
        int c = cell % width - fp->col0, r = cell / width - fp->row0;
        if (!clear_of_edges(plane_at, fp->cols, fp->rows, c, r, p + 1, set->setback_m, cx, cy))
            continue;
        n_inner++, inner_kwh += g;
        if (g < set->min_irradiation || row->tilt_deg > set->max_tilt_deg ||
            off_equator_deg(row->azimuth_deg, job->frame.centre_lat_deg) >
                set->max_off_equator_deg ||
            !isfinite(y->pv_ac[cell - y->base]) || y->pv_ac[cell - y->base] < 0)
            continue;
        n_usable++;
        usable[r * fp->cols + c] = 1;
    }
    row->area_m2 = (double)row->fit.n_cells * cell_m2;
    row->inner_area_m2 = (double)n_inner * cell_m2;
    row->usable_area_m2 = (double)n_usable * cell_m2;
    /* the plane's irradiation over its inner cells (its edges' slopes mix
     * the eaves' and ridges' neighbours); all its cells where none is inner */
    row->kwh_m2_year = n_inner ? inner_kwh / (double)n_inner
                       : n_all ? all_kwh / (double)n_all
                               : NAN;
}

/* The layout of orientation `landscape` on a plane's usable cells. */
static int lay_panels(const roofs_run_view *v, const plane_row *row, int landscape,
                      const unsigned char *usable, panel_layout *l, panel_geometry *g)
{
    const ss_dem_frame *fr = &v->job->frame;
    double equator = (fr->centre_lat_deg >= 0 ? 180.0 : 0.0) - fr->grid_north_deg;
    *g = panel_geometry_on(&v->set->panel, landscape, row->tilt_deg, row->fit.aspect_grid_deg,
                           equator);
    return panels_lay(g, usable, v->fp->cols, v->fp->rows, v->job->dem.grid.cell_x_m,
                      v->job->dem.grid.cell_y_m, l);
}

/* Plane row's modules on its usable cells (the orientation asked, or the
 * one that fits more, portrait on a tie); none below the minimum panel
 * area. kwp is their nameplate; each module yields its kWp x the mean AC
 * kWh/kWp of the cells it overlaps; the months share the year as the
 * modules' cells share their irradiation. Returns 0, or -1 out of memory. */
static int plane_panels(const roofs_run_view *v, plane_row *row, const unsigned char *usable,
                        panel_layout *l)
{
    const panel_options *o = &v->set->panel;
    panel_geometry g;
    int landscape = o->orientation == PANELS_LANDSCAPE;
    if (lay_panels(v, row, landscape, usable, l, &g) < 0)
        return -1;
    if (o->orientation == PANELS_BEST) {
        size_t portrait = l->n;
        if (lay_panels(v, row, 1, usable, l, &g) < 0)
            return -1;
        if (l->n <= portrait && lay_panels(v, row, 0, usable, l, &g) < 0)
            return -1;
    }
    if ((double)l->n * o->length_m * o->width_m < o->min_panel_area_m2)
        l->n = 0;
    const ss_footprint *fp = v->fp;
    int width = v->job->dem.grid.width;
    const roof_window *y = v->win;
    double kw = o->power_w / 1000.0, poa = 0, month[12] = {0};
    row->n_panels = (int)l->n;
    row->racked = g.racked, row->landscape = g.landscape;
    row->panel_tilt_deg = g.tilt_deg;
    row->panel_azimuth_deg = fmod(fmod(g.facing_grid_deg + v->job->frame.grid_north_deg, 360.0) +
                                      360.0,
                                  360.0);
    row->kwp = (double)l->n * kw;
    row->kwh_ac_year = 0;
    row->kwh_dc_year = 0;
    for (size_t k = 0; k < l->n; ++k) {
        panel_place *p = &l->items[k];
        double ac = 0, dc = 0, g_sum = 0;
        for (int i = 0; i < p->n_cells; ++i) {
            int w = l->cells[p->first + (size_t)i];
            size_t cell = (size_t)(fp->row0 + w / fp->cols) * (size_t)width +
                          (size_t)(fp->col0 + w % fp->cols) - y->base;
            ac += y->pv_ac[cell];
            dc += y->pv_dc[cell];
            g_sum += y->global[cell];
            for (int m = 0; m < 12; ++m)
                month[m] += y->monthly[(size_t)m * y->n + cell] / p->n_cells;
        }
        p->kwh_ac_year = kw * ac / p->n_cells;
        row->kwh_ac_year += p->kwh_ac_year;
        row->kwh_dc_year += kw * dc / p->n_cells;
        poa += g_sum / p->n_cells;
    }
    row->kwh_per_kwp = row->kwp > 0 ? row->kwh_ac_year / row->kwp : NAN;
    for (int m = 0; m < 12; ++m)
        row->kwh_ac_month[m] = poa > 0 ? row->kwh_ac_year * month[m] / poa : 0;
    return 0;
}


/* A banded job's height origin before any window is read: rows from the
 * first until one holds a height, as a whole read sets it (the windows'
 * heights and the DSM's height the sun is taken at are then the whole
 * grid's). */
static ss_status settle_origin(sweep_job *job)
{
    int width = job->dem.grid.width;
    float *row = malloc(sizeof(float) * (size_t)width);
    ss_status st = row ? SS_OK : command_out_of_memory(&job->run);
    int found = 0;
    for (int r = 0; st == SS_OK && !found && r < job->dem.grid.height; ++r) {
        st = job_read_rows(job, r, 1, row);
        for (int c = 0; st == SS_OK && c < width && !found; ++c)
            found = isfinite(row[c]);
    }
    free(row);
    return st;
}

/* The files' overlaps were refused when the options were parsed (every
 * file option is declared an input or an output, run_parse); what is left
 * is the CSV's and the masks' own check as existing outputs. */
static ss_status check_files(roofs_run *r)
{
    ss_status st = r->set.csv ? ss_output_check(r->job.run.ctx, r->set.csv) : SS_OK;
    if (st == SS_OK && r->set.shade_masks)
        st = ss_output_check(r->job.run.ctx, r->set.shade_masks);
    if (st == SS_OK && r->set.cell_raster)
        st = ss_output_check(r->job.run.ctx, r->set.cell_raster);
    return st;
}

/* Opens --dtm, on the DSM's grid, for the windows to read. */
static ss_status open_dtm(roofs_run *r)
{
    ss_dem_read_options o = {0};
    const char *paths[1] = {r->set.dtm};
    ss_status st = ss_dem_open(r->job.run.ctx, paths, 1, &o, &r->dtm, &r->dtm_src);
    if (st != SS_OK)
        return st;
    const ss_dem *s = &r->job.dem, *d = &r->dtm;
    int same = d->grid.width == s->grid.width && d->grid.height == s->grid.height;
    for (int k = 0; same && k < 6; ++k)
        same =
            fabs(d->geotransform[k] - s->geotransform[k]) <= 1e-6 * (1 + fabs(s->geotransform[k]));
    return same ? SS_OK
                : ss_ctx_error(r->job.run.ctx, SS_ERR_INPUT,
                               "--dtm '%s' must lie on the DSM's grid (size and geotransform)",
                               r->set.dtm);
}

static int by_float(const void *x, const void *y)
{
    float a = *(const float *)x, b = *(const float *)y;
    return (a > b) - (a < b);
}

/* Highest roof-plane cell above the median ground under the footprint. */
static double building_height(const roofs_run *r, const ss_footprint *fp, const int *label)
{
    float *ground = malloc(sizeof(float) * (fp->n_cells + 1));
    size_t n = 0;
    double top = -INFINITY;
    const roof_window *y = &r->win;
    for (size_t i = 0; ground && i < fp->n_cells; ++i) {
        size_t cell = (size_t)fp->cells[i] - y->base;
        if (isfinite(y->dtm[cell]))
            ground[n++] = y->dtm[cell];
        if (label[i] >= 0)
            top = fmax(top, y->z[cell] + r->job.dem.grid.z_origin_m);
    }
    if (n)
        qsort(ground, n, sizeof *ground, by_float);
    double h = n && isfinite(top) ? top - ground[n / 2] : NAN;
    free(ground);
    return h;
}

/* One building: its planes, their yield and polygons, and its sums. */
/* Keeps plane row's modules (layout l) for the layer panels. */
static ss_status keep_panels(roofs_run *r, size_t row, const ss_footprint *fp,
                             const panel_layout *l)
{
    if (r->n_panels + l->n > r->cap_panels) {
        size_t cap = 2 * (r->n_panels + l->n) + 64;
        panel_row *q = realloc(r->panels, cap * sizeof *q);
        if (!q)
            return command_out_of_memory(&r->job.run);
        r->panels = q, r->cap_panels = cap;
    }
    double cx = r->job.dem.grid.cell_x_m, cy = r->job.dem.grid.cell_y_m;
    for (size_t k = 0; k < l->n; ++k) {
        double col_row[4][2];
        for (int i = 0; i < 4; ++i) {
            col_row[i][0] = fp->col0 + l->items[k].corner[i][0] / cx;
            col_row[i][1] = fp->row0 - l->items[k].corner[i][1] / cy;
        }
        void *geometry = ss_polygon_of_grid_points(&r->job.dem, col_row, 4);
        if (!geometry)
            return command_out_of_memory(&r->job.run);
        r->panels[r->n_panels++] = (panel_row){row, (int)k + 1, l->items[k].kwh_ac_year,
                                               geometry};
    }
    return SS_OK;
}

/* Plane p's cells for the shade table (its usable ones, or all its cells
 * where none is usable), as grid cells into cells (fp->n_cells at most). */
static ss_status add_shade_plane(roofs_run *r, const ss_footprint *fp, const int *label, int p,
                                 const unsigned char *usable, plane_row *row, int *cells)
{
    int width = r->job.dem.grid.width, n = 0, n_all = 0;
    for (size_t i = 0; i < fp->n_cells; ++i) {
        int c = fp->cells[i] % width - fp->col0, rr = fp->cells[i] / width - fp->row0;
        if (label[i] == p && usable[rr * fp->cols + c])
            cells[n++] = fp->cells[i];
    }
    row->shade_on_usable = n > 0;
    for (size_t i = 0; n == 0 && i < fp->n_cells; ++i)
        if (label[i] == p)
            cells[n_all++] = fp->cells[i];
    return roof_shade_add_plane(&r->shade, row->tilt_deg, row->fit.aspect_grid_deg, cells,
                                n ? n : n_all) == 0
               ? SS_OK
               : command_out_of_memory(&r->job.run);
}

/* Room for n more plane rows (they grow with the planes found, not with
 * the footprints' cells: a city's would not fit). Returns 0, or -1. */
static int room_for_planes(roofs_run *r, size_t n)
{
    if (r->n_planes + n <= r->cap_planes)
        return 0;
    size_t cap = 2 * (r->n_planes + n) + 64;
    plane_row *p = realloc(r->planes, cap * sizeof *p);
    if (!p)
        return -1;
    r->planes = p, r->cap_planes = cap;
    return 0;
}

static ss_status do_building(roofs_run *r, size_t b, int *label, int *plane_at,
                             unsigned char *usable, panel_layout *layout, int *cells)
{
    const ss_footprint *fp = &r->fps.items[b];
    sweep_job *job = &r->job;
    const ss_grid *g = &job->dem.grid;
    roof_plane_options o = {r->set.min_area_m2, r->set.max_angle_deg, r->set.tolerance_m,
                            r->set.obstacle_m};
    double t0 = run_now();
    roof_plane *found;
    /* the footprint's cells in the window (cells is scratch until the planes') */
    for (size_t i = 0; i < fp->n_cells; ++i)
        cells[i] = (int)((size_t)fp->cells[i] - r->win.base);
    int n = roof_planes_find(r->win.z, g->width, g->cell_x_m, g->cell_y_m, fp->col0,
                             fp->row0 - r->win.row0, fp->cols, fp->rows, cells, fp->n_cells, &o,
                             &found, label);
    if (n < 0)
        return command_out_of_memory(&job->run);
    building_sums *s = &r->sums[b];
    memset(s, 0, sizeof *s);
    s->n_planes = n;
    s->footprint_area_m2 = (double)fp->n_cells * g->cell_x_m * g->cell_y_m;
    for (int k = 0; k < fp->cols * fp->rows; ++k)
        plane_at[k] = 0;
    for (size_t i = 0; i < fp->n_cells; ++i) {
        int c = fp->cells[i] % g->width - fp->col0, row = fp->cells[i] / g->width - fp->row0;
        plane_at[row * fp->cols + c] = label[i] >= 0 ? label[i] + 1 : 0;
        s->obstacle_area_m2 += label[i] == ROOF_OBSTACLE ? g->cell_x_m * g->cell_y_m : 0;
    }
    void **geoms = calloc((size_t)n + 1, sizeof *geoms);
    ss_status st = geoms && room_for_planes(r, (size_t)n) == 0
                       ? ss_polygons_of_labels(job->run.ctx, &job->dem, plane_at, fp->col0,
                                               fp->row0, fp->cols, fp->rows, n, geoms)
                       : command_out_of_memory(&job->run);
    r->seconds_planes += run_now() - t0;
    for (int p = 0; st == SS_OK && p < n; ++p) {
        plane_row *row = &r->planes[r->n_planes++];
        memset(row, 0, sizeof *row);
        row->building = b;
        row->number = p + 1;
        row->fit = found[p];
        row->tilt_deg = found[p].tilt_deg;
        double az = found[p].aspect_grid_deg + job->frame.grid_north_deg;
        az = fmod(fmod(az, 360.0) + 360.0, 360.0);
        row->azimuth_deg = row->tilt_deg < 1.0 ? (job->frame.centre_lat_deg >= 0 ? 180.0 : 0.0)
                                               : az;
        row->geometry = geoms[p];
        geoms[p] = NULL;
        roof_plane_centre(fp->cells, label, fp->n_cells, g->width, p, &row->centre_col,
                          &row->centre_row);
        memset(usable, 0, (size_t)fp->cols * (size_t)fp->rows);
        plane_irradiation(job, &r->set, &r->win, fp, label, plane_at, p, row, usable);
        roofs_run_view view = {job, &r->set, fp, &r->win};
        double t1 = run_now();
        if (plane_panels(&view, row, usable, layout) < 0)
            st = command_out_of_memory(&job->run);
        if (st == SS_OK && r->set.panels_layer)
            st = keep_panels(r, r->n_planes - 1, fp, layout);
        if (st == SS_OK)
            st = add_shade_plane(r, fp, label, p, usable, row, cells);
        r->seconds_panels += run_now() - t1;
        s->n_panels += row->n_panels;
        s->roof_area_m2 += row->area_m2;
        s->usable_area_m2 += row->usable_area_m2;
        s->kwp += row->kwp;
        s->kwh_ac_year += row->kwh_ac_year;
        s->kwh_dc_year += row->kwh_dc_year;
        for (int m = 0; m < 12; ++m)
            s->kwh_ac_month[m] += row->kwh_ac_month[m];
    }
    s->height_m = r->win.dtm ? building_height(r, fp, label) : NAN;
    for (int p = 0; geoms && p < n; ++p)
        ss_geometry_free(geoms[p]);
    free(geoms);
    free(found);
    return st;
}

/* ---- windows of rows (doc/roofs.md, "Scale") -------------------------------- */

static void free_window(roof_window *w)
{
    free(w->z_read);
    free(w->dtm);
    free(w->global);
    free(w->monthly);
    free(w->pv_dc);
    free(w->pv_ac);
    memset(w, 0, sizeof *w);
}

/* Room for windows of up to rows rows. */
static ss_status alloc_window(roofs_run *r, int rows)
{
    roof_window *w = &r->win;
    size_t n = (size_t)rows * (size_t)r->job.dem.grid.width + 1;
    w->global = malloc(sizeof(float) * n);
    w->monthly = malloc(sizeof(float) * n * 12);
    w->pv_dc = malloc(sizeof(float) * n);
    w->pv_ac = malloc(sizeof(float) * n);
    w->z_read = r->job.source ? malloc(sizeof(float) * n) : NULL;
    w->dtm = r->set.dtm ? malloc(sizeof(float) * n) : NULL;
    return w->global && w->monthly && w->pv_dc && w->pv_ac && (w->z_read || !r->job.source) &&
                   (w->dtm || !r->set.dtm)
               ? SS_OK
               : command_out_of_memory(&r->job.run);
}

/* Rows [row0, row0 + rows) into the window: the DSM's (read from its files
 * where the job holds it in bands), the ground's (--dtm) and the
 * insolation run's results. */
static ss_status read_window(roofs_run *r, int row0, int rows)
{
    roof_window *w = &r->win;
    sweep_job *job = &r->job;
    ss_ctx *ctx = job->run.ctx;
    int width = job->dem.grid.width, height = job->dem.grid.height;
    w->row0 = row0, w->rows = rows;
    w->base = (size_t)row0 * (size_t)width, w->n = (size_t)rows * (size_t)width;
    ss_status st = SS_OK;
    if (job->source)
        st = job_read_rows(job, row0, rows, w->z_read);
    w->z = job->source ? w->z_read : job->dem.grid.z + w->base;
    if (st == SS_OK && w->dtm) {
        st = ss_dem_source_read(ctx, r->dtm_src, &r->dtm, row0, rows, w->dtm);
        for (size_t i = 0; st == SS_OK && i < w->n; ++i)
            w->dtm[i] += (float)r->dtm.grid.z_origin_m;
    }
    const char *raster = r->raster;
    if (st == SS_OK)
        st = ss_raster_read_rows(ctx, raster, BAND_GLOBAL, 1, width, height, row0, rows, w->global);
    if (st == SS_OK)
        st = ss_raster_read_rows(ctx, raster, BAND_MONTHS, 12, width, height, row0, rows,
                                 w->monthly);
    if (st == SS_OK)
        st = ss_raster_read_rows(ctx, raster, BAND_PV_DC, 1, width, height, row0, rows, w->pv_dc);
    if (st == SS_OK)
        st = ss_raster_read_rows(ctx, raster, BAND_PV_AC, 1, width, height, row0, rows, w->pv_ac);
    return st;
}

/* The most rows a window may hold: the job's band where --memory keeps the
 * DSM in its files, else the grid's; a test hook (doc/roofs.md, "Scale")
 * makes windows of fewer rows on a DSM held whole, so that a small test
 * grid runs in several windows. */
static int window_rows(const roofs_run *r)
{
    int rows = r->job.source ? r->job.band_rows : r->job.dem.grid.height;
    const char *hook = getenv("SKYSWEEP_TEST_ROOF_WINDOW_ROWS");
    int test = hook ? atoi(hook) : 0;
    return test > 0 && test < rows ? test : rows;
}

/* Refuses, before the insolation run, what windows cannot do: a footprint
 * taller than a window, and what needs the whole grid held (the horizon
 * files' sweeps, the shade masks). */
static ss_status check_windows(roofs_run *r)
{
    ss_ctx *ctx = r->job.run.ctx;
    const char *memory = r->set.common.memory ? r->set.common.memory : "half the machine's memory";
    int most = window_rows(r);
    double row_mib = (double)r->job.dem.grid.width * (double)WINDOW_CELL_BYTES / 1048576.0;
    for (size_t b = 0; b < r->fps.n; ++b) {
        const ss_footprint *fp = &r->fps.items[b];
        /* bands of 256 rows and more come in whole 256-row strips */
        int need = fp->rows <= 256 ? fp->rows : 256 * ((fp->rows + 255) / 256);
        if (fp->rows > most)
            return ss_ctx_error(ctx, SS_ERR_MEMORY,
                                "the memory budget (%s) holds windows of %d rows, and footprint "
                                "'%s' spans %d: windows of %d rows need at least %.0f MiB more "
                                "--memory (doc/roofs.md)",
                                memory, most, fp->id, fp->rows, need,
                                ceil((need - most) * row_mib));
    }
    if (r->job.source && (r->set.horizon_dir || r->set.shade_masks))
        return ss_ctx_error(ctx, SS_ERR_MEMORY,
                            "%s needs the DSM held whole, and the memory budget (%s) keeps it "
                            "in its files: give more --memory or leave it out",
                            r->set.horizon_dir ? "--horizon-files" : "--shade-masks", memory);
    return SS_OK;
}

/* A footprint's first row and index. */
typedef struct {
    int row0;
    size_t index;
} footprint_start;

static int by_start(const void *x, const void *y)
{
    const footprint_start *a = x, *b = y;
    return a->row0 != b->row0 ? (a->row0 > b->row0) - (a->row0 < b->row0)
                              : (a->index > b->index) - (a->index < b->index);
}

static int by_index(const void *x, const void *y)
{
    const footprint_start *a = x, *b = y;
    return (a->index > b->index) - (a->index < b->index);
}

/* Puts the planes (with their modules and shade cells) in the order of
 * their buildings, as one window over the whole grid gives them: windows
 * take the buildings by their rows. Returns 0, or -1 out of memory. */
static int order_planes(roofs_run *r)
{
    size_t n = r->n_planes, nb = r->fps.n;
    size_t *next = calloc(nb + 1, sizeof *next), *to = malloc(sizeof *to * (n + 1));
    size_t *at = calloc(n + 1, sizeof *at);
    plane_row *planes = malloc(sizeof *planes * (n + 1));
    shade_plane *shade = malloc(sizeof *shade * (n + 1));
    panel_row *panels = malloc(sizeof *panels * (r->n_panels + 1));
    int ok = next && to && at && planes && shade && panels && r->shade.n_planes == n;
    for (size_t i = 0; ok && i < n; ++i)
        next[r->planes[i].building + 1]++;
    for (size_t b = 1; ok && b <= nb; ++b)
        next[b] += next[b - 1];
    for (size_t i = 0; ok && i < n; ++i) {
        to[i] = next[r->planes[i].building]++;
        planes[to[i]] = r->planes[i];
        shade[to[i]] = r->shade.planes[i];
    }
    /* the modules by their plane's new place, in their order within it */
    for (size_t k = 0; ok && k < r->n_panels; ++k)
        at[to[r->panels[k].plane] + 1]++;
    for (size_t i = 1; ok && i <= n; ++i)
        at[i] += at[i - 1];
    for (size_t k = 0; ok && k < r->n_panels; ++k) {
        panel_row p = r->panels[k];
        p.plane = to[p.plane];
        panels[at[p.plane]++] = p;
    }
    if (ok && n) {
        memcpy(r->planes, planes, sizeof *planes * n);
        memcpy(r->shade.planes, shade, sizeof *shade * n);
        if (r->n_panels)
            memcpy(r->panels, panels, sizeof *panels * r->n_panels);
    }
    free(next);
    free(to);
    free(at);
    free(planes);
    free(shade);
    free(panels);
    return ok ? 0 : -1;
}

/* Every building, a window of rows at a time: footprints by their first
 * row, each window taking the next while their rows fit in it, its
 * buildings in their own order. */
static ss_status do_windows(roofs_run *r, int *label, int *plane_at, unsigned char *usable,
                            panel_layout *layout, int *cells)
{
    size_t n = r->fps.n;
    int most = window_rows(r);
    footprint_start *order = malloc(sizeof *order * (n + 1));
    ss_status st = order ? alloc_window(r, most) : command_out_of_memory(&r->job.run);
    for (size_t b = 0; st == SS_OK && b < n; ++b)
        order[b] = (footprint_start){r->fps.items[b].row0, b};
    if (st == SS_OK)
        qsort(order, n, sizeof *order, by_start);
    for (size_t i = 0, j; st == SS_OK && i < n; i = j) {
        const ss_footprint *fp = r->fps.items;
        int row0 = order[i].row0, end = row0 + fp[order[i].index].rows;
        for (j = i + 1; j < n; ++j) {
            int e = order[j].row0 + fp[order[j].index].rows;
            if ((e > end ? e : end) - row0 > most)
                break;
            end = e > end ? e : end;
        }
        qsort(order + i, j - i, sizeof *order, by_index);
        st = read_window(r, row0, end - row0);
        r->n_windows++;
        r->most_rows = end - row0 > r->most_rows ? end - row0 : r->most_rows;
        for (size_t k = i; st == SS_OK && k < j; ++k)
            st = do_building(r, order[k].index, label, plane_at, usable, layout, cells);
    }
    free(order);
    free_window(&r->win);
    if (st == SS_OK && r->n_windows > 1 && order_planes(r) != 0)
        st = command_out_of_memory(&r->job.run);
    return st;
}

/* Every plane's irradiation (kWh/m2) with no horizon: the same records,
 * sky model and albedo on an open plane of its tilt and true azimuth over
 * level ground (ss_insolation_open_planes). */
static ss_status unshaded_planes(roofs_run *r)
{
    ss_ctx *ctx = r->job.run.ctx;
    size_t n = r->n_planes;
    double *tilt = malloc(sizeof(double) * (n + 1)), *az = malloc(sizeof(double) * (n + 1));
    double *wh = malloc(sizeof(double) * (n + 1));
    ss_insolation_options io;
    ss_status st = tilt && az && wh ? ss_insolation_params_options(ctx, &r->set.ins,
                                                                   SS_SHADOW_EXACT, &io)
                                    : command_out_of_memory(&r->job.run);
    for (size_t i = 0; st == SS_OK && i < n; ++i)
        tilt[i] = r->planes[i].tilt_deg, az[i] = r->planes[i].azimuth_deg;
    if (st == SS_OK)
        st = ss_insolation_open_planes(ctx, &io, r->sky.n, roofs_sky_step_at, &r->sky, (int)n, tilt, az, wh);
    for (size_t i = 0; st == SS_OK && i < n; ++i) {
        plane_row *p = &r->planes[i];
        p->unshaded_kwh_m2_year = wh[i] / 1000.0;
        p->shading_loss_pct = p->unshaded_kwh_m2_year > 0
                                  ? 100.0 * (1.0 - p->kwh_m2_year / p->unshaded_kwh_m2_year)
                                  : NAN;
        building_sums *s = &r->sums[p->building];
        if (isfinite(p->kwh_m2_year)) {
            double a = p->inner_area_m2 > 0 ? p->inner_area_m2 : p->area_m2;
            s->inner_area_m2 += a;
            s->inner_kwh += a * p->kwh_m2_year;
            s->inner_unshaded_kwh += a * p->unshaded_kwh_m2_year;
        }
    }
    free(tilt);
    free(az);
    free(wh);
    return st;
}

/* Plane ids of a building go 1..n; the ids in plane_at are p + 1. */
static ss_status find_all(roofs_run *r)
{
    size_t most_cells = 1, most_window = 1;
    for (size_t b = 0; b < r->fps.n; ++b) {
        const ss_footprint *fp = &r->fps.items[b];
        most_cells = fp->n_cells > most_cells ? fp->n_cells : most_cells;
        size_t win = (size_t)fp->cols * (size_t)fp->rows;
        most_window = win > most_window ? win : most_window;
    }
    int *label = malloc(sizeof(int) * most_cells), *plane_at = malloc(sizeof(int) * most_window);
    unsigned char *usable = malloc(most_window);
    int *cells = malloc(sizeof(int) * most_cells);
    panel_layout layout = {0};
    r->sums = calloc(r->fps.n + 1, sizeof *r->sums);
    ss_status st = label && plane_at && usable && cells && r->sums
                       ? SS_OK
                       : command_out_of_memory(&r->job.run);
    if (st == SS_OK)
        st = do_windows(r, label, plane_at, usable, &layout, cells);
    double t0 = run_now();
    if (st == SS_OK)
        st = unshaded_planes(r);
    r->seconds_unshaded = run_now() - t0;
    free(label);
    free(plane_at);
    free(usable);
    free(cells);
    panel_layout_free(&layout);
    t0 = run_now();
    size_t grid_cells = (size_t)r->job.dem.grid.width * (size_t)r->job.dem.grid.height;
    if (st == SS_OK && r->set.shade_masks &&
        !(r->shade.masks = calloc(SHADE_SLOTS * grid_cells, sizeof *r->shade.masks)))
        st = ss_ctx_error(r->job.run.ctx, SS_ERR_MEMORY,
                          "out of memory for --shade-masks (%zu MB: 1.2 kB a cell)",
                          SHADE_SLOTS * grid_cells * sizeof *r->shade.masks >> 20);
    ss_source src = job_source(&r->job, NULL);
    if (st == SS_OK && (r->set.shade_table || r->set.shade_masks))
        st = roof_shade_sweep(r->job.run.ctx, &src, &r->job.opt, r->job.frame.grid_north_deg,
                              r->sky.steps, r->sky.n, r->weather.utc_offset_h, &r->shade);
    r->seconds_shade = run_now() - t0;
    return st;
}

/* --horizon-files: one file per plane, at its centre (roof_horizons.c). */
static ss_status plane_horizon_files(roofs_run *r)
{
    roof_horizon_site *s = malloc(sizeof *s * (r->n_planes + 1));
    if (!s)
        return command_out_of_memory(&r->job.run);
    for (size_t i = 0; i < r->n_planes; ++i)
        s[i] = (roof_horizon_site){r->fps.items[r->planes[i].building].id, r->planes[i].number,
                                   r->planes[i].centre_col, r->planes[i].centre_row};
    ss_status st = roof_horizon_files(r->job.run.ctx, &r->job.dem, &r->job.frame,
                                      r->set.horizon_dir, r->set.horizon_format, s, r->n_planes);
    free(s);
    return st;
}

static void print_summary(roofs_run *r)
{
    const ss_footprints *f = &r->fps;
    printf("buildings %zu read from '%s': %zu placed (%zu partly outside the DSM, flagged), "
           "%zu repaired; skipped %zu invalid, %zu empty, %zu outside the DSM, %zu covering no "
           "cell centre; ids from %s\n",
           f->read, r->set.buildings, f->n, f->partly_outside, f->repaired, f->invalid, f->empty,
           f->outside, f->no_cell, *f->id_field ? f->id_field : "the feature ids");
    for (size_t i = 0; i < f->n_notes; ++i)
        printf("          %s\n", f->notes[i]);
    printf("sky       %s\n", r->sky_note);
    double kwp = 0, kwh = 0, dc = 0, usable = 0, area = 0;
    for (size_t b = 0; b < f->n; ++b)
        kwp += r->sums[b].kwp, kwh += r->sums[b].kwh_ac_year, dc += r->sums[b].kwh_dc_year,
            usable += r->sums[b].usable_area_m2, area += r->sums[b].roof_area_m2;
    printf("planes    %zu roof planes, %.0f m2 (true area), %.0f m2 usable\n", r->n_planes, area,
           usable);
    int panels = 0;
    for (size_t b = 0; b < f->n; ++b)
        panels += r->sums[b].n_panels;
    printf("yield     %d modules, %.1f kWp, %.0f kWh AC a year (%.0f kWh/kWp), %.0f kWh DC\n",
           panels, kwp, kwh, kwp > 0 ? kwh / kwp : 0.0, dc);
    if (r->job.source)
        printf("memory    the DSM read in %d windows of up to %d rows (%d rows a window under "
               "--memory)\n",
               r->n_windows, r->most_rows, r->job.band_rows);
    else
        printf("memory    the DSM held whole, %d window%s of up to %d rows\n", r->n_windows,
               r->n_windows == 1 ? "" : "s", r->most_rows);
    printf("time      insolation %.2f s, planes %.2f s, panels %.2f s, unshaded planes %.2f s, "
           "shade table %.2f s (%zu sweeps), output %.2f s -> %s\n",
           r->seconds_insolation, r->seconds_planes, r->seconds_panels, r->seconds_unshaded,
           r->seconds_shade, r->shade.sweeps, r->seconds_write, r->job.output);
}

static void close_run(roofs_run *r)
{
    for (size_t i = 0; r->planes && i < r->n_planes; ++i)
        ss_geometry_free(r->planes[i].geometry);
    free(r->planes);
    for (size_t i = 0; i < r->n_panels; ++i)
        ss_geometry_free(r->panels[i].geometry);
    free(r->panels);
    roof_shade_free(&r->shade);
    free(r->sums);
    free_window(&r->win);
    if (*r->raster)
        remove(r->raster);
    if (r->set.cell_raster)
        ss_temporaries_forget(r->set.cell_raster);
    free(r->sky.steps);
    ss_dem_source_close(r->dtm_src);
    ss_dem_free(&r->dtm);
    if (*r->clear_sky) {
        remove(r->clear_sky);
        ss_temporaries_forget(r->job.output);
    }
    ss_weather_free(&r->weather);
    ss_footprints_free(&r->fps);
    job_close(&r->job);
}

/* The sweep options of the shade table's sweeps: those the planner gives
 * `skysweep shadow` on this DSM (the line model: box lines where walls
 * stand), so that a cell's verdict is the shadow product's. Its plan is
 * not printed (the insolation run's was). Returns -1 to go on, else the
 * exit code. */
static int plan_shade_sweeps(roofs_run *r)
{
    int quiet = r->job.run.quiet;
    r->job.run.quiet = 1;
    int rc = job_plan(&r->job, &r->set.common, ss_product_named("shadow"), NULL, 0, NULL);
    r->job.run.quiet = quiet;
    return rc;
}

/* The panel options from their words: --module-size L x W, both positive
 * (the longer is the length). Returns -1, or exit 2 with one line. */
static int settle_panel_options(roofs_settings *set)
{
    double a = 0, b = 0;
    char tail;
    if (sscanf(set->module_size, "%lf%*[xX]%lf%c", &a, &b, &tail) != 2 || !isfinite(a) ||
        !isfinite(b) || a <= 0 || b <= 0 || a > 10 || b > 10)
        return run_usage_error("roofs", "--module-size must be LENGTHxWIDTH in metres, both "
                                        "above 0 and at most 10 (e.g. 1.7x1.0)");
    set->panel = (panel_options){fmax(a, b), fmin(a, b), set->module_power_w,
                                 (panel_orientation)set->orientation, set->module_spacing_m,
                                 set->row_spacing_m, set->flat_tilt_deg, set->rack_tilt_deg,
                                 set->rack_sun_elevation_deg, set->min_panel_area_m2};
    return -1;
}

/* The racks' design sun where none was given: the noon sun at the winter
 * solstice at the DSM's centre (the rule of thumb of row spacing: no row
 * shades the next on the year's shortest day at noon), at least 5 deg. */
static void settle_rack_sun(roofs_settings *set, double lat_deg)
{
    if (set->panel.rack_sun_elevation_deg <= 0)
        set->panel.rack_sun_elevation_deg = fmax(5.0, 90.0 - fabs(lat_deg) - 23.44);
}

/* Options that make no sense for roofs, refused in one line. */
/* Whether a file's name ends as a GeoTIFF's does. */
static int raster_is_geotiff(const char *path)
{
    const char *dot = strrchr(path, '.');
    return dot && (strcasecmp(dot, ".tif") == 0 || strcasecmp(dot, ".tiff") == 0);
}

static int refuse_options(const roofs_settings *set, const opt_spec *const *tables)
{
    if (!set->buildings)
        return run_usage_error("roofs", "--buildings FILE is needed (the footprints)");
    if (!set->weather && (set->weather_zone || set->weather_far_ok))
        return run_usage_error("roofs", "--weather-zone and --weather-far-ok are for --weather: "
                                        "without it the sky is clear");
    if (set->common.projwin)
        return run_usage_error("roofs", "the footprints say where: -projwin is for rasters");
    if (strcmp(set->common.format, opt_find(tables, "of")->default_text) != 0 ||
        set->common.creation_options.count)
        return run_usage_error("roofs", "the output is a GeoPackage: -of and -co are for "
                                        "rasters");
    if (strcmp(set->ins.surface, opt_find(tables, "surface")->default_text) != 0)
        return run_usage_error("roofs", "roofs take each cell's own surface: --surface is for "
                                        "insolation");
    if (set->cell_raster && !raster_is_geotiff(set->cell_raster))
        return run_usage_error("roofs", "--cell-raster writes the insolation run's GeoTIFF: "
                                        "name it .tif or .tiff");
    int bad_folder = roof_horizon_check(set->horizon_dir);
    return bad_folder ? bad_folder : -1;
}

int cmd_roofs(int argc, char **argv)
{
    roofs_run *r = calloc(1, sizeof *r);
    if (!r) {
        fprintf(stderr, "skysweep roofs: out of memory\n");
        return SS_ERR_MEMORY;
    }
    roofs_settings *set = &r->set;
    common_settings_init(&set->common);
    opt_spec insolation_options[32];
    opt_from_params("insolation", offsetof(roofs_settings, ins), insolation_options, 32);
    /* Trees and their seasons, as insolation's (doc/vegetation.md). */
    opt_spec tree_opts[TREE_OPTIONS_MAX], season_opts[INSOLATION_TREE_OPTIONS_MAX];
    insolation_tree_options(offsetof(roofs_settings, trees), tree_opts, season_opts);
    const opt_spec *tables[] = {own_options,
                                passed_on,
                                insolation_options,
                                tree_opts,
                                season_opts,
                                crown_light_options(offsetof(roofs_settings, trees) +
                                                    offsetof(insolation_tree_settings, light)),
                                sun_options(),
                                common_options(),
                                NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse(
        "roofs", tables, set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 2,
        "skysweep roofs --buildings FOOTPRINTS [--weather FILE] [--dtm DTM] [--csv FILE] "
        "[options] DSM... OUT.gpkg",
        "A solar cadastre: roof planes fitted in the DSM inside each footprint, their tilt, "
        "azimuth,\ntrue area and usable area, a panel layout on the usable area, and per plane "
        "and per\nbuilding the modules' kWp, AC and DC kWh per year, AC kWh per month "
        "(PVWatts), kWh/kWp,\nshading loss and a suitability class, from the insolation run "
        "with --weather and --pv\non the DSM (its options apply; without --weather a clear "
        "sky); on request each plane's\nshare in direct sun by month and hour. A GeoPackage "
        "with layers buildings and roof_planes,\nand panels (--panels) and plane_shade "
        "(--shade-table) on request (doc/roofs.md).",
        &set->common.device);
    if (rc < 0)
        rc = refuse_options(set, tables);
    if (rc < 0)
        rc = crown_light_alone("roofs", tables, set, &set->trees.light,
                               set->trees.trees.canopy != NULL);
    if (rc < 0)
        rc = settle_panel_options(set);
    /* What roofs' own stage holds per cell of a window; its shade table
     * sweeps (with the job's bands). */
    band_cost cost = {.cell_bytes = (double)WINDOW_CELL_BYTES,
                      .no_sweep = !set->shade_table,
                      .plans_late = 1,
                      .grid_cell_bytes = run_march_cell_bytes(&set->common)};
    if (rc < 0)
        rc = job_open_banded(&r->job, "roofs", &set->common, pos, n_pos, cost);
    if (rc != 0 || !r->job.run.ctx) {
        free(r);
        return rc;
    }
    roofs_define_fields();
    sweep_job *job = &r->job;
    settle_rack_sun(set, job->frame.centre_lat_deg);
    set->ins.pv = 1;
    ss_status st = check_files(r);
    if (st == SS_OK && job->source)
        st = settle_origin(job);
    double zone_h = NAN;
    char zone_err[160];
    if (st == SS_OK && set->weather_zone &&
        !opt_parse_zone(set->weather_zone, &zone_h, zone_err, sizeof zone_err))
        st = ss_ctx_error(job->run.ctx, SS_ERR_ARGUMENT, "%s", zone_err);
    if (st == SS_OK && !set->weather) {
        st = roofs_write_clear_sky(job, set, r->clear_sky, sizeof r->clear_sky, r->sky_note,
                             sizeof r->sky_note);
        if (*r->clear_sky)
            ss_temporaries_track(job->output); /* the records are among its temporaries */
        set->weather = r->clear_sky;
    } else {
        snprintf(r->sky_note, sizeof r->sky_note, "the weather records of '%s'", set->weather);
    }
    if (st == SS_OK)
        st = ss_weather_read(job->run.ctx, set->weather, zone_h, &r->weather);
    if (st == SS_OK)
        st = roofs_sky_steps(job, set, &r->weather, &r->sky);
    if (st == SS_OK && set->dtm)
        st = open_dtm(r);
    if (st == SS_OK)
        st = ss_footprints_read(job->run.ctx, set->buildings, set->buildings_layer, set->id_field,
                                    &job->dem, &r->fps);
    if (st == SS_OK)
        st = check_windows(r);
    if (st != SS_OK) {
        rc = job_finish(job, st);
        close_run(r);
        free(r);
        return rc;
    }
    double t0 = run_now();
    rc = roofs_run_insolation(job, tables, own_options, argc, argv, *r->clear_sky ? r->clear_sky : NULL,
                        set->cell_raster, r->raster, sizeof r->raster);
    r->seconds_insolation = run_now() - t0;
    /* Under mpirun the processes shared the insolation run's steps, and
     * rank 0 wrote its raster: the roofs' own stage is rank 0's alone. */
    if (rc == 0 && share_rank() > 0) {
        close_run(r);
        free(r);
        return 0;
    }
    if (rc == 0 && !job->run.plan_only)
        rc = set->shade_table || set->shade_masks ? plan_shade_sweeps(r) : -1;
    if (rc < 0) {
        st = find_all(r);
        if (st == SS_OK && set->horizon_dir)
            st = plane_horizon_files(r);
        if (st == SS_OK)
            st = roofs_write_outputs(r);
        rc = job_finish(job, st);
        if (st == SS_OK && !job->run.quiet)
            print_summary(r);
    }
    close_run(r);
    free(r);
    return rc;
}
