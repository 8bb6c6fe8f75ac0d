/* Clear-sky insolation over a time range: for every daylight step, cast
 * shadows (an exact sweep at the sun's azimuth, or horizons interpolated
 * between stored directions), then beam, sky-diffuse and ground-reflected
 * irradiance on each cell's own slope (kernels/ss_insolation.h), summed in
 * Wh/m^2. Steps are skipped exactly where nothing can happen: at night,
 * and the shadow sweep when the sun stands above any horizon the terrain
 * can cast. */
#include "config.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "lines.h"
#include "products_internal.h"
#include "ss_insolation.h"
#include "ss_sun.h"
#include "ss_terms.h"

/* Stored horizons are int16 hundredths of a degree (shadow mode
 * interpolated): 0.005 degrees of rounding, far below the interpolation's
 * own error. */
#define HORIZON_SCALE 100.0f

/* Per-cell quantities that do not change with time. */
typedef struct {
    float *dz_de, *dz_dn;   /* surface gradient (Horn) */
    float *sky_view;        /* radiative SVF of the tilted cell */
    float *slope_term;      /* Muneer's F(S) */
    float *pressure_factor; /* exp(-z / 8434.5): air mass at the cell's height */
} cell_terms;

static void free_terms(cell_terms *t)
{
    free(t->dz_de);
    free(t->dz_dn);
    free(t->sky_view);
    free(t->slope_term);
    free(t->pressure_factor);
}

static ss_status make_terms(ss_ctx *ctx, const ss_grid *g, const ss_sweep_options *opt,
                            cell_terms *t)
{
    size_t n = (size_t)g->width * g->height;
    memset(t, 0, sizeof *t);
    t->dz_de = malloc(n * sizeof(float));
    t->dz_dn = malloc(n * sizeof(float));
    t->sky_view = malloc(n * sizeof(float));
    t->slope_term = malloc(n * sizeof(float));
    t->pressure_factor = malloc(n * sizeof(float));
    if (!t->dz_de || !t->dz_dn || !t->sky_view || !t->slope_term || !t->pressure_factor)
        return ss_fail(ctx, SS_ERR_MEMORY, "cannot allocate insolation buffers for %d x %d cells",
                       g->width, g->height);
    ss_status st = ss_svf(ctx, g, opt, SS_SVF_DEF_TILTED, t->sky_view);
    if (st != SS_OK)
        return st;
    float cx = (float)g->cell_x_m, cy = (float)g->cell_y_m;
#pragma omp parallel for schedule(static)
    for (int r = 0; r < g->height; ++r)
        for (int c = 0; c < g->width; ++c) {
            size_t k = (size_t)r * g->width + c;
            if (!isfinite(g->z[k]))
                continue;
            ss_gradient_horn(g->z, g->width, g->height, c, r, cx, cy, &t->dz_de[k],
                             &t->dz_dn[k]);
            float slope = atanf(sqrtf(t->dz_de[k] * t->dz_de[k] + t->dz_dn[k] * t->dz_dn[k]));
            t->slope_term[k] = ss_muneer_slope_term(slope);
            /* Air pressure relative to sea level (ESRA's p/p0). No dry land
             * lies below -1000 m, and far below it the factor overflows: a
             * DEM of bathymetry or fill values gets the -1000 m air. */
            double height_m = fmax(g->z[k] + g->z_origin_m, -1000.0);
            t->pressure_factor[k] = (float)exp(-height_m / 8434.5);
        }
    return SS_OK;
}

/* Horizons at the D stored directions, int16 hundredths of a degree. */
static ss_status store_horizons(ss_ctx *ctx, ss_session *s, const ss_grid *g,
                                const ss_sweep_options *opt, int16_t **stored)
{
    size_t n = (size_t)g->width * g->height;
    double bytes = (double)n * opt->directions * sizeof(int16_t);
    *stored = bytes < 4e9 ? malloc((size_t)bytes) : NULL;
    if (!*stored)
        return ss_fail(ctx, SS_ERR_MEMORY,
                       "storing %d horizon directions takes %.1f GB: use the exact shadow "
                       "mode or fewer directions",
                       opt->directions, bytes / 1e9);
    for (int i = 0; i < opt->directions; ++i) {
        float *h;
        ss_status st = ss_sun_horizon(s, g, opt, ss_direction_azimuth(opt, i), &h);
        if (st != SS_OK)
            return st;
        int16_t *dst = *stored + (size_t)i * n;
        for (size_t c = 0; c < n; ++c)
            dst[c] = isfinite(g->z[c]) ? (int16_t)lrintf(h[c] * HORIZON_SCALE) : 0;
    }
    return SS_OK;
}

/* Horizon of cell c at azimuth az (options' frame), linear between the two
 * stored directions around it. */
static float stored_horizon(const int16_t *stored, size_t n, const ss_sweep_options *opt,
                            size_t c, double az)
{
    double pos = fmod((az - opt->offset_deg) / (360.0 / opt->directions), opt->directions);
    if (pos < 0)
        pos += opt->directions;
    int i0 = (int)pos % opt->directions, i1 = (i0 + 1) % opt->directions;
    float t = (float)(pos - floor(pos));
    return ((1.0f - t) * stored[(size_t)i0 * n + c] + t * stored[(size_t)i1 * n + c]) /
           HORIZON_SCALE;
}

ss_status ss_insolation(ss_ctx *ctx, const ss_grid *grid, const ss_sweep_options *opt,
                        const ss_insolation_options *io, int n_steps, ss_sun_step_fn sun_at,
                        void *sun_user, ss_step_sink sink, void *sink_user,
                        ss_insolation_out *out)
{
    if (!(io->albedo >= 0 && io->albedo <= 1) || n_steps < 1 ||
        (io->shadow_mode != SS_SHADOW_EXACT && io->shadow_mode != SS_SHADOW_INTERPOLATED))
        return ss_fail(ctx, SS_ERR_ARGUMENT,
                       "insolation needs an albedo in 0..1, at least one step and a shadow mode "
                       "(albedo %g, %d steps)",
                       io->albedo, n_steps);
    size_t n = (size_t)grid->width * grid->height;
    cell_terms terms;
    ss_session *s = NULL;
    int16_t *stored = NULL;
    float *step_global = sink ? malloc(n * sizeof(float)) : NULL;
    ss_status st = ss_product_begin(ctx, grid, opt, 1, &s);
    if (st == SS_OK)
        st = make_terms(ctx, grid, opt, &terms);
    else
        memset(&terms, 0, sizeof terms);
    if (st == SS_OK && sink && !step_global)
        st = ss_fail(ctx, SS_ERR_MEMORY, "out of memory for per-step bands");
    if (st == SS_OK && io->shadow_mode == SS_SHADOW_INTERPOLATED)
        st = store_horizons(ctx, s, grid, opt, &stored);
    for (size_t c = 0; st == SS_OK && c < n; ++c) {
        float v = isfinite(grid->z[c]) ? 0.0f : SS_NODATA;
        out->global[c] = out->beam[c] = out->diffuse[c] = out->reflected[c] = v;
        out->sun_hours[c] = v;
    }
    double bound_deg = ss_horizon_bound_deg(grid, opt->lines);
    for (int k = 0; k < n_steps && st == SS_OK; ++k) {
        ss_sun_step sun;
        st = sun_at(ctx, k, &sun, sun_user);
        if (st != SS_OK)
            break;
        if (step_global)
            for (size_t c = 0; c < n; ++c)
                step_global[c] = isfinite(grid->z[c]) ? 0.0f : SS_NODATA;
        int night = sun.elevation_deg + sun.spread_deg <= 0.0;
        if (night) {
            ctx->counters.night_steps_skipped++;
        } else {
            ctx->counters.time_steps++;
            /* Shadows: none can fall where the sun is above every horizon. */
            float *h = NULL;
            int all_lit = sun.apparent_elevation_deg - sun.spread_deg > bound_deg;
            if (all_lit) {
                ctx->counters.shadow_sweeps_skipped++;
            } else if (io->shadow_mode == SS_SHADOW_EXACT) {
                double t0 = ss_seconds_now();
                st = ss_sun_horizon(s, grid, opt, sun.azimuth_deg, &h);
                ctx->counters.sweep_seconds += ss_seconds_now() - t0;
            }
            if (st != SS_OK)
                break;
            const float rad = (float)(M_PI / 180.0);
            float g0 = (float)sun.extraterrestrial_w_m2, linke = (float)sun.linke;
            float dt = (float)sun.duration_h, albedo = (float)io->albedo;
#pragma omp parallel for schedule(static)
            for (size_t c = 0; c < n; ++c) {
                if (!isfinite(grid->z[c]))
                    continue;
                float az = (sun.grid_azimuth_per_cell ? sun.grid_azimuth_per_cell[c]
                                                      : (float)sun.grid_azimuth_deg) * rad;
                float h0 = (sun.elevation_per_cell ? sun.elevation_per_cell[c]
                                                   : (float)sun.elevation_deg) * rad;
                float app = sun.apparent_per_cell ? sun.apparent_per_cell[c]
                                                  : (float)sun.apparent_elevation_deg;
                if (h0 <= 0.0f)
                    continue;
                float sin_h0 = sinf(h0);
                float se = cosf(h0) * sinf(az), sn = cosf(h0) * cosf(az);
                float cos_i = ss_cos_incidence_gradient(se, sn, sin_h0, terms.dz_de[c],
                                                        terms.dz_dn[c]);
                float horizon = all_lit ? -90.0f
                                : h     ? h[c]
                                        : stored_horizon(stored, n, opt, c, sun.azimuth_deg);
                int lit = app > horizon && cos_i > 0.0f;
                float m = terms.pressure_factor[c] * ss_esra_air_mass_sea_level(h0);
                float kb = ss_esra_beam_transmittance(linke, m);
                float beam_h = g0 * sin_h0 * kb;
                float diff_h = g0 * ss_esra_diffuse_fraction(linke, sin_h0);
                float beam = lit ? g0 * kb * cos_i : 0.0f;
                /* sin S cos(sun azimuth - aspect): the tilt toward the sun. */
                float norm = sqrtf(1.0f + terms.dz_de[c] * terms.dz_de[c] +
                                   terms.dz_dn[c] * terms.dz_dn[c]);
                float side = -(terms.dz_de[c] * sinf(az) + terms.dz_dn[c] * cosf(az)) / norm;
                int level = terms.dz_de[c] == 0.0f && terms.dz_dn[c] == 0.0f;
                float diffuse = diff_h * ss_muneer_diffuse_factor(terms.sky_view[c],
                                                                  terms.slope_term[c], kb, lit,
                                                                  level, cos_i, sin_h0, h0, side);
                float reflected = albedo * (beam_h + diff_h) * (1.0f - terms.sky_view[c]);
                out->beam[c] += beam * dt;
                out->diffuse[c] += diffuse * dt;
                out->reflected[c] += reflected * dt;
                out->global[c] += (beam + diffuse + reflected) * dt;
                out->sun_hours[c] += lit ? dt : 0.0f;
                if (step_global)
                    step_global[c] = (beam + diffuse + reflected) * dt;
            }
        }
        if (st == SS_OK && sink && !sink(k, step_global, sink_user))
            st = ss_fail(ctx, SS_ERR_CANCELLED, "stopped while storing time step %d", k);
        if (st == SS_OK)
            st = ss_progress(ctx, (double)(k + 1) / n_steps, "insolation");
    }
    free(stored);
    free(step_global);
    free_terms(&terms);
    ss_session_close(s);
    return st;
}
