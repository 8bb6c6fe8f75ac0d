/* OpenImageIO at run time (modules.h). Loading OIIO and the codecs it
 * links (OpenEXR, OpenVDB, FFmpeg, ...) costs about 0.3 s at every start of
 * the program, more than a whole SVF of a small DEM, so the adapter
 * (images.cpp) is a module, skysweep-images.so, loaded only by the commands
 * that read or write plain images (--heightmap, quicklook). The two
 * functions of images.h the command line uses are defined here: they load
 * the module on first use and call its own. */
#include "config.h"

#include "images.h"
#include "modules.h"

typedef ss_status (*heightmap_fn)(ss_ctx *, const char *, double, double, double, ss_grid *);
typedef ss_status (*quicklook_fn)(ss_ctx *, const char *, const float *, int, int, double,
                                  double, const char *, int, int);

static void *module;
static union {
    void *symbols[2];
    struct {
        heightmap_fn heightmap;
        quicklook_fn quicklook;
    } fn;
} images;

static ss_status load_module(ss_ctx *ctx)
{
    static const char *const names[2] = {"ss_image_read_heightmap", "ss_image_write_quicklook"};
    return cli_module_load(ctx, "skysweep-images.so", "OpenImageIO", names, 2, images.symbols,
                           &module);
}

ss_status ss_image_read_heightmap(ss_ctx *ctx, const char *path, double cell_m, double z_scale,
                                  double z_offset, ss_grid *out)
{
    ss_status st = load_module(ctx);
    return st != SS_OK ? st : images.fn.heightmap(ctx, path, cell_m, z_scale, z_offset, out);
}

ss_status ss_image_write_quicklook(ss_ctx *ctx, const char *png_path, const float *values,
                                   int width, int height, double vmin, double vmax,
                                   const char *colormap, int bits, int alpha_for_nodata)
{
    ss_status st = load_module(ctx);
    return st != SS_OK ? st
                       : images.fn.quicklook(ctx, png_path, values, width, height, vmin, vmax,
                                             colormap, bits, alpha_for_nodata);
}
