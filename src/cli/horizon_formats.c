/* Horizon files for PV software (horizon_formats.h). Each tool's layout
 * and convention, with the documentation it follows, is in
 * doc/pv-horizons.md (Formats); the tests read every file back with a
 * reader written from that documentation (tests/test_points.sh). */
#include "config.h"

#include <math.h>
#include <string.h>

#include "horizon_formats.h"

/* Elevations as the tools take them: they accept 0 to 90 degrees, so a
 * horizon below the horizontal (a site on a ridge) and -90 (no terrain
 * ahead inside the DEM) both mean open sky down to the horizontal. */
static double open_floor(double elevation_deg)
{
    return elevation_deg > 0.0 ? elevation_deg : 0.0;
}

/* Clockwise from north (0..360) to clockwise from south (-180..180): south 0,
 * west +90, east -90, north -180. PVsyst's and PV*SOL's convention. */
static double from_south(double azimuth_deg)
{
    double a = fmod(azimuth_deg, 360.0);
    return (a < 0.0 ? a + 360.0 : a) - 180.0;
}

/* The PVGIS API's userhorizon list: elevations at equal steps clockwise
 * from north, comma-separated; kept unclipped as it always was. */
static void write_pvgis(FILE *f, const horizon_file_site *site, const ss_point_horizon_result *p,
                        int n)
{
    (void)site;
    for (int i = 0; i < n; ++i)
        fprintf(f, "%s%.2f", i ? "," : "", p[i].elevation_deg);
    fputc('\n', f);
}

/* PVsyst's azimuth (its glossary, "Plane azimuth"): from the equator's side,
 * west +90 and east -90 in both hemispheres, so clockwise from south in the
 * north and counterclockwise from north in the south; -180..180. */
static double pvsyst_azimuth(double azimuth_deg, int south)
{
    if (!south)
        return from_south(azimuth_deg);
    double a = fmod(-azimuth_deg, 360.0);
    a = a < 0.0 ? a + 360.0 : a;
    return (a >= 180.0 ? a - 360.0 : a) + 0.0; /* + 0: north is 0, not -0 */
}

/* PVsyst's "standard CSV" horizon import: lines with text are comments (one
 * naming "Latitude ..., Longitude ..." becomes the horizon's comment), then
 * one azimuth,height pair a line, ascending from -180 and closed at +180.
 * The import asks for the azimuths' rotation and north; a comment says
 * which. */
static void write_pvsyst(FILE *f, const horizon_file_site *site, const ss_point_horizon_result *p,
                         int n)
{
    int south = site->lat_deg < 0.0;
    fprintf(f, "Horizon of site %s by skysweep %s from %s\n", site->id, ss_version(),
            site->sources);
    fprintf(f, "Latitude %.6f, Longitude %.6f\n", site->lat_deg, site->lon_deg);
    fprintf(f,
            "Azimuth in degrees from the %s, west +90, east -90 (PVsyst's convention in the "
            "%s hemisphere): on import choose %s and North azimuth %s. Height in degrees "
            "above the horizontal, 0 where the terrain is lower\n",
            south ? "north" : "south", south ? "southern" : "northern",
            south ? "Counterclockwise" : "Clockwise", south ? "0" : "180");
    fprintf(f, "Azimuth,Height\n");
    /* Ascending from -180: in the north the profile's own order (north,
     * -180, first); in the south from azimuth 180 down to 0, then from the
     * last direction down to just past 180. */
    int half = 0; /* directions at azimuths 0..180 */
    while (half < n && p[half].azimuth_deg <= 180.0)
        half++;
    for (int k = 0; k < n; ++k) {
        int i = !south ? k : k < half ? half - 1 - k : n - 1 - (k - half);
        fprintf(f, "%.10g,%.2f\n", pvsyst_azimuth(p[i].azimuth_deg, south),
                open_floor(p[i].elevation_deg));
    }
    /* +180 closes the profile where -180 opened it: north in the north
     * (always a direction), south in the south where 180 is one. */
    int first = south ? half - 1 : 0;
    if (pvsyst_azimuth(p[first].azimuth_deg, south) == -180.0)
        fprintf(f, "180,%.2f\n", open_floor(p[first].elevation_deg));
}

/* PV*SOL's .hor: two columns separated by a space, the horizontal angle
 * from -180 (north) through -90 (east), 0 (south), 90 (west) to 179, and
 * the elevation 0..90; no header. */
static void write_pvsol(FILE *f, const horizon_file_site *site, const ss_point_horizon_result *p,
                        int n)
{
    (void)site;
    for (int i = 0; i < n; ++i)
        fprintf(f, "%.10g %.2f\n", from_south(p[i].azimuth_deg), open_floor(p[i].elevation_deg));
}

/* A Solmetric SunEye "ObstructionElevation" CSV as HelioScope's uploader
 * takes it: the labels it looks for, the -180..180 azimuth (0 south) and
 * the compass heading (0 north, 90 east), which is what it reads. */
static void write_helioscope(FILE *f, const horizon_file_site *site,
                             const ss_point_horizon_result *p, int n)
{
    fprintf(f, "Obstruction elevations of site %s by skysweep %s\n", site->id, ss_version());
    fprintf(f, "Latitude %.6f; Longitude %.6f\n", site->lat_deg, site->lon_deg);
    fprintf(f, "Azimuth (-180 to 180; South=0; East=-90),Compass Heading (0-360; North=0; "
               "East=90),Average Elevation (0-90) Session\n");
    for (int i = 0; i < n; ++i)
        fprintf(f, "%.10g,%.10g,%.2f\n", from_south(p[i].azimuth_deg), p[i].azimuth_deg,
                open_floor(p[i].elevation_deg));
}

/* SAM's "azimuth by altitude" beam shading table (SSC's shading:azal): the
 * first row holds the sun's azimuths (clockwise from north, closed at 360),
 * the first column its altitudes 0..90, every other cell the beam loss in
 * percent. A row stands for the degree of altitude above it: its loss is the
 * part of that degree below the horizon, so the flat horizon is all zeros and
 * the horizon is the sum of a column's losses / 100 (SAM interpolates
 * between rows: the sun fades behind the terrain over one degree). */
#define SAM_ALTITUDES 91
static void write_sam(FILE *f, const horizon_file_site *site, const ss_point_horizon_result *p,
                      int n)
{
    (void)site;
    fputc('0', f);
    for (int i = 0; i < n; ++i)
        fprintf(f, ",%.10g", p[i].azimuth_deg);
    fputs(",360\n", f);
    for (int a = 0; a < SAM_ALTITUDES; ++a) {
        fprintf(f, "%d", a);
        for (int i = 0; i <= n; ++i) {
            double below = open_floor(p[i % n].elevation_deg) - a;
            double loss = below <= 0.0 ? 0.0 : below >= 1.0 ? 100.0 : 100.0 * below;
            fprintf(f, ",%g", nearbyint(loss * 10.0) / 10.0);
        }
        fputc('\n', f);
    }
}

static const horizon_file_format formats[] = {
    {"pvgis", ".txt", write_pvgis}, {"pvsyst", ".csv", write_pvsyst},
    {"pvsol", ".hor", write_pvsol}, {"helioscope", ".csv", write_helioscope},
    {"sam", ".csv", write_sam},
};

const horizon_file_format *horizon_file_format_named(const char *name)
{
    for (size_t i = 0; i < sizeof formats / sizeof formats[0]; ++i)
        if (strcmp(formats[i].name, name) == 0)
            return &formats[i];
    return NULL;
}
