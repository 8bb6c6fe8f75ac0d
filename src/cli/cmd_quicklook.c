/* skysweep quicklook: a PNG of one band of any product (or any raster GDAL
 * reads), through a colour map, with nodata transparent. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "band_read.h"
#include "colormap.h"
#include "commands.h"
#include "run.h"
#include "temporaries.h"
#ifdef HAVE_OIIO
#include "images.h"
#endif

typedef struct {
    int band;
    const char *colormap;
    double min, max;
    int bits; /* index into "8|16" */
    int quiet;
} quicklook_settings;

#define SET(field) offsetof(quicklook_settings, field)
static const opt_spec quicklook_options[] = {
    {"band", OPT_INT, SET(band), "N", "1", 1, 65535, NULL, "band to draw (1-based)"},
    {"colormap", OPT_STRING, SET(colormap), "NAME", NULL, 0, 0, NULL,
     "colour map: " SS_COLORMAP_NAMES " (default viridis at 8 bits, grey at 16)"},
    {"min", OPT_DOUBLE, SET(min), "VALUE", NULL, -1e30, 1e30, NULL,
     "value drawn at the start of the map (default: the band's minimum)"},
    {"max", OPT_DOUBLE, SET(max), "VALUE", NULL, -1e30, 1e30, NULL,
     "value drawn at the end of the map (default: the band's maximum); min > max reverses it"},
    {"bits", OPT_CHOICE, SET(bits), NULL, "8", 0, 0, "8|16",
     "8: RGB through the colour map; 16: grey 0..65535 (for further processing)"},
    {"q", OPT_FLAG, SET(quiet), NULL, NULL, 0, 0, NULL, "quiet: no summary"},
    OPT_END};

int cmd_quicklook(int argc, char **argv)
{
    quicklook_settings set = {0};
    set.min = NAN;
    set.max = NAN;
    const opt_spec *tables[] = {quicklook_options, NULL};
    const char *pos[2];
    int n_pos = 0;
    int rc = run_parse("quicklook", tables, &set, argc, argv, pos, &n_pos, 2, 2,
                       "skysweep quicklook [options] INPUT OUTPUT.png",
                       "A PNG of one band of a product (any raster GDAL reads) through a colour "
                       "map, stretched from\n--min to --max; nodata cells are transparent "
                       "(an alpha channel is added when there are any).",
                       NULL);
    if (rc >= 0)
        return rc;
#ifndef HAVE_OIIO
    fprintf(stderr, "skysweep quicklook: skysweep was built without OpenImageIO: quicklooks are "
                    "unavailable (install libopenimageio-dev and rebuild)\n");
    return SS_ERR_DEVICE;
#else
    int bits = set.bits == 0 ? 8 : 16;
    const char *map = set.colormap ? set.colormap : bits == 8 ? "viridis" : "grey";
    char err[300];
    if (!ss_colormap_known(map)) {
        snprintf(err, sizeof err, "unknown colour map '%s' (known: %s)", map, SS_COLORMAP_NAMES);
        return run_usage_error("quicklook", err);
    }
    if (bits == 16 && strcmp(map, "grey") != 0)
        return run_usage_error("quicklook", "16-bit quicklooks are grey: use --bits 8 for a "
                                            "colour map");
    run_state run;
    if ((rc = run_begin(&run, "quicklook", NULL)))
        return rc;
    run.quiet = set.quiet;
    ss_status bad = run_check_output(&run, pos[1]);
    if (bad != SS_OK) {
        rc = run_fail(&run, bad);
        run_end(&run);
        return rc;
    }
    /* A quicklook is a PNG whatever its name says: a name that says
     * otherwise (out.tif) would hide PNG bytes behind it. */
    const char *dot = strrchr(pos[1], '.'), *slash = strrchr(pos[1], '/');
    if (!dot || (slash && dot < slash) || strcasecmp(dot, ".png") != 0) {
        rc = run_fail(&run, ss_ctx_error(run.ctx, SS_ERR_ARGUMENT,
                                         "a quicklook is a PNG: name the output '*.png', not "
                                         "'%s'",
                                         pos[1]));
        run_end(&run);
        return rc;
    }
    ss_bands b;
    ss_status st = ss_bands_read(run.ctx, pos[0], set.band, 1, &b);
    size_t n = (size_t)b.width * (size_t)b.height, holes = 0;
    for (size_t i = 0; st == SS_OK && i < n; ++i)
        holes += b.values[0][i] == SS_NODATA;
    if (st == SS_OK && holes == n)
        st = ss_ctx_error(run.ctx, SS_ERR_INPUT,
                          "every cell of band %d of '%s' is nodata: there is nothing to show",
                          set.band, pos[0]);
    if (st == SS_OK) { /* the module names its temporary as the raster writer does */
        ss_temporaries_track(pos[1]);
        st = ss_image_write_quicklook(run.ctx, pos[1], b.values[0], b.width, b.height, set.min,
                                      set.max, map, bits, holes > 0);
        ss_temporaries_forget(pos[1]);
    }
    rc = st == SS_OK ? 0 : run_fail(&run, st);
    if (st == SS_OK && !run.quiet) {
        double lo, mean, hi;
        run_stats(b.values[0], n, &lo, &mean, &hi);
        printf("band    %d of %d: %s%s%s%s, %d x %d, min %.6g mean %.6g max %.6g\n", set.band,
               b.file_bands, b.names[0], *b.units[0] ? " (" : "", b.units[0],
               *b.units[0] ? ")" : "", b.width, b.height, lo, mean, hi);
        printf("picture %d-bit %s, %.6g..%.6g, %zu nodata cells %s -> %s\n", bits, map,
               isnan(set.min) ? lo : set.min, isnan(set.max) ? hi : set.max, holes,
               holes ? "transparent" : "(no alpha channel)", pos[1]);
    }
    ss_bands_free(&b);
    run_end(&run);
    return rc;
#endif
}
