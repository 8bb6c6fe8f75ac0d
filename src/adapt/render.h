/* VTK adapter: a DEM as a lit 3D surface, optionally draped with a product or
 * an RGB image, rendered off-screen to PNG; and the DEM with any products
 * exported as a ParaView structured grid (.vts). The only files that include
 * VTK are render.cpp and the tests.
 *
 * Frames: x grows east, y north, z up; rows of the grids run north to south
 * (row 0 is the northern edge), columns west to east. Azimuths are degrees
 * clockwise from north, elevations degrees above the horizontal. */
#ifndef SS_RENDER_H
#define SS_RENDER_H

#include "skysweep.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    SS_VIEW_OBLIQUE = 0, /* perspective, looking toward view_azimuth_deg from 35 deg up */
    SS_VIEW_TOP = 1,     /* orthographic map view, north up (view angles ignored) */
    SS_VIEW_CUSTOM = 2   /* perspective from view_azimuth_deg / view_elevation_deg */
} ss_render_view;

typedef struct {
    /* The DEM: width x height heights in metres relative to z_origin_m (as
     * in ss_grid), NAN = nodata. A surface cell is drawn only where its four
     * corner heights are valid. Renders depend on relative heights only; the
     * .vts export writes z_origin_m + z. */
    int width, height;
    double cell_x_m, cell_y_m;
    double z_origin_m;
    const float *z;

    /* Optional scalar drape on the same grid (NULL = none); SS_NODATA or NaN
     * cells are drawn in neutral grey. min/max NAN = range of the data. */
    const float *scalar;
    const char *scalar_name; /* legend title, e.g. "sky-view factor" */
    const char *scalar_unit; /* e.g. "1", "deg"; NULL or "" for none */
    const char *colormap;    /* colormap.h name; NULL = viridis */
    double scalar_min, scalar_max;

    /* Optional RGB drape (NULL = none): 3 bytes per cell, row-major. At most
     * one of scalar and rgb. Without either the surface is light grey. */
    const unsigned char *rgb;

    /* Vertical exaggeration. NAN = automatic: relief (max - min height)
     * becomes 0.3 of the longer horizontal side, never below 1 (true relief is
     * never flattened) nor above 100; the value used is reported. */
    double z_factor;

    /* Camera: view_azimuth_deg is the direction the camera looks toward
     * (0 = looking north, the camera south of the scene); distance_factor 1
     * fits the whole scene, 2 stands twice as far. */
    ss_render_view view;
    double view_azimuth_deg, view_elevation_deg;
    double distance_factor;

    /* A directional light coming from the sun's direction: with
     * sun_azimuth_deg 90 it comes from the east and lights east-facing slopes.
     * A weaker light from the zenith (0.3) stands in for skylight. Lambert
     * shading of the (exaggerated) surface, no cast shadows. */
    double sun_azimuth_deg, sun_elevation_deg;

    int image_width, image_height; /* pixels */
    unsigned char background_rgb[3];
    const char *title; /* drawn at the top; NULL = none */

    /* Above this many surface points the grid is sampled every k-th row and
     * column (k the smallest integer that fits, last row and column kept);
     * 0 = no limit. */
    long max_points;
} ss_render_scene;

typedef struct {
    int decimation;        /* k: 1 = every cell drawn */
    double z_factor;       /* vertical exaggeration used */
    double render_seconds; /* scene build, render and PNG write */
} ss_render_report;

/* Fills every field with its default: no drapes, automatic z_factor, oblique
 * view looking north, sun from azimuth 315 at 45 deg, 800 x 600 pixels,
 * white background, 1,000,000 points at most, distance factor 1. The grid
 * fields are zeroed and must be set by the caller. */
void ss_render_scene_default(ss_render_scene *scene);
/* The oblique view's elevation above the horizontal, degrees. */
#define SS_RENDER_OBLIQUE_ELEVATION_DEG 35.0

/* Renders the scene off-screen to a PNG (8-bit RGB), written to a temporary
 * name in the same folder and renamed when complete. Needs an X display
 * (Xvfb on a headless machine): without one, SS_ERR_DEVICE. report may be
 * NULL. */
ss_status ss_render_png(ss_ctx *ctx, const ss_render_scene *scene, const char *png_path,
                        ss_render_report *report);

/* Writes the DEM and n_fields float fields (each width x height, same layout
 * as z) as a VTK XML structured grid (.vts, zlib-compressed, points in double
 * precision). origin_x/origin_y are the CRS coordinates (metres) of the centre
 * of cell (0,0); point (i, j) is column i, row height-1-j, at
 * x = origin_x + i*cell_x_m, y = origin_y - (height-1-j)*cell_y_m and
 * z = z_origin_m + its height (never exaggerated), so j grows north and the grid is right-handed.
 * Nodata heights are hidden points (vtkGhostType) placed at the lowest valid
 * height; SS_NODATA and NaN field values are written as NaN, which ParaView
 * shows in its NaN colour. Drapes, camera, light and max_points are ignored:
 * the export is at full resolution. Needs no display. */
ss_status ss_export_vts(ss_ctx *ctx, const ss_render_scene *scene, double origin_x, double origin_y,
                        const char *const *field_names, const float *const *fields, int n_fields,
                        const char *path);

#ifdef __cplusplus
}
#endif
#endif
