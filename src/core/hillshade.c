/* Hillshade as gdaldem computes it (apps/gdaldem_lib.cpp, GDAL 3.6): the
 * cosine of the angle between the light and the surface normal, with the
 * gradient by Horn or Zevenbergen-Thorne and the z factor applied to it,
 * mapped to 1 + 254 cos(i) (1 where the cell faces away); or gdaldem's
 * multidirectional blend of lights from 225, 270, 315 and 360 degrees.
 * Returned as floats in 1..255 (the writer rounds to bytes, as gdaldem's
 * output does); SS_NODATA at nodata. Edges and holes take the gradient
 * as gdaldem -compute_edges does (kernels/ss_terms.h, ss_z_or; without
 * that option gdaldem leaves them nodata).
 *
 * ss_hillshade_rows adds what the sweep gives: the light's exact cast
 * shadows (a horizon walk along it), sky-view shading (the SVF of an
 * earlier walk, kept in a cell store), or RVT's VAT blend instead
 * (relief_blend.c).
 *
 * The pragma lets GCC vectorise the inner cells' loop (shade_inner_cells):
 * the shade's arithmetic may run where its select then takes the constant
 * (no-trapping-math), which changes no value (the reasoning of
 * insolation_lanes_body.h). It precedes the headers so that their inline
 * functions are compiled alike. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("no-trapping-math", "fp-contract=off")
#endif

#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "cell_store.h"
#include "products_internal.h"
#include "relief_blend.h"
#include "ss_sun.h"
#include "ss_terms.h"

/* gdaldem's multidirectional shade for gradient (x, y) = (-dz/de, dz/dn),
 * z factor included, as 1 + 127 * weighted sum (GDALHillshadeMultiDirectionalAlg). */
static double multidirectional(double x, double y, double alt_rad)
{
    double xx = x * x, yy = y * y, xx_yy = xx + yy;
    double s127 = 127.0 * sin(alt_rad), c127 = 127.0 * cos(alt_rad);
    if (xx_yy == 0.0)
        return 1.0 + 2.0 * s127;
    double cos225 = cos(225.0 * M_PI / 180.0);
    double v225 = fmax(0.0, s127 + (x - y) * cos225 * c127);
    double v270 = fmax(0.0, s127 - x * c127);
    double v315 = fmax(0.0, s127 + (x + y) * cos225 * c127);
    double v360 = fmax(0.0, s127 - y * c127);
    double w225 = 0.5 * xx_yy - x * y, w270 = xx, w315 = xx_yy - w225, w360 = yy;
    return 1.0 + (w225 * v225 + w270 * v270 + w315 * v315 + w360 * v360) / xx_yy /
                     sqrt(1.0 + xx_yy);
}

ss_status ss_hillshade_check(ss_ctx *ctx, const ss_hillshade_options *ho)
{
    ss_call_begin(ctx);
    if (!isfinite(ho->azimuth_deg) || !(ho->altitude_deg >= 0 && ho->altitude_deg <= 90) ||
        !(isfinite(ho->z_factor) && ho->z_factor > 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "hillshade needs a light azimuth, an altitude in 0..90 degrees and a "
                       "positive z factor (got %g, %g, %g)",
                       ho->azimuth_deg, ho->altitude_deg, ho->z_factor);
    if (!(ho->sky_view >= 0 && ho->sky_view <= 1) || !(ho->radius_m >= 0) ||
        !isfinite(ho->radius_m))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "hillshade needs a sky-view weight in 0..1 and a radius >= 0 (got %g, %g)",
                       ho->sky_view, ho->radius_m);
    if (ho->vat && (ho->cast_shadows || ho->sky_view > 0 || ho->multidirectional))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "the VAT blend (--blend vat) has its own light and layers: it takes "
                       "no --cast-shadows, --sky-view or --multidirectional");
    if (ho->crowns_crossed && !ho->cast_shadows)
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "trees shade the hillshade through its cast shadows: give --cast-shadows "
                       "with --canopy");
    if (ho->crowns_crossed && !(ho->transmissivity >= 0.0 && ho->transmissivity <= 1.0))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "transmissivity %g is not within 0..1",
                       ho->transmissivity);
    return SS_OK;
}

/* The shade of a cell with gradient (dz_de, dz_dn), z factor applied. */
static inline float shade_of(float dz_de, float dz_dn, float sun_e, float sun_n, float sun_u)
{
    float cang = ss_cos_incidence_gradient(sun_e, sun_n, sun_u, dz_de, dz_dn);
    return cang <= 0.0f ? 1.0f : 1.0f + 254.0f * cang;
}

/* Cells c0..c1-1 of row r of any kind: on the grid's edge, beside nodata,
 * nodata. */
static void shade_cells(const ss_grid *grid, int r, int c0, int c1,
                        const ss_hillshade_options *ho, float sun_e, float sun_n, float sun_u,
                        float *out_row)
{
    float cx = (float)grid->cell_x_m, cy = (float)grid->cell_y_m, zf = (float)ho->z_factor;
    double alt = ho->altitude_deg * M_PI / 180.0;
    for (int c = c0; c < c1; ++c) {
        if (!isfinite(grid->z[(size_t)r * grid->width + c])) {
            out_row[c] = SS_NODATA;
            continue;
        }
        float dz_de, dz_dn;
        if (ho->zevenbergen_thorne)
            ss_gradient_zt(grid->z, grid->width, grid->height, c, r, cx, cy, &dz_de, &dz_dn);
        else
            ss_gradient_horn(grid->z, grid->width, grid->height, c, r, cx, cy, &dz_de, &dz_dn);
        dz_de *= zf;
        dz_dn *= zf;
        out_row[c] = ho->multidirectional ? (float)multidirectional(-dz_de, dz_dn, alt)
                                          : shade_of(dz_de, dz_dn, sun_e, sun_n, sun_u);
    }
}

/* The inner cells of row r (not on the grid's edge) under one light: the
 * same values as shade_cells, in a loop that vectorises. Always inlined
 * with a constant zevenbergen_thorne, so that each copy keeps only its own
 * gradient (a choice inside the loop would become a select of both). */
static inline __attribute__((always_inline)) void
shade_inner_run(const ss_grid *grid, int r, int zevenbergen_thorne, float zf, float sun_e,
                float sun_n, float sun_u, float *out_row)
{
    const float *z = grid->z;
    int width = grid->width;
    float cx = (float)grid->cell_x_m, cy = (float)grid->cell_y_m;
#pragma omp simd
    for (int c = 1; c < width - 1; ++c) {
        float dz_de, dz_dn;
        if (zevenbergen_thorne)
            ss_gradient_zt_inner(z, width, c, r, cx, cy, &dz_de, &dz_dn);
        else
            ss_gradient_horn_inner(z, width, c, r, cx, cy, &dz_de, &dz_dn);
        float v = shade_of(dz_de * zf, dz_dn * zf, sun_e, sun_n, sun_u);
        out_row[c] = isfinite(z[(size_t)r * width + c]) ? v : SS_NODATA;
    }
}

static void shade_inner_cells(const ss_grid *grid, int r, const ss_hillshade_options *ho,
                              float sun_e, float sun_n, float sun_u, float *out_row)
{
    float zf = (float)ho->z_factor;
    if (ho->zevenbergen_thorne)
        shade_inner_run(grid, r, 1, zf, sun_e, sun_n, sun_u, out_row);
    else
        shade_inner_run(grid, r, 0, zf, sun_e, sun_n, sun_u, out_row);
}

void ss_hillshade_of_rows(const ss_grid *grid, int row0, int row1,
                          const ss_hillshade_options *ho, float *out)
{
    double az = ho->azimuth_deg * M_PI / 180.0, alt = ho->altitude_deg * M_PI / 180.0;
    float sun_e = (float)(cos(alt) * sin(az)), sun_n = (float)(cos(alt) * cos(az)),
          sun_u = (float)sin(alt);
    int width = grid->width;
#pragma omp parallel for schedule(static)
    for (int r = row0; r < row1; ++r) {
        float *out_row = out + (size_t)(r - row0) * width;
        if (ho->multidirectional || r == 0 || r == grid->height - 1 || width < 3) {
            shade_cells(grid, r, 0, width, ho, sun_e, sun_n, sun_u, out_row);
            continue;
        }
        shade_cells(grid, r, 0, 1, ho, sun_e, sun_n, sun_u, out_row);
        shade_inner_cells(grid, r, ho, sun_e, sun_n, sun_u, out_row);
        shade_cells(grid, r, width - 1, width, ho, sun_e, sun_n, sun_u, out_row);
    }
}

ss_status ss_hillshade(ss_ctx *ctx, const ss_grid *grid, double light_azimuth_deg,
                       double light_altitude_deg, double z_factor, int zevenbergen_thorne,
                       int multidirectional_light, float *shade)
{
    ss_call_begin(ctx);
    if (ss_grid_check(ctx, grid, NULL) != SS_OK)
        return SS_ERR_INPUT;
    ss_hillshade_options ho = {.azimuth_deg = light_azimuth_deg,
                               .altitude_deg = light_altitude_deg,
                               .z_factor = z_factor,
                               .zevenbergen_thorne = zevenbergen_thorne,
                               .multidirectional = multidirectional_light};
    ss_status st = ss_hillshade_check(ctx, &ho);
    if (st == SS_OK)
        ss_hillshade_of_rows(grid, 0, grid->height, &ho, shade);
    return st;
}

/* ---- in rows, with what the sweep gives --------------------------------- */

typedef struct {
    const ss_source *src;
    const ss_hillshade_options *ho;
    ss_cell_store *layers; /* sky view: the SVF; VAT: SVF and openness */
    float *shade, *svf, *openness; /* a band's rows */
    ss_rows_sink sink;
    void *user;
} shade_run;

/* The band's shade: the hillshade or the VAT blend, darkened in the
 * light's cast shadows (sunlit: the walk's horizons, else NULL), with the
 * sky view blended in. */
static ss_status shade_band(shade_run *s, const ss_band_view *band, const float *horizon)
{
    const ss_hillshade_options *ho = s->ho;
    ss_grid held = ss_band_grid(band, s->src);
    int first = band->row0 - band->lo;
    size_t n = (size_t)band->n_rows * band->width;
    ss_status st = SS_OK;
    if (s->layers)
        st = ss_cell_store_get(s->layers, 0, band->row0, band->n_rows, s->svf);
    if (st == SS_OK && ho->vat)
        st = ss_cell_store_get(s->layers, 1, band->row0, band->n_rows, s->openness);
    if (st != SS_OK)
        return st;
    if (ho->vat) {
        ss_vat_rows(&held, first, first + band->n_rows, s->svf, s->openness, s->shade);
        for (size_t c = 0; c < n; ++c)
            if (s->shade[c] != SS_NODATA)
                s->shade[c] = 1.0f + 254.0f * s->shade[c];
    } else {
        ss_hillshade_of_rows(&held, first, first + band->n_rows, ho, s->shade);
    }
    const unsigned char *crossed =
        ho->crowns_crossed ? ho->crowns_crossed + (size_t)band->row0 * band->width : NULL;
    for (size_t c = 0; horizon && c < n; ++c) {
        if (s->shade[c] == SS_NODATA)
            continue;
        if (!(ho->altitude_deg > horizon[c]))
            s->shade[c] = 1.0f;
        else if (crossed && crossed[c])
            s->shade[c] = (float)(1.0 + ho->transmissivity * (s->shade[c] - 1.0));
    }
    for (size_t c = 0; ho->sky_view > 0 && c < n; ++c)
        if (s->shade[c] != SS_NODATA)
            s->shade[c] = (float)((1 - ho->sky_view) * s->shade[c] +
                                  ho->sky_view * (1.0 + 254.0 * s->svf[c]));
    return s->sink(s->user, SS_OUT_SHADE, 0, band->row0, band->n_rows, s->shade);
}

static ss_status shade_direction(void *user, int index, const ss_band_view *band,
                                 const ss_dir_rows *rows, float *planes)
{
    (void)index, (void)planes;
    return shade_band(user, band, rows->angle);
}

static ss_status shade_finish(void *user, const ss_band_view *band, float *planes)
{
    (void)planes;
    return shade_band(user, band, NULL);
}

/* The layers the shade needs from summed walks: the SVF (geometric, within
 * the radius for VAT) and, for VAT, positive openness. */
static ss_status sky_layers(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                            shade_run *s)
{
    const ss_hillshade_options *ho = s->ho;
    int n = ho->vat ? 2 : 1;
    ss_status st = ss_cell_store_open(ctx, src, n, sizeof(float), &s->layers);
    double radius = ho->vat ? ho->radius_m : 0.0;
    for (int k = 0; k < n && st == SS_OK; ++k) {
        ss_store_sink sink = {s->layers, k};
        st = ss_sky_walk(ctx, src, opt, k == 0 ? SS_SKY_SVF_GEOMETRIC : SS_SKY_OPENNESS_POSITIVE,
                         radius, NULL, ss_store_sink_rows, &sink);
    }
    return st;
}

ss_status ss_hillshade_rows(ss_ctx *ctx, const ss_source *src, const ss_sweep_options *opt,
                            const ss_hillshade_options *ho, ss_rows_sink sink, void *user)
{
    ss_call_begin(ctx);
    ss_status st = ss_hillshade_check(ctx, ho);
    if (st == SS_OK)
        st = ss_rows_begin(ctx, src, opt, NULL);
    if (st != SS_OK)
        return st;
    int rows = ss_source_band_rows(src);
    size_t n = (size_t)rows * (size_t)src->width;
    /* The layers' rows only where the shade needs them. */
    int sky = ho->vat || ho->sky_view > 0;
    shade_run s = {src,  ho, NULL, ss_malloc(n * sizeof(float)),
                   sky ? ss_malloc(n * sizeof(float)) : NULL,
                   ho->vat ? ss_malloc(n * sizeof(float)) : NULL,
                   sink, user};
    if (!s.shade || (sky && !s.svf) || (ho->vat && !s.openness))
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for a band of shades");
    if (st == SS_OK && sky)
        st = sky_layers(ctx, src, opt, &s);
    /* The light's azimuth is in the raster's frame; the walk takes the
     * options' frame (true north unless the options say grid). */
    ss_engine_dir light = {ho->azimuth_deg + opt->grid_north_deg, 1, 0, -1};
    ss_consumer consumer = {.planes = 0,
                            .direction = shade_direction,
                            .finish = ho->cast_shadows ? NULL : shade_finish};
    ss_engine_job job = {
        .walk = {.term = ho->cast_shadows ? SS_TERM_HORIZON : SS_TERM_NONE, .none_deg = 0.0f},
        .dirs = &light,
        .n_dirs = ho->cast_shadows,
        .consumer = &consumer,
        .user = &s,
        .what = "hillshade"};
    /* Box shadows by each cell's own ray where they can be: the shade
     * needs only whether the light clears each cell's horizon. */
    if (st == SS_OK && ho->cast_shadows && ss_box_shadows_marched(opt))
        st = ss_box_shadow_march(ctx, src, opt, light.azimuth_deg, ho->altitude_deg,
                                 ho->altitude_deg, shade_direction, &s);
    else if (st == SS_OK)
        st = ss_engine_run(ctx, src, opt, &job);
    ss_cell_store_close(s.layers);
    free(s.shade);
    free(s.svf);
    free(s.openness);
    return st;
}
