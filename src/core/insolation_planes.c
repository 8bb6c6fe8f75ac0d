/* Irradiation on open planes (ss_insolation_open_planes): each weather
 * record's step on a plane of given tilt and azimuth over level ground,
 * with no horizon but the ground's, computed by the same per-cell step as
 * every insolation run (kernels/ss_cell_step.h) with the terms a fixed
 * module on level ground takes. skysweep roofs compares each roof plane
 * with it (its shading loss); without weather it runs a clear sky as
 * records (ss_clear_sky_record). */
#include "config.h"

#include <math.h>

#include "insolation_cell.h"
#include "insolation_internal.h"

ss_status ss_insolation_open_planes(ss_ctx *ctx, const ss_insolation_options *io, int n_steps,
                                    ss_sun_step_fn sun_at, void *sun_user, int n_planes,
                                    const double *tilt_deg, const double *azimuth_deg,
                                    double *global_wh_m2)
{
    for (int p = 0; p < n_planes; ++p) {
        if (!(tilt_deg[p] >= 0 && tilt_deg[p] <= 90 && isfinite(azimuth_deg[p])))
            return ss_fail(ctx, SS_ERR_ARGUMENT, "a plane's tilt must lie in 0..90 degrees and "
                                                 "its azimuth be finite");
        global_wh_m2[p] = 0;
    }
    const double rad = M_PI / 180.0;
    for (int k = 0; k < n_steps; ++k) {
        ss_sun_step sun;
        ss_status st = sun_at(ctx, k, &sun, sun_user);
        if (st != SS_OK)
            return st;
        if (!sun.real_sky)
            return ss_fail(ctx, SS_ERR_ARGUMENT, "open planes take weather records");
        ss_sky_record rec;
        int light = 0;
        if (!ss_insolation_sky_record(ctx, &sun, io, &rec, &light, 1) || !light)
            continue;
        ss_sky_parts sky = ss_sky_parts_of((int)io->sky_model, fmaxf(rec.dhi, 0.0f),
                                           fmaxf(rec.dni, 0.0f), rec.dni_extra,
                                           (float)((90.0 - sun.elevation_deg) * rad));
        for (int p = 0; p < n_planes; ++p) {
            /* A plane descending toward its azimuth (the steps' north is
             * true north); level ground leaves it the sky view of pvlib's
             * isotropic sky, (1 + cos tilt) / 2, and the whole horizon band. */
            double slope = tan(fmin(tilt_deg[p], 89.9) * rad), a = azimuth_deg[p] * rad;
            ss_cell_terms t = ss_cell_terms_of((float)(-slope * sin(a)), (float)(-slope * cos(a)),
                                               (float)(0.5 * (1.0 + cos(tilt_deg[p] * rad))),
                                               0.0);
            ss_cell_sun s = ss_cell_sun_exact(&t, (float)(sun.elevation_deg * rad),
                                              (float)(sun.grid_azimuth_deg * rad), 0.0f, 0);
            ss_cell_step step = ss_cell_step_weather(&t, &s, (float)sun.apparent_elevation_deg,
                                                     0.0f, &rec, sky, (float)sun.duration_h);
            global_wh_m2[p] += step.total;
        }
    }
    return SS_OK;
}

void ss_clear_sky_record(const ss_sun_step *step, double height_m, double *ghi_w_m2,
                         double *dni_w_m2, double *dhi_w_m2)
{
    const double rad = M_PI / 180.0;
    ss_cell_terms level = ss_cell_terms_of(0.0f, 0.0f, 1.0f, height_m);
    ss_cell_sun s =
        ss_cell_sun_exact(&level, (float)(step->elevation_deg * rad), 0.0f, (float)step->linke, 1);
    double g0 = step->extraterrestrial_w_m2;
    int up = step->elevation_deg > 0.0;
    *dni_w_m2 = up ? g0 * s.kb : 0.0;
    *dhi_w_m2 = up ? g0 * s.diffuse_fraction : 0.0;
    *ghi_w_m2 = up ? *dni_w_m2 * s.sin_h0 + *dhi_w_m2 : 0.0;
}
