/* skysweep render: the DEM as a shaded 3D surface in a PNG (VTK, drawn
 * off-screen on an X display), optionally draped with a product on the
 * same grid and lit by the sun of skysweep shadow, so the cast shadows in
 * a draped shadow product line up with the shading; and the surface with
 * every band of the drape as a ParaView structured grid (.vts). */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "band_read.h"
#include "colormap.h"
#include "commands.h"
#include "run.h"
#include "temporaries.h"
#include "sun_field.h"
#ifdef HAVE_VTK
#include "render.h"
#endif

typedef struct {
    common_settings common; /* first: common_options()' offsets are relative to it */
    const char *drape;
    int drape_band;
    int rgb;
    const char *colormap;
    double min, max;
    const char *legend, *unit;
    double z_factor;
    int view; /* index into "oblique|top" */
    double camera_azimuth_deg, camera_elevation_deg, distance;
    const char *size, *background, *title;
    int max_points;
    const char *export_path;
} render_settings;

#define SET(field) offsetof(render_settings, field)
static const opt_spec render_options[] = {
    {"drape", OPT_INPUT, SET(drape), "FILE", NULL, 0, 0, NULL,
     "colour the surface by a raster on the DEM's grid (any skysweep product)"},
    {"drape-band", OPT_INT, SET(drape_band), "N", "1", 1, 65535, NULL,
     "band of the drape to show (with --rgb the first of three)"},
    {"rgb", OPT_FLAG, SET(rgb), NULL, NULL, 0, 0, NULL,
     "the drape is an RGB image: bands N, N+1, N+2 hold red, green, blue 0..255"},
    {"colormap", OPT_STRING, SET(colormap), "NAME", "viridis", 0, 0, NULL,
     "colour map of the drape: " SS_COLORMAP_NAMES},
    {"min", OPT_DOUBLE, SET(min), "VALUE", NULL, -1e30, 1e30, NULL,
     "drape value at the start of the map (default: the band's minimum)"},
    {"max", OPT_DOUBLE, SET(max), "VALUE", NULL, -1e30, 1e30, NULL,
     "drape value at the end of the map (default: the band's maximum)"},
    {"legend", OPT_STRING, SET(legend), "TEXT", NULL, 0, 0, NULL,
     "title of the colour bar (default: the band's description)"},
    {"unit", OPT_STRING, SET(unit), "TEXT", NULL, 0, 0, NULL,
     "unit shown in the colour bar (default: the band's unit)"},
    {"z-factor", OPT_DOUBLE, SET(z_factor), "FACTOR", NULL, 1e-3, 1e4, NULL,
     "vertical exaggeration (default: relief becomes 0.3 of the longer side, 1 to 100)"},
    {"view", OPT_CHOICE, SET(view), NULL, "oblique", 0, 0, "oblique|top",
     "oblique: perspective from --camera-elevation (35 deg); top: map view, north up"},
    {"camera-azimuth", OPT_DOUBLE, SET(camera_azimuth_deg), "DEG", "0", -360, 360, NULL,
     "direction the camera looks toward, clockwise from the raster's top (0: looking north)"},
    {"camera-elevation", OPT_DOUBLE, SET(camera_elevation_deg), "DEG", NULL, 1, 90, NULL,
     "camera height above the horizon, degrees (oblique view; default 35)"},
    {"distance", OPT_DOUBLE, SET(distance), "FACTOR", "1", 0.1, 100, NULL,
     "camera distance: 1 fits the scene, 2 stands twice as far"},
    {"size", OPT_STRING, SET(size), "WxH", "800x600", 0, 0, NULL, "image size in pixels"},
    {"background", OPT_STRING, SET(background), "R,G,B", "255,255,255", 0, 0, NULL,
     "background colour, 0..255 each"},
    {"title", OPT_STRING, SET(title), "TEXT", NULL, 0, 0, NULL, "title at the top"},
    {"max-points", OPT_INT, SET(max_points), "N", "1000000", 0, 2147483647, NULL,
     "above this many surface points every k-th row and column is drawn (0: all)"},
    {"export", OPT_OUTPUT, SET(export_path), "FILE.vts", NULL, 0, 0, NULL,
     "also write the surface (full resolution, true heights, CRS coordinates) with every band "
     "of the drape as point data, for ParaView"},
    OPT_END};

#ifdef HAVE_VTK
/* The image size, background and camera into the scene; returns 0 or the
 * exit code of a usage error. */
static int look_of(const render_settings *set, ss_render_scene *scene)
{
    char tail;
    int r, g, b;
    if (sscanf(set->size, "%dx%d%c", &scene->image_width, &scene->image_height, &tail) != 2)
        return run_usage_error("render", "--size expects WIDTHxHEIGHT in pixels, e.g. 800x600");
    if (sscanf(set->background, "%d,%d,%d%c", &r, &g, &b, &tail) != 3 || r < 0 || r > 255 ||
        g < 0 || g > 255 || b < 0 || b > 255)
        return run_usage_error("render", "--background expects R,G,B from 0 to 255, e.g. "
                                         "255,255,255");
    if (!ss_colormap_known(set->colormap)) {
        char err[200];
        snprintf(err, sizeof err, "unknown colour map '%s' (known: %s)", set->colormap,
                 SS_COLORMAP_NAMES);
        return run_usage_error("render", err);
    }
    if (set->view == 1 && isfinite(set->camera_elevation_deg))
        return run_usage_error("render", "--camera-elevation is for the oblique view; the top "
                                         "view looks straight down");
    size_t len = set->export_path ? strlen(set->export_path) : 0;
    if (set->export_path && (len < 5 || strcmp(set->export_path + len - 4, ".vts") != 0))
        return run_usage_error("render", "--export writes a VTK structured grid: give a name "
                                         "ending in .vts");
    scene->background_rgb[0] = (unsigned char)r;
    scene->background_rgb[1] = (unsigned char)g;
    scene->background_rgb[2] = (unsigned char)b;
    scene->view = set->view == 1                        ? SS_VIEW_TOP
                  : isfinite(set->camera_elevation_deg) ? SS_VIEW_CUSTOM
                                                        : SS_VIEW_OBLIQUE;
    scene->view_azimuth_deg = set->camera_azimuth_deg;
    scene->view_elevation_deg = set->camera_elevation_deg;
    scene->distance_factor = set->distance;
    scene->title = set->title;
    scene->max_points = set->max_points;
    scene->z_factor = set->z_factor;
    return 0;
}

/* Each output must be writable where it is named (run_check_output; that
 * neither replaces an input or the other, run_parse has checked). */
static ss_status check_outputs(sweep_job *job, const render_settings *set)
{
    ss_status st = run_check_output(&job->run, job->output);
    return st != SS_OK || !set->export_path ? st : run_check_output(&job->run, set->export_path);
}

/* The drape must lie on the DEM's grid: same size, and origins and cell
 * sizes within a millionth of a cell. */
static ss_status check_drape_grid(sweep_job *job, const char *path, const ss_bands *d)
{
    const double *a = job->dem.geotransform, *b = d->geotransform;
    int same = d->width == job->dem.grid.width && d->height == job->dem.grid.height;
    for (int i = 0; i < 6; ++i)
        same = same && fabs(a[i] - b[i]) <= 1e-6 * fabs(a[1]);
    if (same)
        return SS_OK;
    return ss_ctx_error(job->run.ctx, SS_ERR_INPUT,
                        "the drape '%s' (%d x %d cells of %g x %g from %.10g, %.10g) is not on "
                        "the DEM's grid (%d x %d cells of %g x %g from %.10g, %.10g): warp it "
                        "onto the DEM's grid first",
                        path, d->width, d->height, b[1], -b[5], b[0], b[3], job->dem.grid.width,
                        job->dem.grid.height, a[1], -a[5], a[0], a[3]);
}

/* Bands k..k+2 of the drape as RGB bytes; nodata is drawn mid-grey. */
static unsigned char *rgb_of(const ss_bands *d, int k)
{
    size_t n = (size_t)d->width * (size_t)d->height;
    unsigned char *rgb = malloc(3 * n);
    for (size_t i = 0; rgb && i < n; ++i)
        for (int c = 0; c < 3; ++c) {
            float v = d->values[k + c][i];
            v = v == SS_NODATA ? 128.0f : v < 0.0f ? 0.0f : v > 255.0f ? 255.0f : v;
            rgb[3 * i + c] = (unsigned char)lrintf(v);
        }
    return rgb;
}

/* Writes the .vts: true heights as a field too (ParaView colours by point
 * data, not by coordinates), then every band of the drape. Coordinates
 * are the CRS's for a projected DEM; a geographic DEM gets a local frame
 * in metres, which `frame` describes for the summary. */
static ss_status export_vts(sweep_job *job, const ss_render_scene *scene, const ss_bands *d,
                            const char *path, char *frame, size_t frame_size)
{
    const ss_grid *g = &job->dem.grid;
    const double *gt = job->dem.geotransform;
    ss_render_scene ex = *scene;
    double x0, y0;
    if (job->frame.georeferenced && !job->frame.geographic) {
        /* CRS units, so the grid lines up with other data in that CRS. */
        ex.cell_x_m = gt[1];
        ex.cell_y_m = -gt[5];
        x0 = gt[0] + 0.5 * gt[1];
        y0 = gt[3] + 0.5 * gt[5];
        snprintf(frame, frame_size, "the DEM's CRS (cell (0,0) centred at %.3f, %.3f)", x0, y0);
    } else if (job->frame.georeferenced) {
        /* A lat/lon grid has no metres of its own: east and north metres
         * from the grid's centre, at the geodesic cell sizes there. */
        x0 = -0.5 * (g->width - 1) * g->cell_x_m;
        y0 = 0.5 * (g->height - 1) * g->cell_y_m;
        snprintf(frame, frame_size,
                 "local metres east and north of the grid's centre (%.6f, %.6f lon, lat), "
                 "cells %.4f x %.4f m as there (they vary by %.2g over the grid)",
                 job->frame.centre_lon_deg, job->frame.centre_lat_deg, g->cell_x_m, g->cell_y_m,
                 job->frame.cell_variation);
    } else {
        x0 = 0.0;
        y0 = (g->height - 1) * g->cell_y_m;
        snprintf(frame, frame_size, "no CRS: metres, the south-west cell centred at 0, 0");
    }
    int n_fields = 1 + d->n_bands;
    size_t n = (size_t)g->width * (size_t)g->height;
    char(*names)[300] = calloc((size_t)n_fields, sizeof *names);
    const char **name_of = calloc((size_t)n_fields, sizeof *name_of);
    const float **field_of = calloc((size_t)n_fields, sizeof *field_of);
    float *height = malloc(n * sizeof *height);
    if (!names || !name_of || !field_of || !height) {
        free(names);
        free(name_of);
        free(field_of);
        free(height);
        return ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory exporting '%s'", path);
    }
    for (size_t i = 0; i < n; ++i)
        height[i] = (float)(g->z_origin_m + g->z[i]);
    snprintf(names[0], sizeof names[0], "height [m]");
    field_of[0] = height;
    for (int k = 0; k < d->n_bands; ++k) {
        snprintf(names[k + 1], sizeof names[0], *d->units[k] ? "%s [%s]" : "%s", d->names[k],
                 d->units[k]);
        /* ParaView finds arrays by name: repeated descriptions get the band. */
        for (int j = 0; j <= k; ++j)
            if (strcmp(names[j], names[k + 1]) == 0) {
                size_t len = strlen(names[k + 1]);
                snprintf(names[k + 1] + len, sizeof names[0] - len, " (band %d)",
                         d->first_band + k);
                break;
            }
        field_of[k + 1] = d->values[k];
    }
    for (int f = 0; f < n_fields; ++f)
        name_of[f] = names[f];
    ss_status st = ss_export_vts(job->run.ctx, &ex, x0, y0, name_of, field_of, n_fields, path);
    free(names);
    free(name_of);
    free(field_of);
    free(height);
    return st;
}

static int render_job(const render_settings *set, const char **pos, int n_pos)
{
    ss_render_scene scene;
    ss_render_scene_default(&scene);
    int rc = look_of(set, &scene);
    if (rc)
        return rc;
    sweep_job job;
    if ((rc = job_open(&job, "render", &set->common, pos, n_pos)))
        return rc;
    ss_status clash = check_outputs(&job, set);
    if (clash != SS_OK) {
        rc = run_fail(&job.run, clash);
        job_close(&job);
        return rc;
    }
    ss_ctx *ctx = job.run.ctx;
    const ss_grid *g = &job.dem.grid;
    ss_bands drape = {0};
    unsigned char *rgb = NULL;
    ss_status st = SS_OK;
    /* Only the bands shown, unless the export wants them all (0: to the last). */
    int shown = set->rgb ? 3 : 1;
    if (set->drape)
        st = ss_bands_read(ctx, set->drape, set->export_path ? 1 : set->drape_band,
                           set->export_path ? 0 : shown, &drape);
    int k = set->drape_band - drape.first_band;
    if (st == SS_OK && set->drape)
        st = check_drape_grid(&job, set->drape, &drape);
    if (st == SS_OK && set->drape && k + shown > drape.n_bands)
        st = ss_ctx_error(ctx, SS_ERR_ARGUMENT, "'%s' has %d band%s: no band %d%s", set->drape,
                          drape.file_bands, drape.file_bands == 1 ? "" : "s",
                          set->drape_band + shown - 1,
                          set->rgb ? " for blue (--rgb takes three)" : "");
    if (st == SS_OK && set->drape && set->rgb) {
        rgb = rgb_of(&drape, k);
        st = rgb ? SS_OK : ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory");
    }
    scene.width = g->width;
    scene.height = g->height;
    scene.cell_x_m = g->cell_x_m;
    scene.cell_y_m = g->cell_y_m;
    scene.z_origin_m = g->z_origin_m;
    scene.z = g->z;
    scene.rgb = rgb;
    if (st == SS_OK && set->drape && !set->rgb) {
        scene.scalar = drape.values[k];
        scene.scalar_name = set->legend ? set->legend : drape.names[k];
        scene.scalar_unit = set->unit ? set->unit : drape.units[k];
        scene.colormap = set->colormap;
        scene.scalar_min = set->min;
        scene.scalar_max = set->max;
    }

    /* The light: the sun skysweep shadow would use (at the DEM's centre,
     * where the shadow sweep takes its azimuth), else the cartographer's
     * north-west light. One light serves the scene: without a plan,
     * job_sun computes the centre's sun only. */
    int sun_given = set->common.sun.time || isfinite(set->common.sun.sun_azimuth_deg) ||
                    isfinite(set->common.sun.sun_elevation_deg);
    ss_sun_field sun;
    int have_sun = 0;
    if (st == SS_OK && sun_given) {
        st = job_sun(&job, &set->common, &sun);
        have_sun = st == SS_OK;
    }
    if (have_sun) {
        scene.sun_azimuth_deg = sun.centre_grid_azimuth_deg;
        scene.sun_elevation_deg = sun.centre.apparent_elevation_deg;
        if (scene.sun_elevation_deg <= 0 && !job.run.quiet)
            fprintf(stderr,
                    "skysweep render: warning: the sun is %.2f deg below the horizon: only the "
                    "sky light falls on the surface\n",
                    -scene.sun_elevation_deg);
    }
    ss_render_report report;
    /* The module names its temporaries as the raster writer does. */
    ss_temporaries_track(job.output);
    if (set->export_path)
        ss_temporaries_track(set->export_path);
    if (st == SS_OK)
        st = ss_render_png(ctx, &scene, job.output, &report);
    char frame[400] = "";
    if (st == SS_OK && set->export_path)
        st = export_vts(&job, &scene, &drape, set->export_path, frame, sizeof frame);
    ss_temporaries_forget(job.output);
    if (set->export_path)
        ss_temporaries_forget(set->export_path);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        if (have_sun)
            printf("light   the sun at azimuth %.4f deg, apparent elevation %.4f deg (as "
                   "skysweep shadow%s%s)\n",
                   sun.centre_grid_azimuth_deg + job.opt.grid_north_deg,
                   sun.centre.apparent_elevation_deg, set->common.sun.time ? " at " : "",
                   set->common.sun.time ? set->common.sun.time : "");
        else
            printf("light   azimuth %g deg from the raster's top, elevation %g deg (default; "
                   "give --time or --sun-azimuth/--sun-elevation for the sun)\n",
                   scene.sun_azimuth_deg, scene.sun_elevation_deg);
        if (set->drape && set->rgb)
            printf("drape   bands %d-%d of %s as RGB\n", set->drape_band, set->drape_band + 2,
                   set->drape);
        else if (set->drape)
            printf("drape   band %d of %s: %s, %s map\n", set->drape_band, set->drape,
                   scene.scalar_name, set->colormap);
        printf("render  %d x %d px, z factor %.3g, ", scene.image_width, scene.image_height,
               report.z_factor);
        if (report.decimation > 1)
            printf("decimated: one row and column in %d drawn (--max-points %d)", report.decimation,
                   set->max_points);
        else
            printf("every cell drawn");
        printf(", %.2f s -> %s\n", report.render_seconds, job.output);
        if (set->export_path && set->drape)
            printf("export  height and %d band%s of the drape in %s -> %s\n", drape.n_bands,
                   drape.n_bands == 1 ? "" : "s", frame, set->export_path);
        else if (set->export_path)
            printf("export  height in %s -> %s\n", frame, set->export_path);
    }
    if (have_sun)
        ss_sun_field_free(&sun);
    free(rgb);
    ss_bands_free(&drape);
    job_close(&job);
    return rc;
}
#endif

int cmd_render(int argc, char **argv)
{
    render_settings set = {0};
    common_settings_init(&set.common);
    set.min = NAN;
    set.max = NAN;
    set.z_factor = NAN;
    set.camera_elevation_deg = NAN;
    const opt_spec *tables[] = {render_options, sun_options(), common_options(), NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("render", tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 2,
                       "skysweep render [options] DEM... OUTPUT.png",
                       "The DEM as a shaded 3D surface (VTK), optionally draped with a product on "
                       "its grid, lit by the\nsun skysweep shadow uses (--time or "
                       "--sun-azimuth/--sun-elevation). Needs an X display:\non a headless "
                       "machine run it as xvfb-run -a skysweep render ...",
                       &set.common.device);
    if (rc >= 0)
        return rc;
#ifndef HAVE_VTK
    fprintf(stderr, "skysweep render: skysweep was built without VTK: 3D rendering is "
                    "unavailable (install libvtk9-dev and rebuild)\n");
    return SS_ERR_DEVICE;
#else
    return render_job(&set, pos, n_pos);
#endif
}
