/* The OpenImageIO adapter and the colour maps: heightmaps keep raw integer
 * and float values exactly (PNG 8/16 bit, PGM, EXR), colour images are
 * refused and grey RGB accepted, quicklooks have the asked size, bit depth
 * and alpha 0 exactly at nodata. PNG headers are parsed here, independently
 * of OIIO; the EXR is made by oiiotool from a PFM written here (skipped when
 * oiiotool is absent). */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "colormap.h"
#include "images.h"
#include "tap.h"

static char dir[] = "/tmp/ss-test-images-XXXXXX";
static char paths[16][300];
static int n_paths;

static const char *out_path(const char *name)
{
    snprintf(paths[n_paths], sizeof paths[0], "%s/%s", dir, name);
    return paths[n_paths++];
}

/* Width, height, bit depth and colour type (0 grey, 2 RGB, 4 grey+alpha,
 * 6 RGBA) from a PNG's IHDR chunk. */
static int png_header(const char *path, int *w, int *h, int *depth, int *colour_type)
{
    unsigned char b[26];
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    size_t got = fread(b, 1, sizeof b, f);
    fclose(f);
    if (got != sizeof b || memcmp(b, "\x89PNG\r\n\x1a\n", 8) != 0 || memcmp(b + 12, "IHDR", 4))
        return -1;
    *w = (int)((uint32_t)b[16] << 24 | (uint32_t)b[17] << 16 | (uint32_t)b[18] << 8 | b[19]);
    *h = (int)((uint32_t)b[20] << 24 | (uint32_t)b[21] << 16 | (uint32_t)b[22] << 8 | b[23]);
    *depth = b[24];
    *colour_type = b[25];
    return 0;
}

/* The context's message after a failure, "" after success. */
static const char *failure(const ss_ctx *ctx, ss_status st)
{
    return st == SS_OK ? "" : ss_ctx_message(ctx);
}

static void test_colormaps(void)
{
    unsigned char c[3];
    ss_colormap_rgb("viridis", 0.0, c);
    int v0 = c[0] == 68 && c[1] == 1 && c[2] == 84;
    ss_colormap_rgb("viridis", 1.0, c);
    int v1 = c[0] == 253 && c[1] == 231 && c[2] == 37;
    tap_ok(v0 && v1, "viridis ends are matplotlib's #440154 and #fde725");
    ss_colormap_rgb("magma", 0.5, c);
    tap_ok(c[0] == 183 && c[1] == 55 && c[2] == 121, "magma(0.5) = (183,55,121), got (%d,%d,%d)",
           c[0], c[1], c[2]);
    ss_colormap_rgb("terrain", 0.5, c);
    tap_ok(c[0] == 255 && c[1] == 255 && c[2] == 153,
           "terrain(0.5) is matplotlib's sand (255,255,153), got (%d,%d,%d)", c[0], c[1], c[2]);
    ss_colormap_rgb("grey", 0.25, c);
    int mid = c[0] == 64 && c[1] == 64 && c[2] == 64;
    ss_colormap_rgb("grey", -3.0, c);
    int low = c[0] == 0;
    ss_colormap_rgb("grey", 7.0, c);
    int high = c[0] == 255;
    ss_colormap_rgb("grey", NAN, c);
    int nan0 = c[0] == 0;
    tap_ok(mid && low && high && nan0, "grey interpolates (0.25 -> 64), clamps, NaN -> 0");
    int rising = 1, prev = -1;
    for (int i = 0; i <= 100; ++i) {
        ss_colormap_rgb("svf", i / 100.0, c);
        rising &= c[0] >= prev && c[0] == c[1] && c[1] == c[2];
        prev = c[0];
    }
    ss_colormap_rgb("svf", 0.0, c);
    tap_ok(rising && c[0] == 0 && prev == 255,
           "svf is a grey ramp from black (enclosed) to white (open)");
    tap_ok(ss_colormap_known("svf") && ss_colormap_known("magma") && !ss_colormap_known("jet") &&
               !ss_colormap_known(NULL) && !ss_colormap_known("Viridis"),
           "known names: svf, magma; not jet, NULL, Viridis");
}

#define W 37
#define H 23

/* Every 16-bit value class: 0, 65535 and a spread between. */
static float raw16(int col, int row)
{
    if (col == 0 && row == 0)
        return 0.0f;
    if (col == W - 1 && row == H - 1)
        return 65535.0f;
    return (float)((col * 977 + row * 5003 + 7) % 65536);
}

static void test_png16_heightmap(void)
{
    float *v = malloc(sizeof(float) * W * H);
    for (int r = 0; r < H; ++r)
        for (int c = 0; c < W; ++c)
            v[r * W + c] = raw16(c, r);
    ss_ctx *ctx = ss_ctx_new();
    /* A 0..65535 stretch writes each value as that very 16-bit integer. */
    const char *path = out_path("height16.png");
    ss_status st = ss_image_write_quicklook(ctx, path, v, W, H, 0.0, 65535.0, "grey", 16, 0);
    int w = -1, h = -1, depth = -1, type = -1;
    int header = png_header(path, &w, &h, &depth, &type);
    tap_ok(st == SS_OK && header == 0 && w == W && h == H && depth == 16 && type == 0,
           "16-bit grey PNG written by OIIO (IHDR %d x %d, depth %d, type %d)", w, h, depth, type);

    ss_grid g;
    st = ss_image_read_heightmap(ctx, path, 2.5, 0.25, 1000.5, &g);
    if (tap_ok(st == SS_OK, "read it as a heightmap %s", failure(ctx, st))) {
        int bad = 0;
        for (int r = 0; r < H; ++r)
            for (int c = 0; c < W; ++c) {
                double got = g.z_origin_m + g.z[r * W + c], want = raw16(c, r) * 0.25 + 1000.5;
                if (got != want && bad++ == 0)
                    tap_diag("cell (%d,%d): %.6f, want %.6f", c, r, got, want);
            }
        tap_ok(bad == 0 && g.width == W && g.height == H && g.cell_x_m == 2.5 &&
                   g.cell_y_m == 2.5 && g.z_origin_m == 1000.5,
               "heights are exactly raw x 0.25 + 1000.5 for 0..65535 (%d wrong), 2.5 m cells", bad);
        ss_grid_free(&g);
    }
    free(v);
    ss_ctx_free(ctx);
}

/* An 8-bit PGM written by hand: raw integers, not normalised. */
static void test_pgm8_heightmap(void)
{
    const char *path = out_path("height8.pgm");
    FILE *f = fopen(path, "wb");
    fprintf(f, "P5\n4 2\n255\n");
    const unsigned char px[8] = {0, 1, 2, 3, 128, 200, 254, 255};
    fwrite(px, 1, sizeof px, f);
    fclose(f);
    ss_ctx *ctx = ss_ctx_new();
    ss_grid g;
    ss_status st = ss_image_read_heightmap(ctx, path, 1.0, 2.0, -10.0, &g);
    int bad = st != SS_OK;
    for (int i = 0; i < 8 && st == SS_OK; ++i)
        bad += g.z_origin_m + g.z[i] != px[i] * 2.0 - 10.0;
    tap_ok(!bad, "8-bit PGM heightmap: raw 0..255 x 2 - 10, row 0 at the top %s", failure(ctx, st));
    if (st == SS_OK)
        ss_grid_free(&g);
    ss_ctx_free(ctx);
}

static int have_oiiotool(void)
{
    return system("oiiotool --version > /dev/null 2>&1") == 0;
}

/* A float PFM written by hand (rows bottom to top), turned into a float EXR
 * by oiiotool: values, NaN nodata and orientation survive. */
static void test_exr_heightmap(void)
{
    if (!have_oiiotool()) {
        tap_skip("float EXR heightmap round trip", "oiiotool is absent (openimageio-tools)");
        return;
    }
    const int w = 5, h = 3;
    float v[3][5];
    for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c)
            v[r][c] = (float)(-123.456 + 1e3 * sin(c + 10.0 * r)) * 1.0001f;
    v[1][3] = NAN;
    const char *pfm = out_path("height.pfm"), *exr = out_path("height.exr");
    FILE *f = fopen(pfm, "wb");
    fprintf(f, "Pf\n%d %d\n-1.0\n", w, h);
    for (int r = h - 1; r >= 0; --r)
        fwrite(v[r], sizeof(float), (size_t)w, f); /* little-endian: scale -1 */
    fclose(f);
    char cmd[800];
    snprintf(cmd, sizeof cmd, "oiiotool '%s' -d float -o '%s'", pfm, exr);
    if (!tap_ok(system(cmd) == 0, "oiiotool makes a float EXR"))
        return;
    ss_ctx *ctx = ss_ctx_new();
    ss_grid g;
    ss_status st = ss_image_read_heightmap(ctx, exr, 30.0, 1.0, 0.0, &g);
    int bad = st != SS_OK;
    for (int r = 0; r < h && st == SS_OK; ++r)
        for (int c = 0; c < w; ++c)
            bad += isnan(v[r][c]) ? !isnan(g.z[r * w + c]) : g.z[r * w + c] != v[r][c];
    tap_ok(!bad, "float EXR heightmap: every value exact, NaN is nodata, row 0 at the top %s",
           failure(ctx, st));
    if (st == SS_OK)
        ss_grid_free(&g);
    ss_ctx_free(ctx);
}

static void test_colour_refused(void)
{
    float v[4 * 3];
    for (int i = 0; i < 12; ++i)
        v[i] = (float)i;
    ss_ctx *ctx = ss_ctx_new();
    const char *colour = out_path("colour.png"), *grey = out_path("grey_rgb.png");
    ss_status st = ss_image_write_quicklook(ctx, colour, v, 4, 3, 0, 11, "viridis", 8, 0);
    ss_grid g;
    if (st == SS_OK)
        st = ss_image_read_heightmap(ctx, colour, 1.0, 1.0, 0.0, &g);
    tap_ok(st == SS_ERR_INPUT && strstr(ss_ctx_message(ctx), "colour image"),
           "an RGB colour PNG is refused: %s", ss_ctx_message(ctx));

    /* The grey map writes RGB with R = G = B: accepted, heights the levels. */
    st = ss_image_write_quicklook(ctx, grey, v, 4, 3, 0, 11, "grey", 8, 0);
    int w = -1, h = -1, depth = -1, type = -1;
    int rgb = png_header(grey, &w, &h, &depth, &type) == 0 && type == 2 && depth == 8;
    if (st == SS_OK)
        st = ss_image_read_heightmap(ctx, grey, 1.0, 1.0, 0.0, &g);
    int bad = st != SS_OK;
    for (int i = 0; i < 12 && st == SS_OK; ++i) {
        unsigned char c[3];
        ss_colormap_rgb("grey", v[i] / 11.0, c);
        bad += g.z[i] != c[0];
    }
    tap_ok(rgb && !bad, "a grey RGB PNG (R = G = B) is accepted with its levels %s",
           failure(ctx, st));
    if (st == SS_OK)
        ss_grid_free(&g);
    ss_ctx_free(ctx);
}

static void test_quicklooks(void)
{
    const int w = 50, h = 30;
    float *v = malloc(sizeof(float) * w * h);
    int *hole = calloc((size_t)w * h, sizeof *hole);
    for (int i = 0; i < w * h; ++i) {
        v[i] = (float)(0.6 + 0.4 * (i % w) / (w - 1.0));
        if ((i * 7) % 11 == 0) {
            v[i] = (i % 2) ? SS_NODATA : NAN;
            hole[i] = 1;
        }
    }
    v[1] = 0.6f; /* the minimum, at a known valid cell */
    hole[1] = 0;
    ss_ctx *ctx = ss_ctx_new();
    const char *rgba = out_path("ql_rgba.png");
    ss_status st = ss_image_write_quicklook(ctx, rgba, v, w, h, NAN, NAN, "viridis", 8, 1);
    int pw = -1, ph = -1, depth = -1, type = -1;
    int header = png_header(rgba, &pw, &ph, &depth, &type);
    tap_ok(st == SS_OK && header == 0 && pw == w && ph == h && depth == 8 && type == 6,
           "8-bit quicklook with alpha: RGBA PNG %d x %d, depth %d, type %d", pw, ph, depth, type);
    ss_image img;
    if (st == SS_OK && ss_image_read(ctx, rgba, &img) == SS_OK) {
        int bad = img.channels != 4 || img.alpha_channel != 3;
        for (int i = 0; i < w * h && !bad; ++i)
            bad += img.pixels[4 * i + 3] != (hole[i] ? 0.0f : 255.0f);
        tap_ok(!bad, "alpha is 0 exactly at the nodata cells (SS_NODATA and NaN), 255 elsewhere");
        unsigned char c[3];
        ss_colormap_rgb("viridis", 0.0, c);
        const float *p = &img.pixels[4 * 1];
        tap_ok(p[0] == c[0] && p[1] == c[1] && p[2] == c[2],
               "automatic stretch: the minimum cell is viridis(0) (%g,%g,%g)", p[0], p[1], p[2]);
        ss_image_free(&img);
    } else {
        tap_ok(0, "read the RGBA quicklook back (%s)", ss_ctx_message(ctx));
    }

    /* 16-bit grey + alpha, read back as a heightmap: alpha marks nodata. */
    const char *ga = out_path("ql_grey16.png");
    st = ss_image_write_quicklook(ctx, ga, v, w, h, 0.0, 1.0, NULL, 16, 1);
    header = png_header(ga, &pw, &ph, &depth, &type);
    tap_ok(st == SS_OK && header == 0 && depth == 16 && type == 4,
           "16-bit quicklook with alpha: grey+alpha PNG, depth %d, type %d", depth, type);
    ss_grid g;
    if (st == SS_OK && ss_image_read_heightmap(ctx, ga, 1.0, 1.0 / 65535.0, 0.0, &g) == SS_OK) {
        int bad = 0;
        for (int i = 0; i < w * h; ++i)
            bad += hole[i] ? !isnan(g.z[i]) : fabs(g.z[i] - v[i]) > 0.5 / 65535.0 + 1e-7;
        tap_ok(!bad, "its values within half a 16-bit step, nodata exactly at alpha 0 (%d wrong)",
               bad);
        ss_grid_free(&g);
    } else {
        tap_ok(0, "read the 16-bit quicklook back (%s)", ss_ctx_message(ctx));
    }

    /* Bad requests fail with a message and leave no file. */
    const char *bad_path = out_path("never.png");
    int refused =
        ss_image_write_quicklook(ctx, bad_path, v, w, h, 0, 1, NULL, 12, 0) == SS_ERR_ARGUMENT &&
        ss_image_write_quicklook(ctx, bad_path, v, w, h, 0, 1, "viridis", 16, 0) ==
            SS_ERR_ARGUMENT &&
        ss_image_write_quicklook(ctx, bad_path, v, w, h, 0, 1, "jet", 8, 0) == SS_ERR_ARGUMENT &&
        access(bad_path, F_OK) != 0;
    tap_ok(refused, "bits 12, a 16-bit colour map and an unknown map are refused (last: %s)",
           ss_ctx_message(ctx));
    tap_ok(ss_image_write_quicklook(ctx, "/nonexistent-dir/q.png", v, w, h, 0, 1, NULL, 8, 0) ==
               SS_ERR_OUTPUT,
           "an unwritable path gives SS_ERR_OUTPUT: %s", ss_ctx_message(ctx));
    tap_ok(ss_image_read_heightmap(ctx, "/nonexistent.png", 1, 1, 0, &g) == SS_ERR_INPUT,
           "a missing heightmap gives SS_ERR_INPUT: %s", ss_ctx_message(ctx));
    free(v);
    free(hole);
    ss_ctx_free(ctx);
}

int main(void)
{
    if (!mkdtemp(dir)) {
        printf("Bail out! cannot create a temporary folder\n");
        return 99;
    }
    test_colormaps();
    test_png16_heightmap();
    test_pgm8_heightmap();
    test_exr_heightmap();
    test_colour_refused();
    test_quicklooks();

    /* Temporary names were renamed away: only the files asked for remain. */
    char cmd[400];
    snprintf(cmd, sizeof cmd, "ls -A '%s' | grep -q '\\.tmp$'", dir);
    tap_ok(system(cmd) != 0, "no temporary files left behind");
    for (int i = 0; i < n_paths; ++i)
        unlink(paths[i]);
    rmdir(dir);
    return tap_done();
}
