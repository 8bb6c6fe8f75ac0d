/* OpenImageIO adapter: plain images in and out (PNG, TIFF, EXR, ...):
 * heightmaps without georeferencing, and quicklook pictures of products.
 * OIIO reads no GeoTIFF tags and no nodata value, so every georeferenced
 * raster goes through GDAL (dem_io.h) instead. The only file that includes
 * OIIO is images.cpp. */
#ifndef SS_IMAGES_H
#define SS_IMAGES_H

#include "skysweep.h"

#ifdef __cplusplus
extern "C" {
#endif

/* An image as stored in its file, without colour or gamma conversion and
 * without premultiplying alpha. Integer samples keep their raw values
 * (0..255 for 8 bits, 0..65535 for 16 bits, -32768..32767 for signed 16
 * bits); floating-point samples keep theirs. */
typedef struct {
    int width, height, channels;
    int bits;          /* bits per sample in the file: 8, 16, 32 or 64 */
    int is_float;      /* 1 for half, float or double samples */
    int alpha_channel; /* index of the alpha channel, -1 if none */
    float *pixels;     /* width*height*channels, top row first, channels interleaved */
} ss_image;

/* Reads the first subimage of any format OIIO knows. 8- and 16-bit integer
 * and half/float/double samples are accepted; 32-bit integers (which float
 * cannot hold exactly) are refused. */
ss_status ss_image_read(ss_ctx *ctx, const char *path, ss_image *out);
void ss_image_free(ss_image *image);

/* Reads a heightmap into a grid of cell_m x cell_m cells, row 0 the top row
 * of the image. height = pixel value * z_scale + z_offset, where the pixel
 * value is the raw sample: an 8- or 16-bit integer (0..255, 0..65535; not
 * normalised to 0..1) or the float of an EXR or float TIFF. z_offset is kept
 * as the grid's z_origin_m and z holds pixel * z_scale, so large offsets cost
 * no float precision. Single-channel images are read as they are; images
 * with colour channels are accepted only when grey (R = G = B at every
 * pixel), else refused with a message; an alpha channel marks cells whose
 * alpha is 0 as nodata. */
ss_status ss_image_read_heightmap(ss_ctx *ctx, const char *path, double cell_m, double z_scale,
                                  double z_offset, ss_grid *out);

/* Writes a quicklook PNG of a product (width x height values, row 0 at the
 * top), t = (value - vmin) / (vmax - vmin) clamped to [0, 1]; vmin or vmax
 * NAN takes the data's own minimum or maximum, and vmin > vmax reverses the
 * stretch. bits 8: RGB through the colour map (NULL = grey); bits 16: grey
 * 0..65535 (colormap NULL or "grey"). alpha_for_nodata adds an alpha channel
 * that is 0 exactly at SS_NODATA or NaN cells and fully opaque elsewhere;
 * without it nodata cells are black. The stretch and map are recorded in the
 * PNG's description. Written to a temporary name and renamed when complete. */
ss_status ss_image_write_quicklook(ss_ctx *ctx, const char *png_path, const float *values,
                                   int width, int height, double vmin, double vmax,
                                   const char *colormap, int bits, int alpha_for_nodata);

#ifdef __cplusplus
}
#endif
#endif
