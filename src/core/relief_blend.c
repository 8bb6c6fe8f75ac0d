/* RVT's "visualisation for archaeological topography" (VAT; Kokalj &
 * Somrak 2019, Remote Sensing 11(7) 747; RVT's blender_VAT.json), built
 * from skysweep's own layers. Bottom to top, each layer normalised to 0..1
 * by a linear stretch between the bounds given, then blended onto what is
 * below and mixed in with its opacity:
 *   4 hillshade, sun 315 deg / 35 deg, 0..1,        normal,     100 %
 *   3 slope, 0..50 deg, inverted (steep = dark),     luminosity,  50 %
 *   2 positive openness, 68..93 deg,                 overlay,     50 %
 *   1 sky-view factor (geometric), 0.7..1,           multiply,    25 %
 * On grey layers luminosity is the active layer itself; overlay is
 * 2ab below b = 0.5 and 1 - 2(1-a)(1-b) above (b below, a active).
 * doc/relief.md describes the recipe and the choice of radius. */
#include "config.h"

#include <math.h>
#include <stdlib.h>

#include "products_internal.h"
#include "relief_blend.h"
#include "ss_terms.h"

static float stretch(float v, float lo, float hi)
{
    float t = (v - lo) / (hi - lo);
    return t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
}

static float mix(float blended, float below, float opacity)
{
    return opacity * blended + (1.0f - opacity) * below;
}

float ss_vat_compose(float hillshade, float slope_deg, float openness_deg, float svf)
{
    float image = stretch(hillshade, 0.0f, 1.0f);
    image = mix(1.0f - stretch(slope_deg, 0.0f, 50.0f), image, 0.5f);
    float a = stretch(openness_deg, 68.0f, 93.0f);
    float overlay = image > 0.5f ? 1.0f - 2.0f * (1.0f - a) * (1.0f - image) : 2.0f * a * image;
    image = mix(overlay, image, 0.5f);
    return mix(stretch(svf, 0.7f, 1.0f) * image, image, 0.25f);
}

void ss_vat_rows(const ss_grid *grid, int row0, int row1, const float *svf,
                 const float *openness, float *out)
{
    /* The light comes from 315 deg in the raster's frame, as RVT's does. */
    ss_hillshade_options light = {.azimuth_deg = 315.0, .altitude_deg = 35.0, .z_factor = 1.0};
    ss_hillshade_of_rows(grid, row0, row1, &light, out);
    float cx = (float)grid->cell_x_m, cy = (float)grid->cell_y_m;
#pragma omp parallel for schedule(static)
    for (int r = row0; r < row1; ++r)
        for (int c = 0; c < grid->width; ++c) {
            size_t k = (size_t)(r - row0) * grid->width + c;
            if (!isfinite(grid->z[(size_t)r * grid->width + c])) {
                out[k] = SS_NODATA;
                continue;
            }
            float dz_de, dz_dn;
            ss_gradient_horn(grid->z, grid->width, grid->height, c, r, cx, cy, &dz_de, &dz_dn);
            float slope_deg = atanf(sqrtf(dz_de * dz_de + dz_dn * dz_dn)) * (float)(180 / M_PI);
            float cos_i = (out[k] - 1.0f) / 254.0f; /* gdaldem's 1 + 254 cos(i) */
            out[k] = ss_vat_compose(cos_i, slope_deg, openness[k], svf[k]);
        }
}

ss_status ss_vat(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt, double radius_m,
                 float *out)
{
    ss_call_begin(ctx);
    size_t n = (size_t)grid->width * grid->height;
    float *svf = ss_malloc(n * sizeof *svf), *openness = ss_malloc(n * sizeof *openness);
    ss_status st = svf && openness ? SS_OK : ss_fail(ctx, SS_ERR_MEMORY, "out of memory for VAT");
    if (st == SS_OK)
        st = ss_svf_within(ctx, grid, opt, SS_SVF_DEF_GEOMETRIC, radius_m, svf);
    if (st == SS_OK)
        st = ss_openness(ctx, grid, opt, 0, radius_m, openness);
    if (st == SS_OK)
        ss_vat_rows(grid, 0, grid->height, svf, openness, out);
    free(svf);
    free(openness);
    return st;
}
