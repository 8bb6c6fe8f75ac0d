/* skysweep hillshade: gdaldem's hillshade (same formula, options and byte
 * output), plus what a cartographer wants from the sweep: exact cast
 * shadows of the light, with trees' partial shade (--canopy), sky-view
 * shading blended in, or RVT's VAT blend (ss_hillshade_rows), on the DEM
 * held whole or read band by band. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include "commands.h"
#include "run.h"
#include "trees.h"

typedef struct {
    common_settings common;  /* first: common_options()' offsets are relative to it */
    ss_hillshade_params hs;  /* the library's "hillshade" table */
    tree_settings trees;
} hillshade_settings;

typedef struct {
    ss_raster_writer *w;
} shade_out;

static ss_status write_rows(void *user, int output, int index, int row0, int n_rows,
                            const float *values)
{
    (void)output, (void)index;
    shade_out *o = user;
    return ss_writer_rows(o->w, 1, row0, n_rows, values);
}

/* The crowns the light crosses, for the whole grid (ss_canopy_crossed
 * along the light, whose azimuth is in the raster's frame), handed to the
 * shade in ho. */
static ss_status trees_crossed(sweep_job *job, const tree_settings *set, trees *t,
                               ss_hillshade_options *ho, unsigned char **crossed)
{
    ss_status st = trees_open(job, set, t);
    ss_grid ground = trees_ground(job, t);
    if (st == SS_OK &&
        !(*crossed = malloc((size_t)ground.width * (size_t)ground.height)))
        st = ss_ctx_error(job->run.ctx, SS_ERR_MEMORY, "out of memory for the trees");
    if (st == SS_OK)
        st = ss_canopy_crossed(job->run.ctx, &ground, &t->canopy, &job->opt, ho->azimuth_deg,
                               ho->altitude_deg, *crossed);
    ho->crowns_crossed = *crossed;
    ho->transmissivity = set->transmissivity;
    return st;
}

/* The share of the DSM's cells (held whole, g->z) whose light crosses a crown. */
static double crossed_share(const unsigned char *crossed, const ss_grid *g)
{
    size_t n = (size_t)g->width * (size_t)g->height, k = 0, valid = 0;
    for (size_t i = 0; i < n; ++i) {
        k += crossed[i] != 0;
        valid += isfinite(g->z[i]);
    }
    return valid ? (double)k / (double)valid : 0.0;
}

int cmd_hillshade(int argc, char **argv)
{
    hillshade_settings set = {0};
    common_settings_init(&set.common);
    opt_spec hillshade_options[16];
    opt_from_params("hillshade", offsetof(hillshade_settings, hs), hillshade_options, 16);
    opt_spec tree_opts[TREE_OPTIONS_MAX];
    const opt_spec *tables[] = {
        hillshade_options,
        tree_options(offsetof(hillshade_settings, trees), 0,
                     "partial shade: cells whose light crosses a crown (with --cast-shadows) "
                     "take 1 + T (shade - 1)",
                     tree_opts),
        common_options(), NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("hillshade", tables, &set, argc, argv, pos, &n_pos,
                       COMMAND_MAX_INPUTS + 1, 2, "skysweep hillshade [options] DEM... OUTPUT",
                       ss_product_named("hillshade")->description,
                       &set.common.device);
    if (rc < 0)
        rc = trees_options_alone("hillshade", tables, &set, &set.trees);
    if (rc >= 0)
        return rc;
    if (set.trees.canopy && !set.hs.cast_shadows)
        return run_usage_error("hillshade", "trees shade the hillshade through its cast "
                                            "shadows: give --cast-shadows with --canopy");
    /* gdaldem refuses both too (front ends pass the default 315 always). */
    if (set.hs.multidirectional && !opt_at_default(opt_find(tables, "az"), &set))
        return run_usage_error("hillshade", "--multidirectional lights from 225, 270, 315 and "
                                            "360 degrees: leave --az out");
    /* The VAT blend's hillshade is RVT's, lit from 315/35 by Horn's slope
     * unexaggerated: a light given here would change nothing. */
    static const char *const vat_light[] = {"az", "alt", "z", "alg"};
    for (size_t i = 0; set.hs.blend && i < sizeof vat_light / sizeof vat_light[0]; ++i)
        if (!opt_at_default(opt_find(tables, vat_light[i]), &set)) {
            char why[160];
            snprintf(why, sizeof why, "--%s has no effect with --blend vat (its hillshade is "
                     "lit from 315/35 by Horn's slope, unexaggerated)", vat_light[i]);
            return run_usage_error("hillshade", why);
        }
    int sweeps = set.hs.blend || set.hs.cast_shadows || set.hs.sky_view > 0;
    /* A band holds its heights and a row of shades, SVF and openness;
     * sweeps add a horizon's band and its rows carried between bands. */
    band_cost cost = {.cell_bytes = 16.0 + (sweeps ? ss_horizon_band_cell_bytes(0) : 4.0),
                      .column_bytes = sweeps ? ss_horizon_column_bytes() : 0.0,
                      .directions = sweeps ? 0 : 1,
                      .no_sweep = !sweeps,
                      .halo_cells = set.hs.blend ? set.hs.blend_radius_cells : 0.0,
                      .grid_cell_bytes = (set.trees.canopy ? TREES_HILLSHADE_CELL_BYTES : 0.0) +
                                         fmax(set.hs.cast_shadows
                                                  ? run_march_cell_bytes(&set.common)
                                                  : 0.0,
                                              set.hs.sky_view > 0 || set.hs.blend
                                                  ? run_box_sky_cell_bytes(&set.common)
                                                  : 0.0)};
    sweep_job job;
    if ((rc = job_open_banded(&job, "hillshade", &set.common, pos, n_pos, cost)))
        return rc;
    const ss_grid *g = &job.dem.grid;
    ss_hillshade_options ho;
    ss_hillshade_params_options(&set.hs, sqrt(g->cell_x_m * g->cell_y_m), &ho);
    ss_status st = ss_hillshade_check(job.run.ctx, &ho); /* before the plan is printed */
    if (st != SS_OK) {
        rc = job_finish(&job, st);
        job_close(&job);
        return rc;
    }
    if ((rc = job_plan(&job, &set.common, ss_product_named("hillshade"), &set.hs, 0, NULL)) >=
        0) {
        job_close(&job);
        return rc;
    }
    double blend_radius_m = ho.radius_m;
    trees tr = {0};
    unsigned char *crossed = NULL;
    double trees_s = run_now();
    if (set.trees.canopy)
        st = trees_crossed(&job, &set.trees, &tr, &ho, &crossed);
    trees_s = run_now() - trees_s;
    shade_out out = {NULL};
    if (st == SS_OK)
        st = ss_writer_open_byte(job.run.ctx, job.output, &job.dem, 1, set.common.format,
                             set.common.creation_options.items, &out.w);
    ss_raster_writer *w = out.w;
    ss_source src = job_source(&job, NULL);
    if (st == SS_OK)
        st = ss_hillshade_rows(job.run.ctx, &src, &job.opt, &ho, write_rows, &out);
    if (st == SS_OK) {
        char buf[300];
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        if (set.hs.blend)
            snprintf(buf, sizeof buf,
                     "RVT VAT blend (Kokalj & Somrak 2019): hillshade 315/35 normal 100%%, "
                     "slope 0..50 deg inverted luminosity 50%%, positive openness 68..93 deg "
                     "overlay 50%%, SVF 0.7..1 multiply 25%%; horizons within %g m%s",
                     blend_radius_m, blend_radius_m > 0 ? "" : " (unlimited)");
        else
            snprintf(buf, sizeof buf,
                 "gdaldem hillshade: az %g (raster frame), alt %g, z %g, %s%s%s; sky-view "
                 "weight %g",
                 set.hs.azimuth_deg, set.hs.altitude_deg, set.hs.z_factor, set.hs.alg ? "ZevenbergenThorne" : "Horn",
                 set.hs.multidirectional ? ", multidirectional" : "",
                 set.hs.cast_shadows ? ", cast shadows" : "", set.hs.sky_view);
        ss_writer_metadata(w, set.hs.blend ? "RELIEF_BLEND" : "HILLSHADE", buf);
        if (set.trees.canopy)
            trees_metadata(w, &set.trees, &tr);
        ss_writer_describe(w, 1, set.hs.blend ? "VAT relief blend" : "hillshade", NULL);
    }
    if (st == SS_OK)
        st = run_commit(&job.run, w);
    else
        ss_writer_abort(w);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        if (sweeps)
            command_print_sweep(&job.run, &job.opt, g->width, g->height);
        if (job.source)
            printf("bands   %d rows of %d cells at a time, read with two rows either side\n",
                   job.band_rows, g->width);
        if (set.hs.blend)
            printf("shade   VAT blend, horizons within %g m -> %s\n", blend_radius_m, job.output);
        else
            printf("shade   light %g/%g deg -> %s\n", set.hs.azimuth_deg, set.hs.altitude_deg,
                   job.output);
        command_print_box_march(&job.run, "shade  ");
        if (set.trees.canopy) {
            char described[400];
            ss_grid ground = trees_ground(&job, &tr);
            trees_describe(&set.trees, &tr, described, sizeof described);
            printf("trees   %s: the light crosses crowns at %.1f %% of cells (crowns met on "
                   "the host: %s, %.3f s)\n",
                   described, 100.0 * crossed_share(crossed, &ground),
                   trees_crown_lines(&job.opt, 0), trees_s);
        }
        command_print_memory(&job, job.source ? "bands" : "whole grid");
        run_print_phases(&job.run);
    }
    free(crossed);
    trees_free(&tr);
    job_close(&job);
    return rc;
}
