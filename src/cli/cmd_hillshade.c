/* skysweep hillshade: gdaldem's hillshade (same formula, options and byte
 * output), plus what a cartographer wants from the sweep: exact cast
 * shadows of the light, and sky-view shading blended in. A plain hillshade
 * of a DEM that does not fit in --memory is shaded band by band. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include "commands.h"
#include "run.h"

typedef struct {
    common_settings common;
    double azimuth_deg, altitude_deg, z_factor;
    int alg, multidirectional, cast_shadows, blend;
    double sky_view, blend_radius_cells;
} hillshade_settings;

#define SET(field) offsetof(hillshade_settings, field)
static const opt_spec hillshade_options[] = {
    {"az", OPT_DOUBLE, SET(azimuth_deg), "DEG", "315", -360, 360, NULL,
     "light azimuth, degrees clockwise from the top of the raster (gdaldem's -az)"},
    {"alt", OPT_DOUBLE, SET(altitude_deg), "DEG", "45", 0, 90, NULL,
     "light altitude above the horizontal (gdaldem's -alt)"},
    {"z", OPT_DOUBLE, SET(z_factor), "FACTOR", "1", 1e-6, 1e6, NULL,
     "vertical exaggeration (gdaldem's -z; ground sizes come from the CRS, so gdaldem's -s "
     "is not needed)"},
    {"alg", OPT_CHOICE, SET(alg), NULL, "Horn", 0, 0, "Horn|ZevenbergenThorne",
     "slope algorithm (gdaldem's -alg)"},
    {"multidirectional", OPT_FLAG, SET(multidirectional), NULL, NULL, 0, 0, NULL,
     "gdaldem's multidirectional shading (lights from 225, 270, 315, 360)"},
    {"cast-shadows", OPT_FLAG, SET(cast_shadows), NULL, NULL, 0, 0, NULL,
     "darken cells in the light's cast shadows (exact sweep along the light)"},
    {"sky-view", OPT_DOUBLE, SET(sky_view), "WEIGHT", "0", 0, 1, NULL,
     "blend in sky-view shading: (1 - W) hillshade + W (1 + 254 SVF), geometric SVF over "
     "--directions"},
    {"blend", OPT_CHOICE, SET(blend), NULL, "none", 0, 0, "none|vat",
     "vat: RVT's relief blend for archaeology and cartography (hillshade 315/35, slope, "
     "positive openness, SVF; doc/relief.md) instead of the plain hillshade"},
    {"blend-radius", OPT_DOUBLE, SET(blend_radius_cells), "CELLS", "10", 0, 1e6, NULL,
     "how far the blend's SVF and openness look for the horizon, in cells (RVT's default "
     "10); 0: unlimited"},
    OPT_END};

/* A DEM left in its files: bands of rows read with one row either side
 * (the 3 x 3 slope window), shaded as a grid of their own, whose inner
 * rows are then the whole grid's. */
static ss_status shade_banded(sweep_job *job, const hillshade_settings *set,
                              ss_raster_writer *w)
{
    const ss_grid *g = &job->dem.grid;
    size_t held = (size_t)(job->band_rows + 2) * (size_t)g->width;
    float *z = malloc(held * sizeof(float)), *shade = malloc(held * sizeof(float));
    ss_status st = z && shade ? SS_OK : command_out_of_memory(&job->run);
    for (int row0 = 0; row0 < g->height && st == SS_OK; row0 += job->band_rows) {
        int rows = row0 + job->band_rows < g->height ? job->band_rows : g->height - row0;
        int lo = row0 > 0 ? row0 - 1 : 0;
        int hi = row0 + rows < g->height ? row0 + rows + 1 : g->height;
        st = job_read_rows(job, lo, hi - lo, z);
        ss_grid band = {g->width, hi - lo, g->cell_x_m, g->cell_y_m, g->z_origin_m, z};
        size_t n = (size_t)(hi - lo) * (size_t)g->width;
        if (st == SS_OK && !run_any_height(z, n))
            for (size_t c = 0; c < n; ++c) /* all nodata: nothing to shade */
                shade[c] = SS_NODATA;
        else if (st == SS_OK)
            st = ss_hillshade(job->run.ctx, &band, set->azimuth_deg, set->altitude_deg,
                              set->z_factor, set->alg == 1, set->multidirectional, shade);
        if (st == SS_OK)
            st = ss_writer_rows(w, 1, row0, rows, shade + (size_t)(row0 - lo) * g->width);
    }
    free(z);
    free(shade);
    return st;
}

int cmd_hillshade(int argc, char **argv)
{
    hillshade_settings set = {0};
    common_settings_init(&set.common);
    const opt_spec *tables[] = {hillshade_options, common_options, NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("hillshade", tables, &set, argc, argv, pos, &n_pos,
                       COMMAND_MAX_INPUTS + 1, 2, "skysweep hillshade [options] DEM... OUTPUT",
                       "Shaded relief as gdaldem hillshade computes it (Byte 1..255, 0 = "
                       "nodata), optionally with\nexact cast shadows and sky-view shading.",
                       &set.common.device);
    if (rc >= 0)
        return rc;
    if (set.blend && (set.cast_shadows || set.sky_view > 0 || set.multidirectional)) {
        fprintf(stderr, "skysweep hillshade: --blend vat has its own light and layers; it "
                        "does not take --cast-shadows, --sky-view or --multidirectional\n");
        return SS_ERR_ARGUMENT;
    }
    /* A plain hillshade reads rows and shades them: heights and shades of
     * a band. What sweeps needs the whole grid. */
    int plain = !(set.blend || set.cast_shadows || set.sky_view > 0);
    band_cost cost = {8.0, 0.0, 1};
    sweep_job job;
    if ((rc = plain ? job_open_banded(&job, "hillshade", &set.common, pos, n_pos, cost)
                    : job_open(&job, "hillshade", &set.common, pos, n_pos)))
        return rc;
    /* Plain hillshade reads no horizons; cast shadows and sky view do. */
    ss_product product = set.cast_shadows                 ? SS_PRODUCT_SHADOW
                         : set.sky_view > 0 || set.blend ? SS_PRODUCT_SVF
                                                         : SS_PRODUCT_HILLSHADE;
    if ((rc = job_plan(&job, &set.common, product, 0, NULL, SS_SHADOW_EXACT)) >= 0) {
        job_close(&job);
        return rc;
    }
    const ss_grid *g = &job.dem.grid;
    size_t n = job.source ? 0 : (size_t)g->width * (size_t)g->height;
    float *shade = job.source ? NULL : malloc(n * sizeof(float));
    float *extra = (set.cast_shadows || set.sky_view > 0) ? malloc(n * sizeof(float)) : NULL;
    ss_raster_writer *w = NULL;
    ss_status st = (shade || job.source) && (extra || !(set.cast_shadows || set.sky_view > 0))
                       ? ss_writer_open_byte(job.run.ctx, job.output, &job.dem, 1,
                                             set.common.format,
                                             set.common.creation_options.items, &w)
                       : command_out_of_memory(&job.run);
    double blend_radius_m = set.blend_radius_cells * sqrt(g->cell_x_m * g->cell_y_m);
    if (st == SS_OK && job.source) {
        st = shade_banded(&job, &set, w);
    } else if (st == SS_OK && set.blend) {
        st = ss_vat(job.run.ctx, g, &job.opt, blend_radius_m, shade);
        for (size_t c = 0; st == SS_OK && c < n; ++c)
            if (shade[c] != SS_NODATA)
                shade[c] = 1.0f + 254.0f * shade[c];
    } else if (st == SS_OK)
        st = ss_hillshade(job.run.ctx, g, set.azimuth_deg, set.altitude_deg, set.z_factor,
                          set.alg == 1, set.multidirectional, shade);
    /* The light's azimuth is in the raster's frame; the sweep takes the
     * options' frame (true north unless --north grid). */
    if (st == SS_OK && set.cast_shadows) {
        double az = set.azimuth_deg + job.opt.grid_north_deg;
        st = ss_cast_shadow(job.run.ctx, g, &job.opt, az, set.altitude_deg, NULL, extra, NULL);
        for (size_t c = 0; st == SS_OK && c < n; ++c)
            if (shade[c] != SS_NODATA && extra[c] == 0.0f)
                shade[c] = 1.0f;
    }
    if (st == SS_OK && set.sky_view > 0) {
        st = ss_svf(job.run.ctx, g, &job.opt, SS_SVF_DEF_GEOMETRIC, extra);
        for (size_t c = 0; st == SS_OK && c < n; ++c)
            if (shade[c] != SS_NODATA)
                shade[c] = (float)((1 - set.sky_view) * shade[c] +
                                   set.sky_view * (1.0 + 254.0 * extra[c]));
    }
    if (st == SS_OK) {
        char buf[300];
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        if (set.blend)
            snprintf(buf, sizeof buf,
                     "RVT VAT blend (Kokalj & Somrak 2019): hillshade 315/35 normal 100%%, "
                     "slope 0..50 deg inverted luminosity 50%%, positive openness 68..93 deg "
                     "overlay 50%%, SVF 0.7..1 multiply 25%%; horizons within %g m%s",
                     blend_radius_m, blend_radius_m > 0 ? "" : " (unlimited)");
        else
            snprintf(buf, sizeof buf,
                 "gdaldem hillshade: az %g (raster frame), alt %g, z %g, %s%s%s; sky-view "
                 "weight %g",
                 set.azimuth_deg, set.altitude_deg, set.z_factor, set.alg ? "ZevenbergenThorne" : "Horn",
                 set.multidirectional ? ", multidirectional" : "",
                 set.cast_shadows ? ", cast shadows" : "", set.sky_view);
        ss_writer_metadata(w, set.blend ? "RELIEF_BLEND" : "HILLSHADE", buf);
        if (job.source)
            ss_writer_describe(w, 1, "hillshade", NULL);
        else
            st = ss_writer_band(w, 1, shade, set.blend ? "VAT relief blend" : "hillshade", NULL);
    }
    if (st == SS_OK)
        st = run_commit(&job.run, w);
    else
        ss_writer_abort(w);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        if (set.cast_shadows || set.sky_view > 0 || set.blend)
            command_print_sweep(&job.run, &job.opt, g->width, g->height);
        if (job.source)
            printf("bands   %d rows of %d cells at a time, read with a row either side\n",
                   job.band_rows, g->width);
        if (set.blend)
            printf("shade   VAT blend, horizons within %g m -> %s\n", blend_radius_m, job.output);
        else
            printf("shade   light %g/%g deg -> %s\n", set.azimuth_deg, set.altitude_deg,
                   job.output);
    }
    free(shade);
    free(extra);
    job_close(&job);
    return rc;
}
