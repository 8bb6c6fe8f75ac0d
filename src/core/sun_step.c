/* The sun of a clear-sky insolation step (skysweep_sun.h), shared by the
 * command line and the other front ends. */
#include "config.h"

#include <string.h>

#include "skysweep_sun.h"

void ss_sun_step_clear_sky(const ss_spa_result *sun, double grid_azimuth_deg,
                           double options_north_deg, double duration_h, double linke,
                           double solar_constant_w_m2, ss_sun_step *step)
{
    memset(step, 0, sizeof *step);
    step->duration_h = duration_h;
    step->linke = linke;
    double r = sun->earth_sun_distance_au;
    step->extraterrestrial_w_m2 = solar_constant_w_m2 / (r * r);
    step->unix_s = (sun->julian_day - 2440587.5) * 86400.0; /* UT1, within a second of UTC */
    step->grid_azimuth_deg = grid_azimuth_deg;
    step->azimuth_deg = grid_azimuth_deg + options_north_deg;
    step->elevation_deg = sun->elevation_deg;
    step->apparent_elevation_deg = sun->apparent_elevation_deg;
}
