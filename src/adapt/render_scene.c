/* A scene's defaults (render.h), in C and without VTK: the command line
 * fills a scene before it loads the render module. */
#include "config.h"

#include <math.h>
#include <string.h>

#include "render.h"

void ss_render_scene_default(ss_render_scene *scene)
{
    memset(scene, 0, sizeof *scene);
    scene->scalar_min = scene->scalar_max = NAN;
    scene->z_factor = NAN;
    scene->view = SS_VIEW_OBLIQUE;
    scene->view_azimuth_deg = 0.0;
    scene->view_elevation_deg = SS_RENDER_OBLIQUE_ELEVATION_DEG;
    scene->distance_factor = 1.0;
    scene->sun_azimuth_deg = 315.0;
    scene->sun_elevation_deg = 45.0;
    scene->image_width = 800;
    scene->image_height = 600;
    scene->background_rgb[0] = scene->background_rgb[1] = scene->background_rgb[2] = 255;
    scene->max_points = 1000000;
}
