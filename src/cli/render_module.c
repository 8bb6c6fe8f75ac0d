/* VTK at run time (modules.h): VTK and the X, OpenGL and codec libraries it
 * links are about a hundred of the shared libraries the program loaded at
 * every start, for the one command that renders. The adapter (render.cpp)
 * is a module, skysweep-render.so, loaded by `render` alone; the functions
 * of render.h the command line uses are defined here and call the
 * module's (a scene's defaults need no VTK: render_scene.c). */
#include "config.h"

#include "modules.h"
#include "render.h"

typedef ss_status (*png_fn)(ss_ctx *, const ss_render_scene *, const char *, ss_render_report *);
typedef ss_status (*vts_fn)(ss_ctx *, const ss_render_scene *, double, double,
                            const char *const *, const float *const *, int, const char *);

static void *module;
static union {
    void *symbols[2];
    struct {
        png_fn png;
        vts_fn vts;
    } fn;
} render;

static ss_status load_module(ss_ctx *ctx)
{
    static const char *const names[2] = {"ss_render_png", "ss_export_vts"};
    return cli_module_load(ctx, "skysweep-render.so", "VTK", names, 2, render.symbols, &module);
}

ss_status ss_render_png(ss_ctx *ctx, const ss_render_scene *scene, const char *png_path,
                        ss_render_report *report)
{
    ss_status st = load_module(ctx);
    return st != SS_OK ? st : render.fn.png(ctx, scene, png_path, report);
}

ss_status ss_export_vts(ss_ctx *ctx, const ss_render_scene *scene, double origin_x, double origin_y,
                        const char *const *field_names, const float *const *fields, int n_fields,
                        const char *path)
{
    ss_status st = load_module(ctx);
    return st != SS_OK ? st
                       : render.fn.vts(ctx, scene, origin_x, origin_y, field_names, fields,
                                       n_fields, path);
}
