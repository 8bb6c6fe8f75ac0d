/* OpenImageIO 2.4 adapter behind images.h. Samples are read in their own
 * integer type and converted here, because OIIO's conversion to float
 * normalises integers to 0..1 and heightmaps need the raw values. */
#include "config.h"

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include "colormap.h"
#include "temporary_name.h"
extern "C" {
#include "skysweep.h"
}
#include "images.h"

using OIIO::ImageInput;
using OIIO::ImageOutput;
using OIIO::ImageSpec;
using OIIO::TypeDesc;

/* One line of at most a few hundred characters for ss_fail. */
static std::string one_line(std::string text)
{
    for (char &c : text)
        if (c == '\n' || c == '\r')
            c = ' ';
    return text.size() > 400 ? text.substr(0, 400) : text;
}

/* Standard error sent to /dev/null while it lives: libpng (under OIIO
 * 2.4) prints "libpng error: ..." itself before OIIO reports the same
 * error, which the caller then gives as its one line. */
class quiet_stderr
{
  public:
    quiet_stderr() : saved(dup(2))
    {
        int null = open("/dev/null", O_WRONLY | O_CLOEXEC);
        if (saved >= 0 && null >= 0)
            dup2(null, 2);
        if (null >= 0)
            close(null);
    }
    ~quiet_stderr()
    {
        if (saved >= 0) {
            dup2(saved, 2);
            close(saved);
        }
    }
    quiet_stderr(const quiet_stderr &) = delete;
    quiet_stderr &operator=(const quiet_stderr &) = delete;

  private:
    int saved;
};

template <class T>
static bool read_raw(ImageInput &in, const ImageSpec &spec, TypeDesc type, float *dst)
{
    std::vector<T> buf((size_t)spec.width * spec.height * spec.nchannels);
    if (!in.read_image(0, 0, 0, spec.nchannels, type, buf.data()))
        return false;
    for (size_t i = 0; i < buf.size(); ++i)
        dst[i] = (float)buf[i];
    return true;
}

static ss_status read_image(ss_ctx *ctx, const char *path, ss_image *out)
{
    /* Keep alpha as stored: OIIO would otherwise premultiply the colour
     * channels, changing the heights of half-transparent pixels. */
    ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    quiet_stderr quiet;
    auto in = ImageInput::open(path, &config);
    if (!in)
        return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot open image '%s': %s", path,
                       one_line(OIIO::geterror()).c_str());
    const ImageSpec &spec = in->spec();
    if (spec.depth > 1)
        return ss_ctx_error(ctx, SS_ERR_INPUT, "'%s' is a volume image (%d slices), not a picture", path,
                       spec.depth);
    for (const TypeDesc &t : spec.channelformats)
        if (t != spec.format)
            return ss_ctx_error(ctx, SS_ERR_INPUT,
                           "'%s' mixes sample types across channels; save it with one type", path);
    if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1 ||
        (double)spec.width * spec.height * spec.nchannels > 4e9)
        return ss_ctx_error(ctx, SS_ERR_INPUT, "'%s' has an unusable size (%d x %d x %d channels)", path,
                       spec.width, spec.height, spec.nchannels);
    size_t n = (size_t)spec.width * spec.height * spec.nchannels;
    float *pixels = (float *)std::malloc(n * sizeof(float));
    if (!pixels)
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "cannot allocate %zu MB for '%s'",
                       n * sizeof(float) >> 20, path);
    bool ok;
    int is_float = 0;
    switch (spec.format.basetype) {
    case TypeDesc::UINT8: ok = read_raw<uint8_t>(*in, spec, TypeDesc::UINT8, pixels); break;
    case TypeDesc::UINT16: ok = read_raw<uint16_t>(*in, spec, TypeDesc::UINT16, pixels); break;
    case TypeDesc::INT16: ok = read_raw<int16_t>(*in, spec, TypeDesc::INT16, pixels); break;
    case TypeDesc::HALF:
    case TypeDesc::FLOAT:
    case TypeDesc::DOUBLE:
        is_float = 1;
        ok = in->read_image(0, 0, 0, spec.nchannels, TypeDesc::FLOAT, pixels);
        break;
    default:
        std::free(pixels);
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                       "'%s' stores %s samples; heightmaps and pictures must be 8- or 16-bit "
                       "integers or floating point (read other rasters through GDAL)",
                       path, spec.format.c_str());
    }
    /* A truncated TIFF reads "successfully" with its missing strips as
     * zeros, the error only recorded. */
    if (!ok || in->has_error()) {
        std::free(pixels);
        return ss_ctx_error(ctx, SS_ERR_INPUT, "cannot read the pixels of '%s': %s", path,
                       one_line(in->geterror()).c_str());
    }
    out->width = spec.width;
    out->height = spec.height;
    out->channels = spec.nchannels;
    out->bits = spec.get_int_attribute("oiio:BitsPerSample", (int)spec.format.size() * 8);
    out->is_float = is_float;
    out->alpha_channel = spec.alpha_channel;
    out->pixels = pixels;
    return SS_OK;
}

extern "C" ss_status ss_image_read(ss_ctx *ctx, const char *path, ss_image *out)
{
    *out = ss_image{};
    out->alpha_channel = -1;
    if (!path || !*path)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "no image path given");
    try {
        return read_image(ctx, path, out);
    } catch (const std::bad_alloc &) {
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory reading '%s'", path);
    } catch (const std::exception &e) {
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "reading '%s' failed: %s", path, e.what());
    } catch (...) {
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "reading '%s' failed (unknown C++ exception)", path);
    }
}

extern "C" void ss_image_free(ss_image *image)
{
    if (image) {
        std::free(image->pixels);
        image->pixels = nullptr;
    }
}

/* Which channel holds the height, or -1 after failing with a message. */
static int height_channel(ss_ctx *ctx, const char *path, const ss_image *img)
{
    int colour = img->channels - (img->alpha_channel >= 0 ? 1 : 0);
    if (colour == 1)
        return img->alpha_channel == 0 ? 1 : 0;
    if (colour != 3 || (img->alpha_channel >= 0 && img->alpha_channel != 3)) {
        ss_ctx_error(ctx, SS_ERR_INPUT,
                "'%s' has %d channels: a heightmap needs one (grey), grey + alpha, or RGB(A) "
                "with R = G = B",
                path, img->channels);
        return -1;
    }
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; ++i) {
        const float *p = &img->pixels[i * img->channels];
        if (p[0] != p[1] || p[0] != p[2]) {
            ss_ctx_error(ctx, SS_ERR_INPUT,
                    "'%s' is a colour image (R, G, B = %g, %g, %g at column %zu, row %zu): a "
                    "heightmap must be single-channel or grey (R = G = B)",
                    path, (double)p[0], (double)p[1], (double)p[2], i % (size_t)img->width,
                    i / (size_t)img->width);
            return -1;
        }
    }
    return 0;
}

extern "C" ss_status ss_image_read_heightmap(ss_ctx *ctx, const char *path, double cell_m,
                                             double z_scale, double z_offset, ss_grid *out)
{
    out->z = nullptr;
    if (!(cell_m > 0 && std::isfinite(cell_m)))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "heightmap cell size %g m must be positive", cell_m);
    if (!(std::isfinite(z_scale) && z_scale != 0 && std::isfinite(z_offset)))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "height scale %g and offset %g must be finite, the scale nonzero", z_scale,
                       z_offset);
    ss_image img;
    ss_status st = ss_image_read(ctx, path, &img);
    if (st != SS_OK)
        return st;
    int channel = height_channel(ctx, path, &img);
    if (channel < 0) {
        ss_image_free(&img);
        return SS_ERR_INPUT;
    }
    st = ss_grid_alloc(ctx, out, img.width, img.height, cell_m, cell_m);
    if (st != SS_OK) {
        ss_image_free(&img);
        return st;
    }
    out->z_origin_m = z_offset;
    size_t n = (size_t)img.width * img.height;
    for (size_t i = 0; i < n; ++i) {
        const float *p = &img.pixels[i * img.channels];
        bool transparent = img.alpha_channel >= 0 && p[img.alpha_channel] == 0.0f;
        if (!transparent && std::isfinite(p[channel]))
            out->z[i] = (float)(p[channel] * z_scale);
    }
    ss_image_free(&img);
    return SS_OK;
}

static bool nodata(float v)
{
    return !std::isfinite(v) || v == SS_NODATA;
}

static ss_status write_quicklook(ss_ctx *ctx, const char *png_path, const float *values, int w,
                                 int h, double vmin, double vmax, const char *colormap, int bits,
                                 bool alpha)
{
    size_t n = (size_t)w * h;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n; ++i)
        if (!nodata(values[i])) {
            lo = values[i] < lo ? values[i] : lo;
            hi = values[i] > hi ? values[i] : hi;
        }
    if (std::isnan(vmin))
        vmin = lo;
    if (std::isnan(vmax))
        vmax = hi;
    /* All nodata, or a constant product: every valid cell at mid-range. */
    double span = std::isfinite(vmax - vmin) ? vmax - vmin : 0.0;

    const char *map = colormap ? colormap : "grey";
    int colours = bits == 8 ? 3 : 1, nch = colours + (alpha ? 1 : 0);
    ImageSpec spec(w, h, nch, bits == 8 ? TypeDesc::UINT8 : TypeDesc::UINT16);
    spec.alpha_channel = alpha ? nch - 1 : -1;
    spec.attribute("oiio:UnassociatedAlpha", 1);
    char description[300];
    std::snprintf(description, sizeof description,
                  "skysweep quicklook: %s map, %.9g..%.9g stretched to 0..%d%s", map, vmin, vmax,
                  bits == 8 ? 255 : 65535, alpha ? ", alpha 0 at nodata" : ", nodata black");
    spec.attribute("ImageDescription", description);

    std::vector<uint8_t> px8(bits == 8 ? n * nch : 0);
    std::vector<uint16_t> px16(bits == 16 ? n * nch : 0);
    for (size_t i = 0; i < n; ++i) {
        float v = values[i];
        bool valid = !nodata(v);
        double t = span != 0.0 ? (v - vmin) / span : 0.5;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        if (bits == 8) {
            unsigned char rgb[3] = {0, 0, 0};
            if (valid)
                ss_colormap_rgb(map, t, rgb);
            for (int c = 0; c < 3; ++c)
                px8[i * nch + c] = rgb[c];
            if (alpha)
                px8[i * nch + 3] = valid ? 255 : 0;
        } else {
            px16[i * nch] = valid ? (uint16_t)std::lround(t * 65535.0) : 0;
            if (alpha)
                px16[i * nch + 1] = valid ? 65535 : 0;
        }
    }

    auto out = ImageOutput::create("png");
    if (!out)
        return ss_ctx_error(ctx, SS_ERR_OUTPUT, "OpenImageIO cannot write PNG: %s",
                       one_line(OIIO::geterror()).c_str());
    std::string tmp = ss_temporary_name_cxx(png_path);
    const void *data = bits == 8 ? (const void *)px8.data() : (const void *)px16.data();
    bool ok = out->open(tmp, spec) && out->write_image(spec.format, data);
    ok = out->close() && ok;
    if (!ok) {
        std::string why = one_line(out->geterror());
        std::remove(tmp.c_str());
        return ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s': %s", png_path, why.c_str());
    }
    if (ss_output_rename(tmp.c_str(), png_path) != 0) {
        std::remove(tmp.c_str());
        return ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot rename the finished file to '%s'", png_path);
    }
    return SS_OK;
}

extern "C" ss_status ss_image_write_quicklook(ss_ctx *ctx, const char *png_path,
                                              const float *values, int width, int height,
                                              double vmin, double vmax, const char *colormap,
                                              int bits, int alpha_for_nodata)
{
    if (!png_path || !*png_path || !values)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "quicklook needs a path and values");
    if (width < 1 || height < 1 || (double)width * height > 1e9)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "quicklook size %d x %d is not usable", width, height);
    if (bits != 8 && bits != 16)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "quicklook bit depth %d must be 8 or 16", bits);
    if (colormap && !ss_colormap_known(colormap))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "unknown colour map '%s' (known: %s)", colormap,
                       SS_COLORMAP_NAMES);
    if (bits == 16 && colormap && std::string(colormap) != "grey")
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "16-bit quicklooks are grey; colour map '%s' needs bits 8", colormap);
    if (std::isinf(vmin) || std::isinf(vmax))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "quicklook range must be finite (NaN = automatic)");
    try {
        return write_quicklook(ctx, png_path, values, width, height, vmin, vmax, colormap, bits,
                               alpha_for_nodata != 0);
    } catch (const std::bad_alloc &) {
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory writing '%s'", png_path);
    } catch (const std::exception &e) {
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "writing '%s' failed: %s", png_path, e.what());
    } catch (...) {
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "writing '%s' failed (unknown C++ exception)",
                       png_path);
    }
}
