/* Sweep options: defaults, validation, and the azimuth of each direction. */
#include "config.h"

#include <math.h>

#include "ctx_internal.h"

/* A million directions is far beyond any accuracy need (0.00036 degrees
 * apart) and keeps run times finite; see doc/accuracy.md for real needs. */
#define SS_DIRECTIONS_MAX 1000000

void ss_sweep_options_default(ss_sweep_options *opt)
{
    opt->directions = 32;
    opt->offset_deg = 0.0;
    opt->earth_radius_m = 0.0;
    opt->refraction_k = 0.0;
    opt->lines = SS_LINES_INTERPOLATED;
    opt->grid_north_deg = 0.0;
    opt->box_lines = SS_BOX_LINES_DEFAULT;
    opt->box_shadows = SS_BOX_SHADOWS_MARCH;
    opt->box_sky = SS_BOX_SKY_MARCH;
    opt->sky_box_lines = 0;
}

ss_status ss_sweep_options_check(ss_ctx *ctx, const ss_sweep_options *opt)
{
    ss_call_begin(ctx);
    if (opt->directions < 1 || opt->directions > SS_DIRECTIONS_MAX)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "--directions must be 1 to %d, not %d",
                       SS_DIRECTIONS_MAX, opt->directions);
    if (!isfinite(opt->offset_deg) || fabs(opt->offset_deg) > 360.0)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "--offset must be within -360..360 degrees, not %g",
                       opt->offset_deg);
    if (!(opt->earth_radius_m == 0.0 ||
          (opt->earth_radius_m >= 1e3 && opt->earth_radius_m <= 1e9)))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "earth radius must be 0 (no curvature) or 1e3..1e9 m, not %g",
                       opt->earth_radius_m);
    if (!(opt->refraction_k >= 0.0 && opt->refraction_k < 1.0))
        return ss_fail(ctx, SS_ERR_ARGUMENT, "refraction coefficient must be in [0, 1), not %g",
                       opt->refraction_k);
    if (!isfinite(opt->grid_north_deg) || fabs(opt->grid_north_deg) > 360.0)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "grid north must be within -360..360 degrees, not %g",
                       opt->grid_north_deg);
    if (opt->lines != SS_LINES_INTERPOLATED && opt->lines != SS_LINES_DIGITAL &&
        opt->lines != SS_LINES_BOX)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown line model %d", (int)opt->lines);
    if (opt->lines == SS_LINES_BOX && opt->sky_box_lines != 0 &&
        (opt->sky_box_lines < 1 || opt->sky_box_lines > SS_BOX_LINES_MAX ||
         (opt->sky_box_lines & (opt->sky_box_lines - 1)) != 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "box lines for the sky view must be 0 or a power of two from 1 to %d, "
                       "not %d",
                       SS_BOX_LINES_MAX, opt->sky_box_lines);
    if (opt->box_shadows != SS_BOX_SHADOWS_MARCH && opt->box_shadows != SS_BOX_SHADOWS_LINES)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown way of box shadows %d",
                       (int)opt->box_shadows);
    if (opt->box_sky != SS_BOX_SKY_MARCH && opt->box_sky != SS_BOX_SKY_LINES)
        return ss_fail(ctx, SS_ERR_ARGUMENT, "unknown way of the box sky view %d",
                       (int)opt->box_sky);
    if (opt->lines == SS_LINES_BOX &&
        (opt->box_lines < 1 || opt->box_lines > SS_BOX_LINES_MAX ||
         (opt->box_lines & (opt->box_lines - 1)) != 0))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "--box-lines must be a power of two from 1 to %d, not %d",
                       SS_BOX_LINES_MAX, opt->box_lines);
    return SS_OK;
}

const char *ss_line_model_name(ss_line_model lines)
{
    return lines == SS_LINES_DIGITAL ? "digital" : lines == SS_LINES_BOX ? "box" : "interpolated";
}

double ss_direction_azimuth(const ss_sweep_options *opt, int i)
{
    double az = fmod(opt->offset_deg + 360.0 * (double)i / (double)opt->directions, 360.0);
    return az < 0.0 ? az + 360.0 : az;
}
