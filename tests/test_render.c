/* The VTK adapter: renders of a Gaussian hill are the requested size, not
 * blank, lit from the sun's side (east, west and north), leave nodata holes
 * open, change with a drape, and report decimation and z factor; without a
 * display the call fails cleanly; the .vts export reads back through VTK's
 * own reader with CRS coordinates and field values in place. Run the render
 * part under xvfb-run -a; without DISPLAY it is skipped. */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "images.h"
#include "render.h"
#include "tap.h"
#include "vts_readback.h"

#define N 128
#define CELL_M 10.0
#define HILL_M 300.0
#define SIGMA_M 250.0
/* A nodata hole in the north-east quadrant (cells, inclusive). */
#define HOLE_COL0 88
#define HOLE_ROW0 24
#define HOLE_CELLS 16

/* Mesa's llvmpipe, which draws the offscreen renders under Xvfb, leaves
 * allocations behind in driver modules it has already unloaded at exit:
 * LeakSanitizer cannot name them, so no suppression can match, and its
 * report would end the process before the TAP plan is flushed. Leak checks
 * are off for this program only (sanitizer builds read this hook; other
 * builds ignore it). Address and undefined-behaviour checks stay on. */
const char *__asan_default_options(void);
const char *__asan_default_options(void)
{
    return "detect_leaks=0";
}

static char dir[] = "/tmp/ss-test-render-XXXXXX";
static char paths[16][300];
static int n_paths;

static const char *out_path(const char *name)
{
    snprintf(paths[n_paths], sizeof paths[0], "%s/%s", dir, name);
    return paths[n_paths++];
}

/* The context's message after a failure, "" after success. */
static const char *failure(const ss_ctx *ctx, ss_status st)
{
    return st == SS_OK ? "" : ss_ctx_message(ctx);
}

static void make_hill(float *z, int with_hole)
{
    double c = 0.5 * (N - 1) * CELL_M;
    for (int r = 0; r < N; ++r)
        for (int col = 0; col < N; ++col) {
            double dx = col * CELL_M - c, dy = r * CELL_M - c;
            z[r * N + col] =
                (float)(100.0 + HILL_M * exp(-(dx * dx + dy * dy) / (2 * SIGMA_M * SIGMA_M)));
        }
    for (int r = 0; with_hole && r < HOLE_CELLS; ++r)
        for (int col = 0; col < HOLE_CELLS; ++col)
            z[(HOLE_ROW0 + r) * N + HOLE_COL0 + col] = NAN;
}

static void hill_scene(ss_render_scene *s, const float *z)
{
    ss_render_scene_default(s);
    s->width = s->height = N;
    s->cell_x_m = s->cell_y_m = CELL_M;
    s->z = z;
    s->view = SS_VIEW_TOP;
    s->image_width = 640;
    s->image_height = 480;
}

typedef struct {
    ss_image img;
    int ok;
} picture;

static picture read_png(const char *path)
{
    picture p = {.ok = 0};
    ss_ctx *ctx = ss_ctx_new();
    p.ok = ss_image_read(ctx, path, &p.img) == SS_OK && p.img.channels >= 3;
    if (!p.ok)
        tap_diag("reading %s: %s", path, ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    return p;
}

static double grey_at(const ss_image *im, int x, int y)
{
    const float *px = &im->pixels[((size_t)y * im->width + x) * im->channels];
    return (px[0] + px[1] + px[2]) / 3.0;
}

static int is_background(const ss_image *im, int x, int y)
{
    const float *px = &im->pixels[((size_t)y * im->width + x) * im->channels];
    return px[0] >= 250 && px[1] >= 250 && px[2] >= 250;
}

/* Mean grey of the foreground in a window of the picture. */
static double mean_grey(const ss_image *im, int x0, int x1, int y0, int y1)
{
    double sum = 0;
    long n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
            if (!is_background(im, x, y)) {
                sum += grey_at(im, x, y);
                n++;
            }
    return n ? sum / n : NAN;
}

/* Renders the hill with the sun at azimuth sun_az_deg, 30 deg up, from the
 * top; returns the picture (ok = 0 on failure). */
static picture render_hill(const float *z, double sun_az_deg, const char *name,
                           ss_render_report *rep)
{
    ss_render_scene s;
    hill_scene(&s, z);
    s.sun_azimuth_deg = sun_az_deg;
    s.sun_elevation_deg = 30.0;
    ss_ctx *ctx = ss_ctx_new();
    const char *path = out_path(name);
    ss_status st = ss_render_png(ctx, &s, path, rep);
    if (st != SS_OK)
        tap_diag("render %s: %s", name, ss_ctx_message(ctx));
    ss_ctx_free(ctx);
    picture p = {.ok = 0};
    if (st == SS_OK)
        p = read_png(path);
    return p;
}

static void test_no_display(const float *z)
{
    const char *saved = getenv("DISPLAY");
    char keep[256] = "";
    if (saved)
        snprintf(keep, sizeof keep, "%s", saved);
    ss_render_scene s;
    hill_scene(&s, z);
    ss_ctx *ctx = ss_ctx_new();
    const char *path = out_path("nodisplay.png");

    unsetenv("DISPLAY");
    ss_status st = ss_render_png(ctx, &s, path, NULL);
    tap_ok(st == SS_ERR_DEVICE &&
               strcmp(ss_ctx_message(ctx),
                      "3D rendering needs an X display: run under xvfb-run -a") == 0 &&
               access(path, F_OK) != 0,
           "without DISPLAY: SS_ERR_DEVICE, the xvfb-run hint, no file (status %d, '%s')", st,
           ss_ctx_message(ctx));

    /* A display that names no server must fail the same way, not abort(). */
    setenv("DISPLAY", ":4711", 1);
    st = ss_render_png(ctx, &s, path, NULL);
    tap_ok(st == SS_ERR_DEVICE && strstr(ss_ctx_message(ctx), "xvfb-run") &&
               access(path, F_OK) != 0,
           "with an unreachable DISPLAY: SS_ERR_DEVICE (status %d, '%s')", st, ss_ctx_message(ctx));
    if (keep[0])
        setenv("DISPLAY", keep, 1);
    else
        unsetenv("DISPLAY");
    ss_ctx_free(ctx);
}

static void test_vts(const float *z)
{
    const double ox = 500005.0, oy = 4199995.0; /* UTM-sized: needs double points */
    float *svf = malloc(sizeof(float) * N * N), *slope = malloc(sizeof(float) * N * N);
    for (int i = 0; i < N * N; ++i) {
        svf[i] = (float)(0.5 + 0.5 * ((i * 37) % 101) / 100.0);
        slope[i] = (float)(i % N);
    }
    svf[5 * N + 7] = SS_NODATA;
    svf[9 * N + 2] = NAN;
    ss_render_scene s;
    hill_scene(&s, z);
    s.z_origin_m = 1000.0; /* the .vts holds absolute heights */
    const char *names[] = {"svf", "slope"};
    const float *fields[] = {svf, slope};
    const char *path = out_path("hill.vts");
    ss_ctx *ctx = ss_ctx_new();
    const char *saved = getenv("DISPLAY");
    char keep[256] = "";
    if (saved)
        snprintf(keep, sizeof keep, "%s", saved);
    unsetenv("DISPLAY"); /* the export must not need one */
    ss_status st = ss_export_vts(ctx, &s, ox, oy, names, fields, 2, path);
    if (keep[0])
        setenv("DISPLAY", keep, 1);
    tap_ok(st == SS_OK, "export .vts without a display %s", failure(ctx, st));

    vts_data d;
    if (vts_read(path, "svf", &d) != 0) {
        tap_ok(0, "read the .vts back: %s", d.error);
    } else {
        tap_ok(d.n_points == N * N && d.dims[0] == N && d.dims[1] == N && d.dims[2] == 1,
               "vtkXMLStructuredGridReader: %ld points, dims %d x %d x %d", d.n_points, d.dims[0],
               d.dims[1], d.dims[2]);
        float zmin = INFINITY, zmax = -INFINITY;
        long holes = 0;
        for (int i = 0; i < N * N; ++i) {
            if (isnan(z[i])) {
                holes++;
                continue;
            }
            zmin = fminf(zmin, z[i]);
            zmax = fmaxf(zmax, z[i]);
        }
        double want[6] = {ox, ox + (N - 1) * CELL_M, oy - (N - 1) * CELL_M,
                          oy, 1000.0 + zmin,         1000.0 + zmax};
        double worst = 0;
        for (int k = 0; k < 6; ++k)
            worst = fmax(worst, fabs(d.bounds[k] - want[k]));
        tap_ok(worst < 1e-6,
               "bounds in CRS metres [%.3f %.3f] [%.3f %.3f] [%.3f %.3f] (worst error %.3g)",
               d.bounds[0], d.bounds[1], d.bounds[2], d.bounds[3], d.bounds[4], d.bounds[5], worst);
        tap_ok(d.n_hidden == holes, "nodata heights are hidden points: %ld of %ld", d.n_hidden,
               holes);
        /* Point (i, j) is column i, row N-1-j. */
        int probes[][2] = {{0, 0}, {7, 5}, {2, 9}, {100, 3}, {64, 64}, {127, 127}};
        int bad = 0;
        for (size_t p = 0; p < sizeof probes / sizeof probes[0] && d.field; ++p) {
            int col = probes[p][0], row = probes[p][1];
            long id = (long)(N - 1 - row) * N + col;
            float want_v = svf[row * N + col];
            float got = d.field[id];
            int same = (want_v == SS_NODATA || isnan(want_v)) ? isnan(got) : got == want_v;
            const double *xyz = &d.xyz[3 * id];
            if (!same || xyz[0] != ox + col * CELL_M || xyz[1] != oy - row * CELL_M ||
                xyz[2] != 1000.0 + z[row * N + col]) {
                tap_diag("cell (%d,%d): svf %g want %g, point %.3f %.3f %.3f", col, row, got,
                         want_v, xyz[0], xyz[1], xyz[2]);
                bad++;
            }
        }
        tap_ok(d.field && bad == 0,
               "field 'svf' and point coordinates at 6 cells match (nodata -> NaN)");
        vts_data_free(&d);
    }
    ss_ctx_free(ctx);
    free(svf);
    free(slope);
}

static void test_plain_and_light(const float *z)
{
    ss_render_report rep = {0};
    picture east = render_hill(z, 90.0, "sun_east.png", &rep);
    if (!tap_ok(east.ok, "render the hill to PNG, sun in the east"))
        return;
    const ss_image *im = &east.img;
    tap_ok(im->width == 640 && im->height == 480 && im->bits == 8,
           "PNG is 640 x 480, 8 bits (got %d x %d, %d bits)", im->width, im->height, im->bits);
    tap_diag("render 128^2 -> 640x480: %.3f s, z factor %g, decimation %d", rep.render_seconds,
             rep.z_factor, rep.decimation);
    /* Relief 300 m over a 1270 m side: 0.3 * 1270 / 300 = 1.27 -> 1.3. */
    tap_ok(fabs(rep.z_factor - 1.3) < 1e-9 && rep.decimation == 1 && rep.render_seconds > 0,
           "report: automatic z factor %g (want 1.3), decimation %d (want 1)", rep.z_factor,
           rep.decimation);

    double sum = 0, sum2 = 0;
    long fg = 0, n = (long)im->width * im->height;
    for (int y = 0; y < im->height; ++y)
        for (int x = 0; x < im->width; ++x) {
            double g = grey_at(im, x, y);
            sum += g;
            sum2 += g * g;
            fg += !is_background(im, x, y);
        }
    double var = sum2 / n - (sum / n) * (sum / n);
    tap_ok(var > 100.0, "not blank: grey variance %.1f > 100", var);
    tap_ok(fg > 0.4 * n && fg < 0.9 * n,
           "foreground covers %.2f of the picture (a square grid, top view: 0.4..0.9)",
           (double)fg / n);

    /* The hill's slopes lie within about 1.5 sigma of the centre. */
    int cx = im->width / 2, cy = im->height / 2, r = 120;
    double e_west = mean_grey(im, cx - r, cx - 10, cy - r, cy + r);
    double e_east = mean_grey(im, cx + 10, cx + r, cy - r, cy + r);
    tap_ok(e_east > e_west + 15, "sun from azimuth 90: east half %.1f brighter than west %.1f",
           e_east, e_west);

    /* The nodata hole (north-east) shows background; its mirror (north-west)
     * does not. Pixels per metre from the top view's fit (1.05 x half side). */
    double px_per_m = (im->height / 2.0) / (1.05 * 0.5 * (N - 1) * CELL_M);
    double hole_x_m = (HOLE_COL0 + HOLE_CELLS / 2.0 - 0.5 - 0.5 * (N - 1)) * CELL_M;
    double hole_y_m = (0.5 * (N - 1) - (HOLE_ROW0 + HOLE_CELLS / 2.0 - 0.5)) * CELL_M;
    int hx = (int)lround(cx + hole_x_m * px_per_m), hy = (int)lround(cy - hole_y_m * px_per_m);
    int mx = (int)lround(cx - hole_x_m * px_per_m);
    int hole_bg = 0, mirror_bg = 0;
    for (int dy = -3; dy <= 3; ++dy)
        for (int dx = -3; dx <= 3; ++dx) {
            hole_bg += is_background(im, hx + dx, hy + dy);
            mirror_bg += is_background(im, mx + dx, hy + dy);
        }
    tap_ok(hole_bg == 49 && mirror_bg == 0,
           "nodata hole in the north-east is not drawn (%d/49 background at pixel %d,%d; "
           "mirror in the north-west %d/49)",
           hole_bg, hx, hy, mirror_bg);

    picture west = render_hill(z, 270.0, "sun_west.png", NULL);
    if (tap_ok(west.ok, "render with the sun in the west")) {
        double w_west = mean_grey(&west.img, cx - r, cx - 10, cy - r, cy + r);
        double w_east = mean_grey(&west.img, cx + 10, cx + r, cy - r, cy + r);
        tap_ok(w_west > w_east + 15, "sun from azimuth 270: west %.1f brighter than east %.1f",
               w_west, w_east);
    }
    picture north = render_hill(z, 0.0, "sun_north.png", NULL);
    if (tap_ok(north.ok, "render with the sun in the north")) {
        double n_top = mean_grey(&north.img, cx - r, cx + r, cy - r, cy - 10);
        double n_bottom = mean_grey(&north.img, cx - r, cx + r, cy + 10, cy + r);
        tap_ok(n_top > n_bottom + 15,
               "sun from azimuth 0: north (top) %.1f brighter than south %.1f", n_top, n_bottom);
    }

    /* A drape of the heights in viridis: colourful where the plain render
     * is grey, and different from it. */
    ss_render_scene s;
    hill_scene(&s, z);
    s.sun_azimuth_deg = 90.0;
    s.sun_elevation_deg = 30.0;
    s.scalar = z;
    s.scalar_name = "height";
    s.scalar_unit = "m";
    s.colormap = "viridis";
    s.title = "Gaussian hill";
    ss_ctx *ctx = ss_ctx_new();
    const char *path = out_path("drape.png");
    ss_render_report drep = {0};
    ss_status st = ss_render_png(ctx, &s, path, &drep);
    tap_ok(st == SS_OK, "render with a scalar drape, legend and title %s", failure(ctx, st));
    tap_diag("drape render 128^2 -> 640x480: %.3f s", drep.render_seconds);
    picture drape = st == SS_OK ? read_png(path) : (picture){.ok = 0};
    if (drape.ok) {
        long colourful_plain = 0, colourful_drape = 0;
        double diff = 0;
        for (long i = 0; i < n; ++i) {
            const float *a = &im->pixels[i * im->channels];
            const float *b = &drape.img.pixels[i * drape.img.channels];
            colourful_plain += fmaxf(fmaxf(a[0], a[1]), a[2]) - fminf(fminf(a[0], a[1]), a[2]) > 30;
            colourful_drape += fmaxf(fmaxf(b[0], b[1]), b[2]) - fminf(fminf(b[0], b[1]), b[2]) > 30;
            diff += fabs(a[0] - b[0]) + fabs(a[1] - b[1]) + fabs(a[2] - b[2]);
        }
        tap_ok(colourful_plain < n / 100 && colourful_drape > n / 4 && diff / (3.0 * n) > 10,
               "drape differs from the plain render: colourful pixels %.3f vs %.3f, mean "
               "difference %.1f levels",
               (double)colourful_drape / n, (double)colourful_plain / n, diff / (3.0 * n));
        /* The legend sits at the right edge: colourful pixels there. */
        long legend = 0;
        for (int y = 0; y < im->height; ++y)
            for (int x = (int)(0.86 * im->width); x < im->width; ++x) {
                const float *b = &drape.img.pixels[((size_t)y * im->width + x) * 3];
                legend += fmaxf(fmaxf(b[0], b[1]), b[2]) - fminf(fminf(b[0], b[1]), b[2]) > 30;
            }
        tap_ok(legend > 500, "a colour legend is drawn at the right edge (%ld colour pixels)",
               legend);
        ss_image_free(&drape.img);
    }
    ss_ctx_free(ctx);

    /* RGB drape: red on the western half, blue on the eastern. */
    unsigned char *rgb = malloc((size_t)N * N * 3);
    for (int i = 0; i < N * N; ++i) {
        int east_half = i % N >= N / 2;
        rgb[3 * i] = east_half ? 0 : 255;
        rgb[3 * i + 1] = 0;
        rgb[3 * i + 2] = east_half ? 255 : 0;
    }
    hill_scene(&s, z);
    s.rgb = rgb;
    s.image_width = 320;
    s.image_height = 240;
    ctx = ss_ctx_new();
    path = out_path("rgb.png");
    st = ss_render_png(ctx, &s, path, NULL);
    picture rgbp = st == SS_OK ? read_png(path) : (picture){.ok = 0};
    if (tap_ok(rgbp.ok, "render with an RGB drape %s", failure(ctx, st))) {
        const float *w = &rgbp.img.pixels[(120 * 320 + 100) * 3];
        const float *e = &rgbp.img.pixels[(120 * 320 + 220) * 3];
        tap_ok(w[0] > 2 * w[2] && e[2] > 2 * e[0],
               "RGB drape lands on its cells: west pixel (%g,%g,%g) red, east (%g,%g,%g) blue",
               w[0], w[1], w[2], e[0], e[1], e[2]);
        ss_image_free(&rgbp.img);
    }
    free(rgb);
    ss_ctx_free(ctx);

    ss_image_free(&east.img);
    ss_image_free(&west.img);
    ss_image_free(&north.img);
}

static void test_decimation(void)
{
    const int w = 256, h = 192;
    float *z = malloc(sizeof(float) * w * h);
    for (int i = 0; i < w * h; ++i)
        z[i] = (float)(50.0 * sin(0.05 * (i % w)) * cos(0.07 * (i / w)));
    ss_render_scene s;
    ss_render_scene_default(&s);
    s.width = w;
    s.height = h;
    s.cell_x_m = s.cell_y_m = 5.0;
    s.z = z;
    s.max_points = 20000;
    ss_render_report rep = {0};
    ss_ctx *ctx = ss_ctx_new();
    ss_status st = ss_render_png(ctx, &s, out_path("decimated.png"), &rep);
    /* Stride 1: 49152 points; stride 2: 129 x 97 = 12513 <= 20000. */
    tap_ok(st == SS_OK && rep.decimation == 2,
           "256 x 192 DEM, at most 20000 points: decimation %d (want 2) %s", rep.decimation,
           failure(ctx, st));
    tap_diag("oblique render 256x192 (stride 2) -> 800x600: %.3f s, z factor %g",
             rep.render_seconds, rep.z_factor);
    ss_ctx_free(ctx);
    free(z);
}

int main(void)
{
    if (!mkdtemp(dir)) {
        printf("Bail out! cannot create a temporary folder\n");
        return 99;
    }
    float *z = malloc(sizeof(float) * N * N);
    make_hill(z, 1);

    test_no_display(z);
    test_vts(z);
    const char *display = getenv("DISPLAY");
    if (display && *display) {
        test_plain_and_light(z);
        test_decimation();
    } else {
        tap_skip("3D renders", "DISPLAY is not set (run under xvfb-run -a)");
    }
    if (!getenv("SS_KEEP_TEST_OUTPUT")) {
        for (int i = 0; i < n_paths; ++i)
            unlink(paths[i]);
        rmdir(dir);
    } else {
        tap_diag("pictures kept in %s", dir);
    }
    free(z);
    return tap_done();
}
