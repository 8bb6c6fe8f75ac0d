/* Hillshade as gdaldem computes it (apps/gdaldem_lib.cpp, GDAL 3.6): the
 * cosine of the angle between the light and the surface normal, with the
 * gradient by Horn or Zevenbergen-Thorne and the z factor applied to it,
 * mapped to 1 + 254 cos(i) (1 where the cell faces away); or gdaldem's
 * multidirectional blend of lights from 225, 270, 315 and 360 degrees.
 * Returned as floats in 1..255 (the writer rounds to bytes, as gdaldem's
 * output does); SS_NODATA at nodata. Edges and holes use one-sided
 * gradients (gdaldem leaves edges nodata unless -compute_edges). */
#include "config.h"

#include <math.h>

#include "ctx_internal.h"
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

ss_status ss_hillshade(ss_ctx *ctx, const ss_grid *grid, double light_azimuth_deg,
                       double light_altitude_deg, double z_factor, int zevenbergen_thorne,
                       int multidirectional_light, float *shade)
{
    if (ss_grid_check(ctx, grid, NULL) != SS_OK)
        return SS_ERR_INPUT;
    if (!isfinite(light_azimuth_deg) || !(light_altitude_deg >= 0 && light_altitude_deg <= 90) ||
        !(isfinite(z_factor) && z_factor > 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "hillshade needs a light azimuth, an altitude in 0..90 degrees and a "
                       "positive z factor (got %g, %g, %g)",
                       light_azimuth_deg, light_altitude_deg, z_factor);
    double az = light_azimuth_deg * M_PI / 180.0, alt = light_altitude_deg * M_PI / 180.0;
    float sun_e = (float)(cos(alt) * sin(az)), sun_n = (float)(cos(alt) * cos(az)),
          sun_u = (float)sin(alt);
    float cx = (float)grid->cell_x_m, cy = (float)grid->cell_y_m;
#pragma omp parallel for schedule(static)
    for (int r = 0; r < grid->height; ++r)
        for (int c = 0; c < grid->width; ++c) {
            size_t k = (size_t)r * grid->width + c;
            if (!isfinite(grid->z[k])) {
                shade[k] = SS_NODATA;
                continue;
            }
            float dz_de, dz_dn;
            if (zevenbergen_thorne)
                ss_gradient_zt(grid->z, grid->width, grid->height, c, r, cx, cy, &dz_de, &dz_dn);
            else
                ss_gradient_horn(grid->z, grid->width, grid->height, c, r, cx, cy, &dz_de,
                                 &dz_dn);
            dz_de *= (float)z_factor;
            dz_dn *= (float)z_factor;
            if (multidirectional_light) {
                shade[k] = (float)multidirectional(-dz_de, dz_dn, alt);
            } else {
                float cang = ss_cos_incidence_gradient(sun_e, sun_n, sun_u, dz_de, dz_dn);
                shade[k] = cang <= 0.0f ? 1.0f : 1.0f + 254.0f * cang;
            }
        }
    return SS_OK;
}
