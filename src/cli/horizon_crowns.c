/* The crowns' horizon of a site (horizon_crowns.h). */
#include "config.h"

#include <math.h>

#include "horizon_crowns.h"

double crowns_max_top(const ss_grid *ground, const ss_canopy *canopy)
{
    size_t n = (size_t)ground->width * (size_t)ground->height;
    double top = -INFINITY;
    for (size_t i = 0; i < n; ++i)
        if (canopy->height_m[i] > 0.0f && isfinite(ground->z[i]))
            top = fmax(top, (double)ground->z[i] + canopy->height_m[i]);
    return isfinite(top) ? top + ground->z_origin_m : top;
}

/* Distance (m) to the next cell edge along one axis, and the distance
 * between edges: pos in cell units (centres whole), speed in cells per
 * metre. */
static void axis_start(double pos, double speed, double *next, double *delta)
{
    double cell = floor(pos + 0.5);
    if (speed > 0.0)
        *next = (cell + 0.5 - pos) / speed;
    else if (speed < 0.0)
        *next = (cell - 0.5 - pos) / speed;
    else
        *next = INFINITY;
    *delta = speed != 0.0 ? 1.0 / fabs(speed) : INFINITY;
}

/* The best curved slope (dz - k d^2) / d over a crown cell's stretch of
 * ray [t_in, t_out]: at t_in when the top is above the eye, else where its
 * derivative vanishes, held within the stretch. */
static double cell_slope(double dz, double k, double t_in, double t_out)
{
    /* A site on the edge of a crown cell stands against it: the crown
     * rises straight up (t_in 0), within a micrometre. */
    t_in = fmax(t_in, 1e-6);
    double t = t_in;
    if (dz < 0.0)
        t = k > 0.0 ? fmin(fmax(sqrt(-dz / k), t_in), t_out) : t_out;
    return dz / t - k * t;
}

/* One azimuth (grid frame, radians): the best slope, -INFINITY if none. */
static double crowns_ray(const ss_grid *g, const ss_canopy *canopy, const ss_point_site *site,
                         double eye_m, double max_top_m, double k, double az)
{
    double dc = sin(az) / g->cell_x_m, dr = -cos(az) / g->cell_y_m; /* cells per metre */
    int c = (int)floor(site->col + 0.5), r = (int)floor(site->row + 0.5);
    int sc = dc > 0.0 ? 1 : -1, sr = dr > 0.0 ? 1 : -1;
    double next_c, next_r, delta_c, delta_r, best = -INFINITY;
    axis_start(site->col, dc, &next_c, &delta_c);
    axis_start(site->row, dr, &next_r, &delta_r);
    for (;;) {
        double t_in = fmin(next_c, next_r);
        if (next_c <= next_r) {
            c += sc;
            next_c += delta_c;
        } else {
            r += sr;
            next_r += delta_r;
        }
        if (c < 0 || r < 0 || c >= g->width || r >= g->height)
            break;
        /* No crown farther rises above the best: the highest top over the
         * nearest distance still to come bounds them all. */
        if (max_top_m > eye_m && (max_top_m - eye_m) / t_in < best)
            break;
        size_t i = (size_t)r * (size_t)g->width + (size_t)c;
        double t_out = fmin(next_c, next_r);
        /* A cell the ray only grazes at a corner (a diagonal through cell
         * corners, bent by the last digits of the cell sizes) holds under a
         * micrometre of it: left out, as a march along the ray leaves it. */
        if (!(canopy->height_m[i] > 0.0f) || !isfinite(g->z[i]) || t_out - t_in < 1e-6)
            continue;
        double dz = (double)g->z[i] + g->z_origin_m + canopy->height_m[i] - eye_m;
        best = fmax(best, cell_slope(dz, k, t_in, t_out));
    }
    return best;
}

void crowns_profile(const ss_grid *ground, const ss_canopy *canopy, const ss_point_site *site,
                    double eye_m, double max_top_m, const ss_sweep_options *opt, double *deg)
{
    double r_eff = opt->earth_radius_m / (1.0 - opt->refraction_k);
    double k = opt->earth_radius_m > 0.0 ? 0.5 / r_eff : 0.0; /* as the solid profile's */
    for (int i = 0; i < opt->directions; ++i) {
        double az = (ss_direction_azimuth(opt, i) - site->grid_north_deg) * (M_PI / 180.0);
        double slope = isfinite(max_top_m)
                           ? crowns_ray(ground, canopy, site, eye_m, max_top_m, k, az)
                           : -INFINITY;
        deg[i] = isfinite(slope) ? atan(slope) * (180.0 / M_PI) : -90.0;
    }
}
