/* skysweep shadow: where the terrain casts shadows for one sun (an exact
 * sweep along the sun's azimuth), where cells face away from it, and the
 * shaded relief that combines both. */
#include "config.h"

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>

#include "commands.h"
#include "iso_time.h"
#include "run.h"
#include "sun_field.h"

typedef struct {
    common_settings common;
} shadow_settings;

int cmd_shadow(int argc, char **argv)
{
    shadow_settings set = {0};
    common_settings_init(&set.common);
    const opt_spec *tables[] = {sun_options, common_options, NULL};
    const char *pos[COMMAND_MAX_INPUTS + 1];
    int n_pos = 0;
    int rc = run_parse("shadow", tables, &set, argc, argv, pos, &n_pos, COMMAND_MAX_INPUTS + 1, 2,
                       "skysweep shadow (--time ISO8601 | --sun-azimuth DEG --sun-elevation DEG) "
                       "[options] DEM... OUTPUT",
                       "Cast shadows for one sun, by an exact sweep along its azimuth. Bands: 1 "
                       "sunlit (1) or in a cast\nshadow (0); 2 facing the sun (1) or away "
                       "(self-shadow, 0); 3 illumination cos(i) on sunlit cells facing\nthe "
                       "sun, else 0 (shaded relief with cast shadows).",
                       &set.common.device);
    if (rc >= 0)
        return rc;
    sweep_job job;
    if ((rc = job_open(&job, "shadow", &set.common, pos, n_pos)))
        return rc;
    double when;
    int timed = set.common.time && ss_parse_instant(job.run.ctx, set.common.time, &when) == SS_OK;
    if ((rc = job_plan(&job, &set.common, SS_PRODUCT_SHADOW, timed, timed ? &when : NULL,
                       SS_SHADOW_EXACT)) >= 0) {
        job_close(&job);
        return rc;
    }
    const ss_grid *g = &job.dem.grid;
    size_t n = (size_t)g->width * (size_t)g->height;
    ss_sun_field sun;
    float *sunlit = malloc(n * sizeof(float)), *facing = malloc(n * sizeof(float)),
          *light = malloc(n * sizeof(float));
    ss_raster_writer *w = NULL;
    ss_status st = sunlit && facing && light ? job_sun(&job, &set.common, &sun)
                                             : command_out_of_memory(&job.run);
    int have_sun = st == SS_OK;
    if (st == SS_OK)
        st = ss_writer_open(job.run.ctx, job.output, &job.dem, 3, set.common.format,
                            set.common.creation_options.items, &w);
    /* The sweep runs along the sun's azimuth at the DEM's centre. */
    double sun_az_true = sun.centre_grid_azimuth_deg + job.opt.grid_north_deg;
    if (st == SS_OK)
        st = ss_cast_shadow(job.run.ctx, g, &job.opt, sun_az_true,
                            sun.centre.apparent_elevation_deg, sun.apparent_elevation_deg, sunlit,
                            NULL);
    if (st == SS_OK)
        st = ss_sun_incidence(job.run.ctx, g, sun.centre_grid_azimuth_deg,
                              sun.centre.apparent_elevation_deg, sun.grid_azimuth_deg,
                              sun.apparent_elevation_deg, light);
    size_t lit = 0, valid = 0;
    for (size_t c = 0; st == SS_OK && c < n; ++c) {
        if (sunlit[c] == SS_NODATA) {
            facing[c] = SS_NODATA;
            light[c] = SS_NODATA;
            continue;
        }
        facing[c] = light[c] > 0.0f ? 1.0f : 0.0f;
        light[c] = light[c] > 0.0f ? light[c] * sunlit[c] : 0.0f;
        lit += sunlit[c] > 0.0f;
        valid++;
    }
    if (st == SS_OK) {
        char buf[200];
        run_common_metadata(&job.run, w, &job.opt, &job.frame);
        job_plan_metadata(&job, w);
        snprintf(buf, sizeof buf, "azimuth %.6f deg (true), apparent elevation %.6f deg, %s",
                 sun_az_true, sun.centre.apparent_elevation_deg,
                 sun.apparent_elevation_deg ? "per cell" : "one sun for the DEM");
        ss_writer_metadata(w, "SUN", buf);
        if (set.common.time)
            ss_writer_metadata(w, "TIME", set.common.time);
        st = ss_writer_band(w, 1, sunlit, "sunlit (1) or in a cast shadow (0)", "1");
    }
    if (st == SS_OK)
        st = ss_writer_band(w, 2, facing, "facing the sun (1) or away from it (0)", "1");
    if (st == SS_OK)
        st = ss_writer_band(w, 3, light, "illumination cos(incidence), 0 in shadow", "1");
    if (st == SS_OK)
        st = run_commit(&job.run, w);
    else
        ss_writer_abort(w);
    rc = job_finish(&job, st);
    if (st == SS_OK && !job.run.quiet) {
        run_print_dem(&job.run, &job.dem, &job.frame);
        command_print_sweep(&job.run, &job.opt, g->width, g->height);
        printf("sun     azimuth %.4f, apparent elevation %.4f deg (%s, spread %.4f deg)\n",
               sun_az_true, sun.centre.apparent_elevation_deg,
               sun.apparent_elevation_deg ? "per cell" : "one sun", sun.spread_deg);
        printf("shadow  %.1f %% of cells sunlit -> %s\n", valid ? 100.0 * lit / valid : 0.0,
               job.output);
    }
    if (have_sun)
        ss_sun_field_free(&sun);
    free(sunlit);
    free(facing);
    free(light);
    job_close(&job);
    return rc;
}
