/* VTK 9.1 adapter behind render.h. Debian's VTK is built for X/GLX only, so
 * off-screen rendering still needs an X server (Xvfb); when VTK cannot reach
 * one it calls abort(), hence the adapter opens the display itself and hands
 * the connection to VTK. VTK's messages are collected for the length of a
 * call and become the context's message instead of reaching stderr. */
#include "config.h"

/* The one translation unit that registers VTK's factory overrides: without
 * them vtkRenderWindow::New() returns NULL. FreeType draws the legend and
 * title text. */
#include <chrono>

#include <vtkAutoInit.h>
VTK_MODULE_INIT(vtkRenderingOpenGL2);
VTK_MODULE_INIT(vtkRenderingFreeType);

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkLight.h>
#include <vtkLogger.h>
#include <vtkLookupTable.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkStructuredGrid.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>
#include <vtkXMLStructuredGridWriter.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <time.h>
#include <unistd.h>

/* After VTK: Xlib's macros (Status, None, Bool) would clash with its headers. */
#include <X11/Xlib.h>

#include "colormap.h"
#include "temporary_name.h"
extern "C" {
#include "skysweep.h"
}
#include "render.h"

template <class T> using vtk_ptr = vtkSmartPointer<T>;
template <class T> static vtk_ptr<T> make()
{
    return vtk_ptr<T>::New();
}

static const double deg = M_PI / 180.0;
/* Automatic exaggeration: relief becomes this fraction of the longer side. */
static const double auto_relief_fraction = 0.3;
static const double auto_z_factor_max = 100.0;
/* The oblique view's camera elevation, steep enough to see into valleys. */
static const double oblique_elevation_deg = SS_RENDER_OBLIQUE_ELEVATION_DEG;
/* Zenith skylight relative to the sun (intensity 1). */
static const double sky_intensity = 0.3;
/* Window fractions left to the legend (right) and the title (top). */
static const double legend_left = 0.84;
static const double title_bottom = 0.92;

/* Collects VTK's messages one by one instead of printing them. */
class vtk_message_sink : public vtkOutputWindow
{
  public:
    static vtk_message_sink *New();
    vtkTypeMacro(vtk_message_sink, vtkOutputWindow);
    void DisplayText(const char *text) override
    {
        if (text && messages.size() < 20)
            messages.emplace_back(text);
    }
    std::vector<std::string> messages;
};
vtkStandardNewMacro(vtk_message_sink);

/* While alive, VTK's messages go to a sink instead of stderr (its logger
 * prints there too, so that is muted as well); first() is the first one,
 * cleaned to one line: the library never prints. */
class vtk_messages
{
  public:
    vtk_messages()
        : previous(vtkOutputWindow::GetInstance()), sink(make<vtk_message_sink>()),
          verbosity(vtkLogger::GetCurrentVerbosityCutoff())
    {
        previous->Register(nullptr);
        vtkOutputWindow::SetInstance(sink);
        vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    }
    ~vtk_messages()
    {
        /* The cutoff is stderr's own unless a log file or callback was
         * added with a higher one; either way messages keep flowing. */
        vtkLogger::SetStderrVerbosity(verbosity);
        vtkOutputWindow::SetInstance(previous);
        previous->UnRegister(nullptr);
    }
    vtk_messages(const vtk_messages &) = delete;
    vtk_messages &operator=(const vtk_messages &) = delete;
    /* "ERROR: In file.cxx, line 254\nvtkPNGWriter (0x55...): Unable to open
     * file x" -> "vtkPNGWriter: Unable to open file x". */
    std::string first() const
    {
        if (sink->messages.empty())
            return "no message from VTK";
        std::string text = sink->messages.front(), line;
        size_t in = text.find(": In ");
        if (in != std::string::npos && text.find('\n', in) != std::string::npos)
            text = text.substr(text.find('\n', in) + 1);
        size_t address = text.find(" (0x");
        if (address != std::string::npos && text.find(')', address) != std::string::npos)
            text.erase(address, text.find(')', address) + 1 - address);
        for (char c : text)
            line += (c == '\n' || c == '\r') ? ' ' : c;
        line.erase(line.find_last_not_of(' ') + 1);
        return line.size() > 300 ? line.substr(0, 300) : line;
    }

  private:
    vtkOutputWindow *previous;
    vtk_ptr<vtk_message_sink> sink;
    vtkLogger::Verbosity verbosity;
};

static ss_status commit_file(ss_ctx *ctx, const std::string &tmp, const char *path)
{
    if (ss_output_rename(tmp.c_str(), path) != 0) {
        std::remove(tmp.c_str());
        return ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot rename the finished file to '%s'", path);
    }
    return SS_OK;
}

static bool valid_height(float z)
{
    return std::isfinite(z);
}

static bool valid_value(float v)
{
    return std::isfinite(v) && v != SS_NODATA;
}

static ss_status check_grid(ss_ctx *ctx, const ss_render_scene *s)
{
    if (!s || !s->z)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "no heights given to draw");
    if (s->width < 2 || s->height < 2 || (double)s->width * s->height >= 2147483647.0)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "a %d x %d grid cannot be drawn as a surface (2 x 2 to 2^31 cells)",
                       s->width, s->height);
    if (!(s->cell_x_m > 0 && s->cell_y_m > 0 && std::isfinite(s->cell_x_m) &&
          std::isfinite(s->cell_y_m)))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "cell size %g x %g m is not positive", s->cell_x_m,
                       s->cell_y_m);
    return SS_OK;
}

static ss_status check_scene(ss_ctx *ctx, const ss_render_scene *s)
{
    ss_status st = check_grid(ctx, s);
    if (st != SS_OK)
        return st;
    if (s->scalar && s->rgb)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "give a scalar drape or an RGB drape, not both");
    if (s->colormap && !ss_colormap_known(s->colormap))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "unknown colour map '%s' (known: %s)", s->colormap,
                       SS_COLORMAP_NAMES);
    if (!std::isnan(s->z_factor) && !(s->z_factor > 0 && std::isfinite(s->z_factor)))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "z factor %g must be positive (NaN = automatic)",
                       s->z_factor);
    if (!(s->distance_factor > 0 && s->distance_factor <= 100))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "distance factor %g must be in (0, 100]",
                       s->distance_factor);
    if (s->view != SS_VIEW_OBLIQUE && s->view != SS_VIEW_TOP && s->view != SS_VIEW_CUSTOM)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "unknown view %d", (int)s->view);
    if (s->view == SS_VIEW_CUSTOM && !(s->view_elevation_deg > 0 && s->view_elevation_deg <= 90 &&
                                       std::isfinite(s->view_azimuth_deg)))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "view elevation %g deg must be in (0, 90] and the azimuth finite",
                       s->view_elevation_deg);
    if (s->view == SS_VIEW_OBLIQUE && !std::isfinite(s->view_azimuth_deg))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "view azimuth is not a number");
    if (!(s->sun_elevation_deg >= -90 && s->sun_elevation_deg <= 90 &&
          std::isfinite(s->sun_azimuth_deg)))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "sun elevation %g deg must be in [-90, 90] and the azimuth finite",
                       s->sun_elevation_deg);
    if (s->image_width < 16 || s->image_height < 16 || s->image_width > 16384 ||
        s->image_height > 16384)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "image size %d x %d is outside 16..16384 pixels",
                       s->image_width, s->image_height);
    if (s->max_points < 0 || (s->max_points > 0 && s->max_points < 4))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT,
                       "at most %ld surface points cannot draw a surface (0 = no limit, else >= 4)",
                       s->max_points);
    return SS_OK;
}

/* VTK aborts the process when its own XOpenDisplay fails, so the display is
 * opened here and handed to VTK: the connection that was checked is the one
 * used (an Xvfb that vanishes in between cannot take the process down). */
static ss_status open_display(ss_ctx *ctx, Display **display)
{
    const char *name = std::getenv("DISPLAY");
    if (!name || !*name)
        return ss_ctx_error(ctx, SS_ERR_DEVICE,
                       "3D rendering needs an X display: run under xvfb-run -a");
    /* A busy Xvfb turns connections away now and then (EAGAIN, sometimes a
     * reset: about one in ten when connecting in a loop on this 2-core
     * machine): retry those briefly, not a display that is not there. */
    errno = 0;
    *display = XOpenDisplay(name);
    for (int attempt = 1;
         !*display && attempt <= 6 && (errno == EAGAIN || errno == ECONNRESET || errno == EINTR);
         ++attempt) {
        struct timespec pause = {0, 50000000L * attempt};
        nanosleep(&pause, nullptr);
        errno = 0;
        *display = XOpenDisplay(name);
    }
    if (!*display)
        return ss_ctx_error(ctx, SS_ERR_DEVICE,
                       "cannot open X display '%s' (%s): 3D rendering needs an X display: run "
                       "under xvfb-run -a",
                       name, errno ? std::strerror(errno) : "no reason given");
    return SS_OK;
}

/* Samples 0, k, 2k, ... and always the last index, so the extent is kept. */
struct sampling {
    int k, nx, ny, width, height;
    int col(int i) const
    {
        return i * k < width ? i * k : width - 1;
    }
    int row(int j) const
    {
        return j * k < height ? j * k : height - 1;
    }
};

static sampling choose_sampling(const ss_render_scene *s)
{
    sampling smp{1, s->width, s->height, s->width, s->height};
    while (s->max_points > 0 && (double)smp.nx * smp.ny > (double)s->max_points) {
        smp.k++;
        smp.nx = (s->width - 1 + smp.k - 1) / smp.k + 1;
        smp.ny = (s->height - 1 + smp.k - 1) / smp.k + 1;
    }
    return smp;
}

static double auto_z_factor(double relief_m, double extent_m)
{
    if (!(relief_m > 0))
        return 1.0;
    double f = auto_relief_fraction * extent_m / relief_m;
    if (f <= 1.0)
        return 1.0;
    if (f >= auto_z_factor_max)
        return auto_z_factor_max;
    /* Two significant digits: a value people can quote and reuse. */
    double scale = std::pow(10.0, std::floor(std::log10(f)) - 1);
    return std::round(f / scale) * scale;
}

static vtk_ptr<vtkLookupTable> make_lookup_table(const char *colormap, double vmin, double vmax)
{
    auto lut = make<vtkLookupTable>();
    const int n = 256;
    lut->SetNumberOfTableValues(n);
    lut->SetTableRange(vmin, vmax);
    for (int i = 0; i < n; ++i) {
        unsigned char rgb[3];
        ss_colormap_rgb(colormap ? colormap : "viridis", i / (n - 1.0), rgb);
        lut->SetTableValue(i, rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0, 1.0);
    }
    lut->SetNanColor(0.6, 0.6, 0.6, 1.0);
    return lut;
}

/* Legend and title in black or white, whichever stands out from the
 * background. */
static void text_colour(const ss_render_scene *s, double rgb[3])
{
    const unsigned char *b = s->background_rgb;
    double luma = (0.299 * b[0] + 0.587 * b[1] + 0.114 * b[2]) / 255.0;
    rgb[0] = rgb[1] = rgb[2] = luma > 0.5 ? 0.0 : 1.0;
}

struct built_surface {
    vtk_ptr<vtkPolyData> poly;
    double vmin, vmax; /* scalar range used */
};

static ss_status build_surface(ss_ctx *ctx, const ss_render_scene *s, const sampling &smp,
                               double z_min, double z_factor, built_surface *out)
{
    auto points = make<vtkPoints>();
    points->SetDataTypeToFloat();
    points->SetNumberOfPoints((vtkIdType)smp.nx * smp.ny);
    /* Local coordinates around the scene centre keep float precision. */
    double cx = 0.5 * (s->width - 1) * s->cell_x_m, cy = 0.5 * (s->height - 1) * s->cell_y_m;
    std::vector<char> ok((size_t)smp.nx * smp.ny);
    auto scalars = make<vtkFloatArray>();
    auto colours = make<vtkUnsignedCharArray>();
    if (s->scalar) {
        scalars->SetName(s->scalar_name ? s->scalar_name : "value");
        scalars->SetNumberOfTuples((vtkIdType)smp.nx * smp.ny);
    } else if (s->rgb) {
        colours->SetNumberOfComponents(3);
        colours->SetNumberOfTuples((vtkIdType)smp.nx * smp.ny);
    }
    double vmin = INFINITY, vmax = -INFINITY;
    for (int j = 0; j < smp.ny; ++j) {
        int row = smp.row(j);
        for (int i = 0; i < smp.nx; ++i) {
            int col = smp.col(i);
            size_t src = (size_t)row * s->width + col, dst = (size_t)j * smp.nx + i;
            float z = s->z[src];
            ok[dst] = valid_height(z);
            double zz = ok[dst] ? (z - z_min) * z_factor : 0.0;
            points->SetPoint((vtkIdType)dst, col * s->cell_x_m - cx,
                             (s->height - 1 - row) * s->cell_y_m - cy, zz);
            if (s->scalar) {
                float v = s->scalar[src];
                bool good = valid_value(v) && ok[dst];
                scalars->SetValue((vtkIdType)dst, good ? v : NAN);
                if (good) {
                    vmin = v < vmin ? v : vmin;
                    vmax = v > vmax ? v : vmax;
                }
            } else if (s->rgb) {
                for (int c = 0; c < 3; ++c)
                    colours->SetValue((vtkIdType)dst * 3 + c, s->rgb[src * 3 + c]);
            }
        }
    }
    /* Quads counter-clockwise seen from above, so normals point up. */
    auto quads = make<vtkCellArray>();
    for (int j = 0; j + 1 < smp.ny; ++j)
        for (int i = 0; i + 1 < smp.nx; ++i) {
            vtkIdType nw = (vtkIdType)j * smp.nx + i, sw = nw + smp.nx;
            vtkIdType q[4] = {sw, sw + 1, nw + 1, nw};
            if (ok[q[0]] && ok[q[1]] && ok[q[2]] && ok[q[3]])
                quads->InsertNextCell(4, q);
        }
    if (quads->GetNumberOfCells() == 0)
        return ss_ctx_error(ctx, SS_ERR_INPUT,
                       "no surface cell has four valid corner heights: nothing to draw");
    out->poly = make<vtkPolyData>();
    out->poly->SetPoints(points);
    out->poly->SetPolys(quads);
    if (s->scalar) {
        out->poly->GetPointData()->SetScalars(scalars);
        if (!std::isnan(s->scalar_min))
            vmin = s->scalar_min;
        if (!std::isnan(s->scalar_max))
            vmax = s->scalar_max;
        if (!(vmin <= vmax))
            vmin = vmax = 0.0; /* an all-nodata drape: every cell in the NaN colour */
        if (vmin == vmax)
            vmax = vmin + 1.0;
    } else if (s->rgb) {
        out->poly->GetPointData()->SetScalars(colours);
    }
    out->vmin = vmin;
    out->vmax = vmax;
    return SS_OK;
}

static void place_camera(const ss_render_scene *s, vtkRenderer *renderer, const double bounds[6])
{
    vtkCamera *cam = renderer->GetActiveCamera();
    double focal[3] = {0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
                       0.5 * (bounds[4] + bounds[5])};
    const double *vp = renderer->GetViewport();
    double aspect = (vp[2] - vp[0]) * s->image_width / ((vp[3] - vp[1]) * s->image_height);
    if (s->view == SS_VIEW_TOP) {
        double half_x = 0.5 * (bounds[1] - bounds[0]), half_y = 0.5 * (bounds[3] - bounds[2]);
        double fit = half_y > half_x / aspect ? half_y : half_x / aspect;
        cam->ParallelProjectionOn();
        cam->SetFocalPoint(focal);
        cam->SetPosition(focal[0], focal[1], bounds[5] + 2.0 * (half_x + half_y) + 1.0);
        cam->SetViewUp(0, 1, 0);
        cam->SetParallelScale(1.05 * fit * s->distance_factor);
        renderer->ResetCameraClippingRange(bounds);
        return;
    }
    double az = s->view_azimuth_deg * deg;
    double el = (s->view == SS_VIEW_OBLIQUE ? oblique_elevation_deg : s->view_elevation_deg) * deg;
    /* The camera stands opposite the direction it looks toward. */
    double dir[3] = {-std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el)};
    cam->ParallelProjectionOff();
    cam->SetFocalPoint(focal);
    cam->SetPosition(focal[0] + dir[0], focal[1] + dir[1], focal[2] + dir[2]);
    if (el > 89.0 * deg)
        cam->SetViewUp(std::sin(az), std::cos(az), 0);
    else
        cam->SetViewUp(0, 0, 1);
    renderer->ResetCamera(bounds);
    /* ResetCamera fits the bounding sphere, which leaves a wide margin
     * around a flat box; 1.3 fills the frame without cutting corners. */
    cam->Dolly(1.3 / s->distance_factor);
    renderer->ResetCameraClippingRange(bounds);
}

/* The sun, a directional light from its azimuth and elevation, plus a
 * weaker one from the zenith standing in for skylight: slopes facing away
 * from the sun stay readable, and since neither light follows the camera,
 * brightness means the same in every view. */
static void add_lights(const ss_render_scene *s, vtkRenderer *renderer, const double bounds[6])
{
    double az = s->sun_azimuth_deg * deg, el = s->sun_elevation_deg * deg;
    double focal[3] = {0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]),
                       0.5 * (bounds[4] + bounds[5])};
    double toward[2][3] = {{std::sin(az) * std::cos(el), std::cos(az) * std::cos(el), std::sin(el)},
                           {0, 0, 1}};
    double intensity[2] = {1.0, sky_intensity};
    renderer->AutomaticLightCreationOff();
    renderer->RemoveAllLights();
    for (int i = 0; i < 2; ++i) {
        auto light = make<vtkLight>();
        light->SetLightTypeToSceneLight();
        light->PositionalOff();
        light->SetFocalPoint(focal);
        light->SetPosition(focal[0] + toward[i][0], focal[1] + toward[i][1],
                           focal[2] + toward[i][2]);
        light->SetIntensity(intensity[i]);
        renderer->AddLight(light);
    }
}

static void add_texts(const ss_render_scene *s, vtkRenderer *renderer, vtkLookupTable *lut)
{
    double ink[3];
    text_colour(s, ink);
    if (lut) {
        auto bar = make<vtkScalarBarActor>();
        bar->SetLookupTable(lut);
        std::string title = s->scalar_name ? s->scalar_name : "value";
        if (s->scalar_unit && *s->scalar_unit)
            title += std::string(" (") + s->scalar_unit + ")";
        bar->SetTitle(title.c_str());
        bar->SetNumberOfLabels(5);
        bar->SetVerticalTitleSeparation(std::max(4, s->image_height / 60));
        bar->SetLabelFormat("%.3g");
        bar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
        bar->GetPositionCoordinate()->SetValue(legend_left + 0.01, 0.1);
        bar->SetWidth(0.98 - legend_left);
        bar->SetHeight(0.75);
        for (vtkTextProperty *tp : {bar->GetTitleTextProperty(), bar->GetLabelTextProperty()}) {
            tp->SetColor(ink);
            tp->ShadowOff();
            tp->ItalicOff();
        }
        renderer->AddActor2D(bar);
    }
    if (s->title && *s->title) {
        auto text = make<vtkTextActor>();
        text->SetInput(s->title);
        text->GetTextProperty()->SetColor(ink);
        text->GetTextProperty()->SetFontSize(s->image_height / 25 > 12 ? s->image_height / 25 : 12);
        text->GetTextProperty()->SetJustificationToCentered();
        text->GetTextProperty()->SetVerticalJustificationToTop();
        text->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
        text->GetPositionCoordinate()->SetValue(0.5, 0.98);
        renderer->AddActor2D(text);
    }
}

static ss_status render_png(ss_ctx *ctx, const ss_render_scene *s, const char *png_path,
                            ss_render_report *report, Display *display,
                            const vtk_messages &messages)
{
    auto t0 = std::chrono::steady_clock::now();
    double z_min = INFINITY, z_max = -INFINITY;
    for (size_t i = 0; i < (size_t)s->width * s->height; ++i)
        if (valid_height(s->z[i])) {
            z_min = s->z[i] < z_min ? s->z[i] : z_min;
            z_max = s->z[i] > z_max ? s->z[i] : z_max;
        }
    if (!(z_min <= z_max))
        return ss_ctx_error(ctx, SS_ERR_INPUT, "the DEM has no valid heights: nothing to draw");
    double extent_m = std::fmax((s->width - 1) * s->cell_x_m, (s->height - 1) * s->cell_y_m);
    double z_factor =
        std::isnan(s->z_factor) ? auto_z_factor(z_max - z_min, extent_m) : s->z_factor;
    sampling smp = choose_sampling(s);

    built_surface surf;
    ss_status st = build_surface(ctx, s, smp, z_min, z_factor, &surf);
    if (st != SS_OK)
        return st;
    auto normals = make<vtkPolyDataNormals>();
    normals->SetInputData(surf.poly);
    normals->SplittingOff();
    normals->ConsistencyOff();
    normals->AutoOrientNormalsOff();
    normals->ComputeCellNormalsOff();

    auto mapper = make<vtkPolyDataMapper>();
    mapper->SetInputConnection(normals->GetOutputPort());
    vtk_ptr<vtkLookupTable> lut;
    if (s->scalar) {
        lut = make_lookup_table(s->colormap, surf.vmin, surf.vmax);
        mapper->SetLookupTable(lut);
        mapper->SetScalarRange(surf.vmin, surf.vmax);
        mapper->SetScalarModeToUsePointData();
        /* Colours interpolated in value, not in RGB, across each cell. */
        mapper->InterpolateScalarsBeforeMappingOn();
        mapper->ScalarVisibilityOn();
    } else if (s->rgb) {
        mapper->SetColorModeToDirectScalars();
        mapper->ScalarVisibilityOn();
    } else {
        mapper->ScalarVisibilityOff();
    }
    auto actor = make<vtkActor>();
    actor->SetMapper(mapper);
    /* Lit by sun and sky a slope facing the sun reaches about 1 without
     * saturating; the ambient floor keeps the darkest slopes off black. */
    actor->GetProperty()->SetColor(0.85, 0.85, 0.85);
    actor->GetProperty()->SetAmbient(0.15);
    actor->GetProperty()->SetDiffuse(0.7);
    actor->GetProperty()->SetSpecular(0.0);

    /* The frame (layer 0) paints the background and holds legend and title;
     * the scene (layer 1) draws in the part of the window they leave free, so
     * text never covers terrain. */
    auto frame = make<vtkRenderer>();
    frame->SetBackground(s->background_rgb[0] / 255.0, s->background_rgb[1] / 255.0,
                         s->background_rgb[2] / 255.0);
    add_texts(s, frame, lut);
    auto renderer = make<vtkRenderer>();
    renderer->SetLayer(1);
    renderer->SetViewport(0, 0, lut ? legend_left : 1.0,
                          s->title && *s->title ? title_bottom : 1.0);
    renderer->AddActor(actor);
    double bounds[6];
    surf.poly->GetBounds(bounds);
    place_camera(s, renderer, bounds);
    add_lights(s, renderer, bounds);

    auto window = vtk_ptr<vtkRenderWindow>::Take(vtkRenderWindow::New());
    if (!window)
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "VTK has no render window (rendering module missing)");
    window->SetDisplayId(display);
    window->SetOffScreenRendering(1);
    window->SetSize(s->image_width, s->image_height);
    window->SetNumberOfLayers(2);
    window->AddRenderer(frame);
    window->AddRenderer(renderer);
    window->Render();

    auto grab = make<vtkWindowToImageFilter>();
    grab->SetInput(window);
    grab->SetInputBufferTypeToRGB();
    grab->ReadFrontBufferOff();
    grab->Update();
    int *dims = grab->GetOutput()->GetDimensions();
    if (dims[0] != s->image_width || dims[1] != s->image_height)
        return ss_ctx_error(ctx, SS_ERR_DEVICE, "VTK rendered %d x %d pixels instead of %d x %d: %s",
                       dims[0], dims[1], s->image_width, s->image_height, messages.first().c_str());

    std::string tmp = ss_temporary_name_cxx(png_path);
    auto writer = make<vtkPNGWriter>();
    writer->SetFileName(tmp.c_str());
    writer->SetInputConnection(grab->GetOutputPort());
    writer->Write();
    if (writer->GetErrorCode() != 0) {
        std::remove(tmp.c_str());
        return ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s': %s", png_path,
                       messages.first().c_str());
    }
    st = commit_file(ctx, tmp, png_path);
    if (st != SS_OK)
        return st;
    if (report) {
        report->decimation = smp.k;
        report->z_factor = z_factor;
        report->render_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return SS_OK;
}

extern "C" ss_status ss_render_png(ss_ctx *ctx, const ss_render_scene *scene, const char *png_path,
                                   ss_render_report *report)
{
    ss_status st = check_scene(ctx, scene);
    if (st != SS_OK)
        return st;
    if (!png_path || !*png_path)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "no PNG path given");
    Display *display = nullptr;
    st = open_display(ctx, &display);
    if (st != SS_OK)
        return st;
    try {
        /* render_png's VTK objects, window included, are gone when it
         * returns, before the display closes. */
        vtk_messages messages;
        st = render_png(ctx, scene, png_path, report, display, messages);
    } catch (const std::bad_alloc &) {
        st = ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory rendering '%s'", png_path);
    } catch (const std::exception &e) {
        st = ss_ctx_error(ctx, SS_ERR_INTERNAL, "rendering '%s' failed: %s", png_path, e.what());
    } catch (...) {
        st = ss_ctx_error(ctx, SS_ERR_INTERNAL, "rendering '%s' failed (unknown C++ exception)",
                     png_path);
    }
    XCloseDisplay(display);
    return st;
}

static ss_status export_vts(ss_ctx *ctx, const ss_render_scene *s, double origin_x, double origin_y,
                            const char *const *names, const float *const *fields, int n_fields,
                            const char *path, const vtk_messages &messages)
{
    const int w = s->width, h = s->height;
    const size_t n = (size_t)w * h;
    float z_low = INFINITY;
    for (size_t c = 0; c < n; ++c)
        if (valid_height(s->z[c]) && s->z[c] < z_low)
            z_low = s->z[c];
    if (!std::isfinite(z_low))
        return ss_ctx_error(ctx, SS_ERR_INPUT, "the DEM has no valid heights: nothing to export");

    auto grid = make<vtkStructuredGrid>();
    grid->SetDimensions(w, h, 1);
    /* CRS coordinates reach millions of metres: float would round them to
     * half a metre. */
    auto points = make<vtkPoints>();
    points->SetDataTypeToDouble();
    points->SetNumberOfPoints((vtkIdType)n);
    std::vector<vtk_ptr<vtkFloatArray>> arrays;
    for (int f = 0; f < n_fields; ++f) {
        auto a = make<vtkFloatArray>();
        a->SetName(names[f]);
        a->SetNumberOfTuples((vtkIdType)n);
        arrays.push_back(a);
    }
    std::vector<vtkIdType> hidden;
    for (int j = 0; j < h; ++j) {
        int row = h - 1 - j;
        for (int i = 0; i < w; ++i) {
            size_t src = (size_t)row * w + i;
            vtkIdType id = (vtkIdType)j * w + i;
            float z = s->z[src];
            if (!valid_height(z))
                hidden.push_back(id);
            points->SetPoint(id, origin_x + i * s->cell_x_m, origin_y - row * s->cell_y_m,
                             s->z_origin_m + (valid_height(z) ? z : z_low));
            for (int f = 0; f < n_fields; ++f) {
                float v = fields[f][src];
                arrays[f]->SetValue(id, valid_value(v) ? v : NAN);
            }
        }
    }
    grid->SetPoints(points);
    for (auto &a : arrays)
        grid->GetPointData()->AddArray(a);
    for (vtkIdType id : hidden)
        grid->BlankPoint(id);

    std::string tmp = ss_temporary_name_cxx(path);
    auto writer = make<vtkXMLStructuredGridWriter>();
    writer->SetFileName(tmp.c_str());
    writer->SetInputData(grid);
    writer->SetDataModeToAppended();
    writer->EncodeAppendedDataOff();
    writer->SetCompressorTypeToZLib();
    writer->SetHeaderTypeToUInt64(); /* arrays beyond 4 GB: large DEMs in double */
    if (writer->Write() != 1 || writer->GetErrorCode() != 0) {
        std::remove(tmp.c_str());
        return ss_ctx_error(ctx, SS_ERR_OUTPUT, "cannot write '%s': %s", path, messages.first().c_str());
    }
    return commit_file(ctx, tmp, path);
}

extern "C" ss_status ss_export_vts(ss_ctx *ctx, const ss_render_scene *scene, double origin_x,
                                   double origin_y, const char *const *field_names,
                                   const float *const *fields, int n_fields, const char *path)
{
    ss_status st = check_grid(ctx, scene);
    if (st != SS_OK)
        return st;
    if (!path || !*path)
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "no .vts path given");
    if (!std::isfinite(origin_x) || !std::isfinite(origin_y) || !std::isfinite(scene->z_origin_m))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "the grid origin is not a finite coordinate");
    if (n_fields < 0 || (n_fields > 0 && (!field_names || !fields)))
        return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "fields given without names or values");
    for (int f = 0; f < n_fields; ++f)
        if (!field_names[f] || !*field_names[f] || !fields[f])
            return ss_ctx_error(ctx, SS_ERR_ARGUMENT, "field %d has no name or no values", f + 1);
    try {
        vtk_messages messages;
        return export_vts(ctx, scene, origin_x, origin_y, field_names, fields, n_fields, path,
                          messages);
    } catch (const std::bad_alloc &) {
        return ss_ctx_error(ctx, SS_ERR_MEMORY, "out of memory exporting '%s'", path);
    } catch (const std::exception &e) {
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "exporting '%s' failed: %s", path, e.what());
    } catch (...) {
        return ss_ctx_error(ctx, SS_ERR_INTERNAL, "exporting '%s' failed (unknown C++ exception)", path);
    }
}
